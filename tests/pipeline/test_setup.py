"""Face determination and culling, zero-area triangles, depth planes, polygon offset, viewport and
depth range, scissor."""
import numpy as np
import pytest
from softgl import _core

from conftest import (GL_BACK, GL_CCW, GL_CW, GL_FRONT, GL_FRONT_AND_BACK, clip_from_window,
                      coverage, ref_triangle_coverage, snap, window_from_clip)

W = H = 32
CCW_TRI = [(2.3, 3.1), (14.7, 4.2), (6.1, 13.9)]        # left half, counter-clockwise
CW_TRI = [(18.3, 3.1), (22.1, 13.9), (30.7, 4.2)]       # right half, clockwise


@pytest.mark.parametrize("front_face", [GL_CCW, GL_CW])
@pytest.mark.parametrize("cull", [None, GL_FRONT, GL_BACK, GL_FRONT_AND_BACK])
def test_culling(front_face, cull):
    r = coverage(W, H, clip_from_window(CCW_TRI + CW_TRI, W, H), cull_face=cull,
                 front_face=front_face)
    ccw_front = front_face == GL_CCW
    drawn = {0: cull is None or (cull == GL_BACK) == ccw_front,
             1: cull is None or (cull == GL_BACK) != ccw_front}
    if cull == GL_FRONT_AND_BACK:
        drawn = {0: False, 1: False}
    for tri in (0, 1):
        hit = r["last"] == tri
        assert hit.any() == drawn[tri]
        if drawn[tri]:
            assert (r["front"][hit] == (ccw_front if tri == 0 else not ccw_front)).all()
    assert r["setup"]["culled"] == 2 - sum(drawn.values())


def test_zero_area_triangles_never_reach_tiles():
    tris = [[(1.5, 1.5), (20.5, 20.5), (10.5, 10.5)],       # collinear
            [(5.0, 5.0), (5.0, 5.0), (9.0, 2.0)],            # repeated vertex
            [(3.0, 3.0), (3.001, 3.001), (3.0005, 3.0005)]]  # collapses when snapped
    r = coverage(W, H, clip_from_window(sum(tris, []), W, H))
    assert r["count"].sum() == 0
    assert r["setup"]["zero_area"] == 3 and r["setup"]["emitted"] == 0
    assert r["raster"]["quads"] == 0


def ref_depth(fixed, z, X, Y):
    """float64 screen-linear interpolation of z at fixed-point (X, Y)."""
    (x0, y0), (x1, y1), (x2, y2) = fixed.astype(np.float64)
    area = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
    l1 = ((X - x0) * (y2 - y0) - (x2 - x0) * (Y - y0)) / area
    l2 = ((x1 - x0) * (Y - y0) - (X - x0) * (y1 - y0)) / area
    return z[0] + l1 * (z[1] - z[0]) + l2 * (z[2] - z[0])


def random_triangle(rng, z_range=(-1, 1)):
    xy = rng.uniform(-4, W + 4, (3, 2))
    z = rng.uniform(*z_range, 3)
    w = rng.uniform(0.5, 3, 3)
    return clip_from_window(xy, W, H, z=z, w=w)


@pytest.mark.parametrize("depth_range", [(0, 1), (0.25, 0.75), (1, 0), (0.5, 0.5)])
@pytest.mark.parametrize("seed", range(5))
def test_depth_is_screen_linear(seed, depth_range):
    rng = np.random.default_rng(seed)
    clip = random_triangle(rng)
    r = coverage(W, H, clip, depth_range=depth_range)
    n, f = depth_range
    c64 = clip.astype(np.float64)
    zw = (f - n) / 2 * (c64[:, 2] / c64[:, 3]) + (n + f) / 2
    fixed = snap(window_from_clip(clip, W, H))
    ys, xs = np.nonzero(r["count"][..., 0])
    assert len(ys) > 0
    expect = np.clip(ref_depth(fixed, zw, xs * 256 + 128, ys * 256 + 128), 0, 1)
    np.testing.assert_allclose(r["depth"][ys, xs, 0], expect, rtol=0, atol=1e-12)


@pytest.mark.parametrize("factor,units", [(0, 0), (1, 1), (-2, 5), (4, -100), (0, 1e7), (0, -1e7)])
@pytest.mark.parametrize("depth_bits", [16, 24])
def test_polygon_offset(factor, units, depth_bits):
    rng = np.random.default_rng(int(abs(factor) * 7 + abs(units) % 97))
    clip = random_triangle(rng, (-0.5, 0.5))
    r0 = coverage(W, H, clip)
    r = coverage(W, H, clip, polygon_offset=(factor, units), depth_bits=depth_bits)
    np.testing.assert_array_equal(r["count"], r0["count"])
    c64 = clip.astype(np.float64)
    zw = 0.5 * (c64[:, 2] / c64[:, 3]) + 0.5
    fixed = snap(window_from_clip(clip, W, H))
    # Slopes of the depth plane, per pixel (ES 3.0 §3.6.5).
    (x0, y0), (x1, y1), (x2, y2) = fixed / 256.0
    det = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
    dzdx = ((zw[1] - zw[0]) * (y2 - y0) - (zw[2] - zw[0]) * (y1 - y0)) / det
    dzdy = ((zw[2] - zw[0]) * (x1 - x0) - (zw[1] - zw[0]) * (x2 - x0)) / det
    o = max(abs(dzdx), abs(dzdy)) * factor + units / (2.0 ** depth_bits - 1)
    ys, xs = np.nonzero(r["count"][..., 0])
    expect = np.clip(ref_depth(fixed, zw, xs * 256 + 128, ys * 256 + 128) + o, 0, 1)
    np.testing.assert_allclose(r["depth"][ys, xs, 0], expect, rtol=0, atol=1e-9)


