"""Area coverage (SOFTGL_smooth, pipeline/coverage.h) against independent references: exact
rational polygon clipping, shoelace areas, separable rectangle overlaps, and Gauss-Legendre disk
areas. Shapes are the snapped primitives (1/256 pixel), as the C++ documents."""
import math

import numpy as np
import pytest

from area_reference import (disk_rect_area_quadrature, polygon_pixel_areas, snapped_polygon)
from conftest import clip_from_window, core, coverage, snap, window_from_clip
from test_watertight import grid_mesh

W, H = 48, 40


def area(xy, width=W, height=H, **kw):
    return core.raster_area(width, height, clip_from_window(xy, width, height), **kw)


def fixed_of(xy, width=W, height=H):
    return snap(window_from_clip(clip_from_window(xy, width, height), width, height))


def shoelace(fixed):
    v = np.asarray(fixed, np.float64) / 256
    return 0.5 * abs(sum(v[i, 0] * v[(i + 1) % len(v), 1] - v[(i + 1) % len(v), 0] * v[i, 1]
                         for i in range(len(v))))


# ---- triangles ----

@pytest.mark.parametrize("seed", range(10))
def test_random_triangle_sum_is_its_area(seed):
    rng = np.random.default_rng(seed)
    for _ in range(20):
        xy = rng.uniform(1, [W - 1, H - 1], (3, 2))
        r = area(xy)
        a = shoelace(fixed_of(xy))
        if a == 0:
            continue
        assert r["total"] == pytest.approx(a, rel=1e-9, abs=1e-12)
        assert r["coverage"].sum() == pytest.approx(a, rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("seed", range(4))
def test_triangle_per_pixel_matches_exact_rational_clipping(seed):
    rng = np.random.default_rng(40 + seed)
    for _ in range(3):
        xy = rng.uniform(-3, [W + 3, H + 3], (3, 2))     # partly off-screen too
        r = area(xy)
        ref = polygon_pixel_areas(snapped_polygon(fixed_of(xy)), W, H)
        np.testing.assert_allclose(r["coverage"], ref, rtol=0, atol=1e-12)
        # Conservative: a fragment exactly where the area is positive.
        np.testing.assert_array_equal(r["fragments"], (ref > 0).astype(np.uint32))


def test_axis_aligned_edge_half_covers_pixels_exactly():
    # Rectangle [2.5, 20.5] x [3, 9] as two triangles: columns 2 and 20 are exactly half covered.
    xy = [(2.5, 3), (20.5, 3), (20.5, 9), (2.5, 3), (20.5, 9), (2.5, 9)]
    cov = area(xy)["coverage"]
    assert (cov[3:9, 2] == 0.5).all() and (cov[3:9, 20] == 0.5).all()
    np.testing.assert_allclose(cov[3:9, 3:20], 1.0, rtol=0, atol=1e-15)
    # Horizontal edges through pixel middles, a single triangle: exactly 0.5 away from the other edges.
    cov = area([(1, 4.5), (40, 4.5), (1, 30.5)])["coverage"]
    assert (cov[4, 2:10] == 0.5).all()
    assert (cov[30, 1] > 0) and cov[31].sum() == 0


def test_sample_raster_pixels_are_a_subset():
    """Every pixel the sample-based raster covers gets a fragment (with positive fraction), plus the
    partially covered pixels whose centre is outside."""
    rng = np.random.default_rng(3)
    for _ in range(30):
        xy = rng.uniform(0, [W, H], (3, 2))
        clip = clip_from_window(xy, W, H)
        samples = coverage(W, H, clip)["count"][..., 0]
        r = core.raster_area(W, H, clip)
        assert (r["fragments"][samples > 0] == 1).all()
        assert r["fragments"].sum() >= samples.sum()


def test_two_triangles_sharing_an_edge_sum_to_one():
    rng = np.random.default_rng(5)
    for _ in range(40):
        p = rng.uniform(1, [W - 1, H - 1], (4, 2))
        # A convex quad split along a diagonal (skip non-convex draws).
        fixed = fixed_of(p)
        def cross(u, v):
            return u[0] * v[1] - u[1] * v[0]
        cross = [cross(fixed[(i + 1) % 4] - fixed[i], fixed[(i + 2) % 4] - fixed[(i + 1) % 4])
                 for i in range(4)]
        if not (all(c > 0 for c in cross) or all(c < 0 for c in cross)):
            continue
        r = area(p[[0, 1, 2, 0, 2, 3]])
        ref = polygon_pixel_areas(snapped_polygon(fixed), W, H)
        np.testing.assert_allclose(r["coverage"], ref, rtol=0, atol=1e-9)


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("n,jitter", [(5, 0.24), (24, 0.2)])
def test_mesh_covers_each_pixel_exactly_once(seed, n, jitter):
    rng = np.random.default_rng(seed)
    x0, y0, x1, y1 = (3, 2, 43, 37) if seed % 2 else (3.3, 2.7, 42.6, 36.1)
    xy, tris = grid_mesh(rng, n, x0, y0, x1, y1, jitter)
    r = core.raster_area(W, H, clip_from_window(xy, W, H), indices=tris)
    # Expected: the snapped outline rectangle's overlap with each pixel (separable).
    X0, Y0, X1, Y1 = (int(np.floor(v * 256 + 0.5)) / 256 for v in (x0, y0, x1, y1))
    ox = np.clip(np.minimum(np.arange(W) + 1, X1) - np.maximum(np.arange(W), X0), 0, 1)
    oy = np.clip(np.minimum(np.arange(H) + 1, Y1) - np.maximum(np.arange(H), Y0), 0, 1)
    np.testing.assert_allclose(r["coverage"], oy[:, None] * ox[None, :], rtol=0, atol=1e-9)


def test_fan_around_a_vertex_inside_a_pixel():
    c = np.array([20.3, 17.6])
    k = 37
    ang = np.sort(np.random.default_rng(9).uniform(0, 2 * np.pi, k))
    ring = c + np.stack([np.cos(ang), np.sin(ang)], 1) * 9
    xy = np.concatenate([[c, ring[i], ring[(i + 1) % k]] for i in range(k)])
    cov = area(xy)["coverage"]
    ref = polygon_pixel_areas(snapped_polygon(fixed_of(ring)), W, H)
    np.testing.assert_allclose(cov, ref, rtol=0, atol=1e-9)
    assert cov[17, 20] == pytest.approx(1.0, abs=1e-12)


def test_tiny_triangles_inside_one_pixel():
    rng = np.random.default_rng(12)
    for _ in range(100):
        p = rng.integers(2, 30, 2) + rng.uniform(0.05, 0.95, 2)
        xy = p + rng.uniform(-0.04, 0.04, (3, 2))
        r = area(xy)
        a = shoelace(fixed_of(xy))
        assert r["total"] == pytest.approx(a, rel=1e-9, abs=1e-15)
        if a > 0:
            assert r["fragment_count"] == 1
            px, py = np.floor(p).astype(int)
            assert r["coverage"][py, px] == pytest.approx(a, rel=1e-9)


def test_slivers():
    rng = np.random.default_rng(13)
    for _ in range(60):
        a = rng.uniform(1, [W - 1, H - 1])
        b = rng.uniform(1, [W - 1, H - 1])
        m = 0.5 * (a + b) + rng.uniform(-1, 1, 2) / 256 * rng.integers(1, 4)
        xy = np.array([a, b, m])
        r = area(xy)
        ar = shoelace(fixed_of(xy))
        assert r["total"] == pytest.approx(ar, rel=1e-7, abs=1e-13)
        ref = polygon_pixel_areas(snapped_polygon(fixed_of(xy)), W, H)
        np.testing.assert_allclose(r["coverage"], ref, rtol=0, atol=1e-12)


def test_scissor_clips_area():
    xy = [(2, 2), (40, 3), (20, 35)]
    full = area(xy)["coverage"]
    cut = area(xy, scissor=(10, 5, 12, 9))["coverage"]
    expect = np.zeros_like(full)
    expect[5:14, 10:22] = full[5:14, 10:22]
    np.testing.assert_array_equal(cut, expect)


def test_threads_do_not_change_results():
    rng = np.random.default_rng(21)
    xy = rng.uniform(-20, 300, (3 * 400, 2))
    a = core.raster_area(256, 200, clip_from_window(xy, 256, 200), threads=1)
    b = core.raster_area(256, 200, clip_from_window(xy, 256, 200), threads=3)
    np.testing.assert_array_equal(a["coverage"], b["coverage"])
    assert a["total"] == b["total"]


# ---- points ----

def test_disk_rect_area_matches_quadrature():
    rng = np.random.default_rng(1)
    for _ in range(300):
        cx, cy = rng.uniform(-2, 2, 2)
        r = rng.uniform(0.05, 3)
        x0, y0 = rng.uniform(-3, 3, 2)
        x1, y1 = x0 + rng.uniform(0, 2), y0 + rng.uniform(0, 2)
        assert core.disk_rect_area(cx, cy, r, x0, y0, x1, y1) == pytest.approx(
            disk_rect_area_quadrature(cx, cy, r, x0, y0, x1, y1), abs=1e-13)


@pytest.mark.parametrize("size", [1.0, 1.5, 2.0, 3.3828125, 7.0, 17.25, 60.0])
def test_disk_point_sum_is_pi_r2(size):
    rng = np.random.default_rng(int(size * 100))
    for _ in range(5):
        c = rng.uniform(30, 70, 2)
        r = core.raster_area(100, 100, clip_from_window([c], 100, 100), primitive="points",
                             point_sizes=np.array([size], np.float32))
        radius = np.floor(size * 128 + 0.5) / 256     # setup snaps the size to 1/128 pixel
        assert r["total"] == pytest.approx(math.pi * radius ** 2, rel=1e-10)
        # Per pixel against the quadrature, and a fragment wherever the disk has area.
        f = snap(window_from_clip(clip_from_window([c], 100, 100), 100, 100))[0] / 256
        cov = r["coverage"]
        ys, xs = np.nonzero(cov >= 0)
        near = (np.abs(xs + 0.5 - f[0]) < radius + 1) & (np.abs(ys + 0.5 - f[1]) < radius + 1)
        for x, y in zip(xs[near], ys[near]):
            q = disk_rect_area_quadrature(f[0], f[1], radius, x, y, x + 1, y + 1)
            assert cov[y, x] == pytest.approx(q, abs=1e-11)
            assert (r["fragments"][y, x] == 1) == (q > 1e-15)
        assert cov[ys[~near], xs[~near]].sum() == 0


def test_square_point_sum_is_size_squared():
    for size in (1.0, 2.5, 6.0, 9.75):
        r = core.raster_area(40, 40, clip_from_window([(17.3, 20.1)], 40, 40), primitive="points",
                             point_sizes=np.array([size], np.float32), point_shape="square")
        assert r["total"] == pytest.approx(size * size, rel=1e-12)


# ---- smooth lines: rectangles ----

def rectangle_corners(a, b, width):
    a, b = np.asarray(a, float) / 256, np.asarray(b, float) / 256
    d = b - a
    n = np.array([-d[1], d[0]]) / np.hypot(*d) * width / 2
    return [a - n, b - n, b + n, a + n]


@pytest.mark.parametrize("width", [1.0, 0.5, 2.25, 5.0])
def test_smooth_line_sum_is_length_times_width(width):
    rng = np.random.default_rng(int(width * 8))
    for _ in range(25):
        xy = rng.uniform(8, [W - 8, H - 8], (2, 2))
        r = area(xy, primitive="lines", line_width=width)
        f = fixed_of(xy)
        length = np.hypot(*(f[1] - f[0])) / 256
        assert r["total"] == pytest.approx(length * width, rel=1e-9)


def test_smooth_line_per_pixel_matches_rectangle_clipping():
    rng = np.random.default_rng(77)
    for width in (1.0, 3.5):
        for _ in range(6):
            xy = rng.uniform(6, [W - 6, H - 6], (2, 2))
            r = area(xy, primitive="lines", line_width=width)
            f = fixed_of(xy)
            ref = polygon_pixel_areas(rectangle_corners(f[0], f[1], width), W, H)
            np.testing.assert_allclose(r["coverage"], ref, rtol=0, atol=1e-9)
            # Every pixel the rectangle meets in positive area has a fragment.
            assert (r["fragments"][ref > 1e-9] == 1).all()


# ---- FASTEST: the sampled estimate ----

@pytest.mark.parametrize("grid", [1, 4, 8, 16, 64])
def test_sampled_estimate_within_documented_bound(grid):
    rng = np.random.default_rng(grid)
    for _ in range(10):
        xy = rng.uniform(0, [W, H], (3, 2))
        exact = area(xy)["coverage"]
        est = area(xy, sampled=True, grid=grid)["coverage"]
        assert np.abs(est - exact).max() <= core.sampled_error_bound(grid, 3) + 1e-12
    for size in (2.0, 5.5, 13.0):
        kw = dict(primitive="points", point_sizes=np.array([size], np.float32))
        exact = area([(20.3, 19.9)], **kw)["coverage"]
        est = area([(20.3, 19.9)], sampled=True, grid=grid, **kw)["coverage"]
        assert np.abs(est - exact).max() <= core.sampled_error_bound(grid, -1) + 1e-12


def test_sampled_estimate_converges():
    rng = np.random.default_rng(99)
    xy = rng.uniform(0, [W, H], (3 * 8, 2))
    exact = area(xy)["coverage"]
    errors = [np.abs(area(xy, sampled=True, grid=g)["coverage"] - exact).max()
              for g in (2, 8, 32, 128)]
    assert errors[0] > errors[1] > errors[2] > errors[3]
    assert errors[3] < 0.02


def test_sampled_mesh_is_watertight():
    """Samples on shared edges follow the tie rule: each sample counted once, so a mesh over a
    pixel-aligned rectangle sums to exactly 1 in every pixel (k / 64 sums are exact in binary)."""
    rng = np.random.default_rng(4)
    xy, tris = grid_mesh(rng, 12, 3, 2, 43, 37, 0.24)
    r = core.raster_area(W, H, clip_from_window(xy, W, H), indices=tris, sampled=True, grid=8)
    expect = np.zeros((H, W))
    expect[2:37, 3:43] = 1
    np.testing.assert_array_equal(r["coverage"], expect)


def test_invalid_grid_rejected():
    with pytest.raises(ValueError):
        area([(1, 1), (9, 1), (1, 9)], sampled=True, grid=6)
