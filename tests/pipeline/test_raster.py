"""MSAA sample coverage against the analytic standard sample positions, determinism across thread
counts, hierarchical coverage statistics."""
import numpy as np
import pytest

from conftest import clip_from_window, coverage, ref_triangle_coverage, snap, window_from_clip

# Vulkan / D3D standard sample locations, in pixels from the pixel's lower-left corner.
STANDARD = {
    1: [(0.5, 0.5)],
    2: [(0.75, 0.75), (0.25, 0.25)],
    4: [(0.375, 0.125), (0.875, 0.375), (0.125, 0.625), (0.625, 0.875)],
    8: [(0.5625, 0.3125), (0.4375, 0.6875), (0.8125, 0.5625), (0.3125, 0.1875),
        (0.1875, 0.8125), (0.0625, 0.4375), (0.6875, 0.9375), (0.9375, 0.0625)],
    16: [(0.5625, 0.5625), (0.4375, 0.3125), (0.3125, 0.625), (0.75, 0.4375),
         (0.1875, 0.375), (0.625, 0.8125), (0.8125, 0.6875), (0.6875, 0.1875),
         (0.375, 0.875), (0.5, 0.0625), (0.25, 0.125), (0.125, 0.75),
         (0.0, 0.5), (0.9375, 0.25), (0.875, 0.9375), (0.0625, 0.0)],
}
W, H = 40, 36


@pytest.mark.parametrize("samples", [1, 2, 4, 8, 16])
@pytest.mark.parametrize("seed", range(8))
def test_msaa_coverage_matches_sample_positions(samples, seed):
    rng = np.random.default_rng(seed)
    grid = 16 if seed % 2 else 256      # odd seeds: vertices on the 1/16 grid, ties at samples
    xy = np.round(rng.uniform(-3, 43, (3, 2)) * grid) / grid
    z = rng.uniform(-1, 1, 3)
    clip = clip_from_window(xy, W, H, z=z)
    r = coverage(W, H, clip, samples=samples)
    offsets = np.array([(round(x * 256), round(y * 256)) for x, y in STANDARD[samples]], np.int64)
    fixed = snap(window_from_clip(clip, W, H))
    expect = ref_triangle_coverage(fixed, W, H, offsets)
    np.testing.assert_array_equal(r["count"], expect.astype(np.uint32))
    # Depth is evaluated at each sample's own position.
    zw = 0.5 * clip[:, 2].astype(np.float64) + 0.5
    (x0, y0), (x1, y1), (x2, y2) = fixed.astype(np.float64)
    area = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
    py, px, s = np.nonzero(expect)
    X, Y = px * 256 + offsets[s, 0], py * 256 + offsets[s, 1]
    l1 = ((X - x0) * (y2 - y0) - (x2 - x0) * (Y - y0)) / area
    l2 = ((x1 - x0) * (Y - y0) - (X - x0) * (y1 - y0)) / area
    np.testing.assert_allclose(r["depth"][py, px, s],
                               np.clip(zw[0] + l1 * (zw[1] - zw[0]) + l2 * (zw[2] - zw[0]), 0, 1),
                               atol=1e-12, rtol=0)


def test_msaa_edge_sweep_4x():
    """A vertical edge swept across one pixel in 1/16 steps covers exactly the samples to its right
    (left edges are inclusive)."""
    pos = np.array(STANDARD[4])
    for k in range(17):
        x = 3 + k / 16
        clip = clip_from_window([(x, 0), (10, 0), (10, 8), (x, 0), (10, 8), (x, 8)], 10, 8)
        r = coverage(10, 8, clip, samples=4)
        got = r["count"][4, 3]
        np.testing.assert_array_equal(got, (3 + pos[:, 0] >= x).astype(np.uint32), err_msg=str(k))


def big_scene(rng, n=3000, width=300, height=200):
    size = rng.choice([0.7, 3, 20, 150], n, p=[0.5, 0.3, 0.15, 0.05])
    centre = rng.uniform(-20, [width + 20, height + 20], (n, 2))
    xy = centre[:, None, :] + rng.normal(0, 1, (n, 3, 2)) * size[:, None, None]
    z = rng.uniform(-1.2, 1.2, (n, 3))
    w = rng.uniform(0.3, 2, (n, 3))
    w[rng.random(n) < 0.02, 0] *= -1                # a few vertices behind the eye
    return clip_from_window(xy.reshape(-1, 2), width, height, z=z.ravel(), w=w.ravel())


@pytest.mark.parametrize("samples", [1, 4])
@pytest.mark.parametrize("primitive", ["triangles", "lines", "points"])
def test_same_bytes_for_any_thread_count(samples, primitive):
    rng = np.random.default_rng(11)
    clip = big_scene(rng)
    sizes = rng.uniform(0.5, 40, len(clip)).astype(np.float32)
    kw = dict(samples=samples, primitive=primitive, point_sizes=sizes,
              polygon_offset=(1.5, 2.0), cull_face=None)
    ref = coverage(300, 200, clip, threads=1, **kw)
    assert ref["count"].sum() > 10000
    for threads in (2, 3, 4, 8):
        r = coverage(300, 200, clip, threads=threads, **kw)
        for key in ("count", "depth", "last", "front", "weights", "point_coord"):
            assert r[key].tobytes() == ref[key].tobytes(), (key, threads)
        assert r["setup"] == ref["setup"] and r["raster"] == ref["raster"]


def test_full_blocks_skip_edge_tests():
    """A screen-filling quad: almost all 8x8 blocks are accepted whole."""
    clip = np.array([[-1, -1, 0, 1], [1, -1, 0, 1], [1, 1, 0, 1], [-1, -1, 0, 1], [1, 1, 0, 1],
                     [-1, 1, 0, 1]], np.float32)
    r = coverage(256, 256, clip)
    assert (r["count"] == 1).all()
    st = r["raster"]
    # 1024 blocks per triangle's bounding box; only the ~32 along the shared diagonal are partial.
    assert st["blocks_accepted"] >= 850 and st["blocks_partial"] <= 2 * 40
    assert 128 * 128 <= st["quads"] <= 128 * 128 + st["blocks_partial"] * 16


def test_primitive_order_preserved_per_pixel():
    """Overlapping triangles: the last one in draw order wins everywhere, with any thread count."""
    rng = np.random.default_rng(5)
    xy = rng.uniform(0, 128, (600, 2))
    clip = clip_from_window(xy, 128, 128)
    for threads in (1, 4):
        r = coverage(128, 128, clip, threads=threads)
        # Reference: last covering triangle by independent per-triangle coverage.
        fixed = snap(window_from_clip(clip, 128, 128))
        last = np.full((128, 128), -1)
        for t in range(200):
            last[ref_triangle_coverage(fixed[3 * t:3 * t + 3], 128, 128)[..., 0]] = t
        np.testing.assert_array_equal(r["last"], last)


def test_thread_pool_sizes_and_exceptions():
    # Bad sample counts raise instead of drawing.
    with pytest.raises(ValueError):
        coverage(8, 8, np.zeros((3, 4), np.float32), samples=3)
    with pytest.raises(ValueError):
        coverage(8, 8, np.zeros((3, 4), np.float32), indices=np.array([0, 1, 5], np.uint32))