def test_polygon_offset_float_depth_uses_exponent_of_max_z():
    clip = clip_from_window([(2, 2), (30, 3), (5, 29)], W, H, z=[0.2, 0.2, 0.2])
    r = coverage(W, H, clip, polygon_offset=(0, 3), depth_bits=0)
    zw = 0.5 * np.float64(np.float32(0.2)) + 0.5        # 0.6: exponent -1, r = 2^-24
    d = r["depth"][r["count"] > 0]
    np.testing.assert_allclose(d, zw + 3 * 2.0 ** -24, rtol=0, atol=1e-15)


def test_polygon_offset_applies_to_triangles_only():
    pts = clip_from_window([(8.5, 8.5)], W, H, z=0.0)
    r = coverage(W, H, pts, primitive="points", polygon_offset=(0, 1e6))
    assert r["depth"][8, 8, 0] == 0.5


def test_viewport_maps_ndc():
    clip = np.array([[-1, -1, 0, 1], [1, -1, 0, 1], [1, 1, 0, 1], [-1, -1, 0, 1], [1, 1, 0, 1],
                     [-1, 1, 0, 1]], np.float32)
    r = coverage(W, H, clip, viewport=(5, 7, 10, 20))
    expect = np.zeros((H, W), np.uint32)
    expect[7:27, 5:15] = 1
    np.testing.assert_array_equal(r["count"][..., 0], expect)


def test_scissor_limits_coverage():
    clip = np.array([[-1, -1, 0, 1], [3, -1, 0, 1], [-1, 3, 0, 1]], np.float32)
    r = coverage(W, H, clip, scissor=(3, 4, 9, 7))
    expect = np.zeros((H, W), np.uint32)
    expect[4:11, 3:12] = 1
    np.testing.assert_array_equal(r["count"][..., 0], expect)


def test_perspective_correct_weights():
    """Weights at pixel centres are the barycentrics of the 3D point the pixel sees."""
    rng = np.random.default_rng(3)
    for _ in range(10):
        clip = random_triangle(rng, (-0.9, 0.9))
        r = coverage(W, H, clip)
        c = clip.astype(np.float64)
        ys, xs = np.nonzero(r["count"][..., 0])
        for y, x in zip(ys, xs):
            nx, ny = 2 * (x + 0.5) / W - 1, 2 * (y + 0.5) / H - 1
            a = np.array([c[:, 0] - nx * c[:, 3], c[:, 1] - ny * c[:, 3], np.ones(3)])
            b = np.linalg.solve(a, [0, 0, 1])
            # Snapping moves vertices by up to 1/512 px: weights agree to about that.
            np.testing.assert_allclose(r["weights"][y, x], b, atol=3e-3)


def test_point_coord_and_wide_point_off_screen():
    """gl_PointCoord (ES 3.0 §3.4.1): s grows to the right, t grows downwards, evaluated at pixel
    centres; a point whose centre is off-screen still draws its visible part."""
    pts = clip_from_window([(8.5, 8.5), (-1.0, 20.0)], W, H)
    r = coverage(W, H, pts, primitive="points", point_sizes=np.array([4, 6], np.float32))
    ys, xs = np.nonzero(r["last"] == 0)
    assert len(ys) == 16
    np.testing.assert_allclose(r["point_coord"][ys, xs, 0], 0.5 + (xs + 0.5 - 8.5) / 4)
    np.testing.assert_allclose(r["point_coord"][ys, xs, 1], 0.5 - (ys + 0.5 - 8.5) / 4)
    ys, xs = np.nonzero(r["last"] == 1)
    assert sorted(set(xs)) == [0, 1] and sorted(set(ys)) == list(range(17, 23))


def _projection_reference(pos, viewport):
    """Setup's projection in float64 (ES 3.0 §2.12.1), snapped to 1/256 pixel by rounding to
    nearest, with the per-vertex clip test of Clipper::accepts (guard band of 2^20 pixels)."""
    vx, vy, vw, vh = viewport
    p = pos.astype(np.float64)
    x, y, z, w = p[:, 0], p[:, 1], p[:, 2], p[:, 3]
    with np.errstate(all="ignore"):
        g = float(2 ** 20)
        inside = (np.isfinite(p).all(axis=1) & (w >= 2.0 ** -1022) & (z + w >= 0) & (w - z >= 0) &
                  ((0.5 * vw) * x + (vx + 0.5 * vw + g) * w >= 0) &
                  (-(0.5 * vw) * x + (g - (vx + 0.5 * vw)) * w >= 0) &
                  ((0.5 * vh) * y + (vy + 0.5 * vh + g) * w >= 0) &
                  (-(0.5 * vh) * y + (g - (vy + 0.5 * vh)) * w >= 0))
        wx = (0.5 * vw) * (x / w) + (vx + 0.5 * vw)
        wy = (0.5 * vh) * (y / w) + (vy + 0.5 * vh)
        snap = lambda v: np.floor(np.clip(v, -g, g) * 256 + 0.5)
        ties = inside & ((wx * 256) % 1 == 0.5)
        return inside, ties, snap(wx), snap(wy), 0.5 * (z / w) + 0.5, 1.0 / w


@pytest.mark.parametrize("viewport", [(0, 0, 64, 48), (-7, 13, 1023, 777), (5, -3, 3, 1 << 14)])
def test_project_vertices_every_simd_level(viewport):
    # Every level gives the scalar path's bits, and those are the float64 projection's.
    rng = np.random.default_rng(17)
    n = 4099   # not a multiple of the vector width: the scalar tail runs too
    pos = rng.uniform(-1.5, 1.5, (n, 4)).astype(np.float32)
    pos[:, 3] = rng.choice([1.0, 0.5, 2.0, 1e-3, -1.0, 3e-7], n) * rng.uniform(0.5, 2.0, n)
    pos[::7, :2] = np.round(pos[::7, :2] * 2 ** 14) / 2 ** 14   # many land on half a sub-pixel: ties
    pos[::7, 3] = 1.0
    special = [np.nan, np.inf, -np.inf, 0.0, -0.0, 1e-45, 3e38]
    for k, v in enumerate(special * 9):
        pos[11 * k + 3, k % 4] = v
    xy0, zw0 = _core.testing.project_vertices(0, pos, 1024, 1024, viewport)
    inside, ties, X, Y, z, inv_w = _projection_reference(pos, viewport)
    assert ties.sum() >= 5
    assert inside.sum() > n // 4 and (~inside).sum() > n // 4
    assert np.array_equal(zw0[:, 1] > 0, inside)
    assert np.array_equal(xy0[inside, 0], X[inside]) and np.array_equal(xy0[inside, 1], Y[inside])
    assert np.array_equal(zw0[inside, 0], z[inside]) and np.array_equal(zw0[inside, 1], inv_w[inside])
    for level in range(1, _core.testing.simd_level() + 1):
        xy, zw = _core.testing.project_vertices(level, pos, 1024, 1024, viewport)
        assert np.array_equal(xy, xy0), level
        assert np.array_equal(zw.view(np.int64), zw0.view(np.int64)), level


@pytest.mark.parametrize("seed", range(4))
def test_sample_bounds_keep_every_covered_sample(seed):
    """RasterState::sample_bounds (draws on single-sampled targets) shrinks a triangle's bounding box
    to the pixel centres within its extent and drops small triangles that cover no centre: the same
    samples, depths, weights and owners as the full box, and as the int64 reference. Vertices on a
    quarter pixel grid put pixel centres exactly on edges and extents' borders, where a box one
    pixel too small or a wrong tie in the centre test fails."""
    rng = np.random.default_rng(seed)
    n = 400
    centre = rng.integers(-2, 4 * W + 8, (n, 1, 2)) / 4
    xy = (centre + rng.integers(-4, 5, (n, 3, 2)) / 4).reshape(-1, 2)   # up to 2 pixels across
    clip = clip_from_window(xy, W, H, z=rng.uniform(-1, 1, 3 * n))
    full = coverage(W, H, clip)
    tight = coverage(W, H, clip, sample_bounds=True)
    for key in ("count", "depth", "last", "front", "weights"):
        np.testing.assert_array_equal(tight[key], full[key], err_msg=key)
    fixed = snap(window_from_clip(clip, W, H))
    expected = sum(ref_triangle_coverage(fixed[3 * t:3 * t + 3], W, H) for t in range(n)).astype(np.uint32)
    np.testing.assert_array_equal(tight["count"], expected)
    dropped = full["setup"]["emitted"] - tight["setup"]["emitted"]
    assert dropped > 20
    assert tight["setup"]["outside"] - full["setup"]["outside"] == dropped
    # Covered centres on a border of their triangle's extent (the cases an off-by-one box loses).
    on_border = 0
    for t in range(n):
        v = fixed[3 * t:3 * t + 3]
        py, px, _ = np.nonzero(ref_triangle_coverage(v, W, H))
        cx, cy = px * 256 + 128, py * 256 + 128
        on_border += np.sum((cx == v[:, 0].min()) | (cx == v[:, 0].max()) | (cy == v[:, 1].min()) | (cy == v[:, 1].max()))
    assert on_border > 10
    # Multisampled targets keep the full box.
    ms = coverage(W, H, clip, samples=4, sample_bounds=True)
    assert ms["setup"]["emitted"] == full["setup"]["emitted"]
    np.testing.assert_array_equal(ms["count"], coverage(W, H, clip, samples=4)["count"])
