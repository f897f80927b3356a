"""Watertightness (docs/architecture.md, "Numeric rules"): a mesh hits every covered sample exactly
once, with no cracks along shared edges and no double hits, for grids with jittered vertices, fans
and strips, including tiny and sliver triangles, in both windings."""
import numpy as np
import pytest

from conftest import clip_from_window, coverage, ref_mesh_count

W = H = 96


def grid_mesh(rng, n, x0, y0, x1, y1, jitter):
    """(n+1)^2 vertices on [x0,x1]x[y0,y1]; interior vertices jittered by up to `jitter` cells (< 0.25
    keeps every cell convex, so the mesh never folds over itself),
    boundary vertices jittered along the boundary only, so the union is exactly the rectangle."""
    xs, ys = np.linspace(x0, x1, n + 1), np.linspace(y0, y1, n + 1)
    gx, gy = np.meshgrid(xs, ys)
    cx, cy = (x1 - x0) / n, (y1 - y0) / n
    jx = rng.uniform(-jitter, jitter, gx.shape) * cx
    jy = rng.uniform(-jitter, jitter, gy.shape) * cy
    jx[:, [0, -1]] = 0
    jy[[0, -1], :] = 0
    gx, gy = gx + jx, gy + jy
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    tris = []
    for j in range(n):
        for i in range(n):
            a, b, c, d = idx[j, i], idx[j, i + 1], idx[j + 1, i], idx[j + 1, i + 1]
            if rng.random() < 0.5:
                tris += [(a, b, d), (a, d, c)]
            else:
                tris += [(a, b, c), (b, d, c)]
    tris = np.array(tris, np.uint32)
    flip = rng.random(len(tris)) < 0.5          # random winding: no culling, both facings
    tris[flip] = tris[flip][:, [0, 2, 1]]
    return np.stack([gx.ravel(), gy.ravel()], 1), tris


def rect_expected(x0, y0, x1, y1):
    """Pixels whose centre is in the rectangle, left and bottom edges included."""
    X0, Y0, X1, Y1 = (int(np.floor(v * 256 + 0.5)) for v in (x0, y0, x1, y1))
    c = np.arange(W) * 256 + 128
    inx = (c >= X0) & (c < X1)
    iny = (np.arange(H) * 256 + 128 >= Y0) & (np.arange(H) * 256 + 128 < Y1)
    return (iny[:, None] & inx[None, :]).astype(np.uint32)


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("n,jitter", [(6, 0.24), (20, 0.24), (60, 0.2), (150, 0.15)])
def test_jittered_grid_is_watertight(seed, n, jitter):
    rng = np.random.default_rng(seed)
    x0, y0 = rng.uniform(2, 10, 2)
    x1, y1 = rng.uniform(80, 94, 2)
    if seed % 2:    # pixel-centre-aligned outline: ties on the boundary
        x0, y0, x1, y1 = 4.5, 5.5, 88.5, 90.5
    xy, tris = grid_mesh(rng, n, x0, y0, x1, y1, jitter)
    r = coverage(W, H, clip_from_window(xy, W, H), indices=tris)
    count = r["count"][..., 0]
    assert count.max() <= 1, "double hits on shared edges"
    np.testing.assert_array_equal(count, rect_expected(x0, y0, x1, y1))


@pytest.mark.parametrize("seed", range(4))
def test_grid_matches_reference_rule(seed):
    rng = np.random.default_rng(100 + seed)
    xy, tris = grid_mesh(rng, 12, 3.3, 2.7, 91.1, 93.9, 0.24)
    clip = clip_from_window(xy, W, H)
    r = coverage(W, H, clip, indices=tris)
    np.testing.assert_array_equal(r["count"], ref_mesh_count(clip, tris, W, H))


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("segments", [7, 64, 700])
def test_fan_is_watertight(seed, segments):
    """A fan around an interior point of a convex polygon; 700 segments give slivers."""
    rng = np.random.default_rng(seed)
    cx, cy = rng.uniform(40, 56, 2)
    angles = np.sort(rng.uniform(0, 2 * np.pi, segments))
    radius = rng.uniform(30, 40)
    ring = np.stack([cx + radius * np.cos(angles), cy + radius * np.sin(angles)], 1)
    centre = ring.mean(0) if segments < 10 else np.array([cx, cy])
    xy = np.vstack([centre, ring])
    tris = np.array([(0, 1 + i, 1 + (i + 1) % segments) for i in range(segments)], np.uint32)
    clip = clip_from_window(xy, W, H)
    r = coverage(W, H, clip, indices=tris)
    count = r["count"][..., 0]
    assert count.max() <= 1
    # Exact: the sum of the independent per-triangle reference.
    np.testing.assert_array_equal(r["count"], ref_mesh_count(clip, tris, W, H))
    # No cracks: every pixel centre clearly inside the polygon is covered once.
    py, px = np.mgrid[0:H, 0:W] + 0.5
    inside = np.ones((H, W), bool)
    for i in range(segments):
        (x0, y0), (x1, y1) = ring[i], ring[(i + 1) % segments]
        cross = (x1 - x0) * (py - y0) - (y1 - y0) * (px - x0)
        inside &= cross / np.hypot(x1 - x0, y1 - y0) > 0.01
    assert (count[inside] == 1).all()


@pytest.mark.parametrize("seed", range(6))
def test_strip_is_watertight(seed):
    """A zig-zag strip (GL strip order: odd triangles swapped to keep the winding) of tiny and
    sliver triangles along a wavy band."""
    rng = np.random.default_rng(seed)
    n = 400
    x = np.sort(rng.uniform(3, 93, n))
    mid = 48 + 20 * np.sin(x / 9.0 + seed)
    half = rng.uniform(0.05, 6, n)
    xy = np.stack([x, mid + np.where(np.arange(n) % 2, half, -half)], 1)
    tris = np.array([(i, i + 1, i + 2) if i % 2 == 0 else (i + 1, i, i + 2) for i in range(n - 2)],
                    np.uint32)
    clip = clip_from_window(xy, W, H)
    r = coverage(W, H, clip, indices=tris)
    assert r["count"].max() <= 1
    np.testing.assert_array_equal(r["count"], ref_mesh_count(clip, tris, W, H))


def test_tiny_triangles_cover_each_centre_once():
    """A 0.37-pixel grid: almost every triangle covers no pixel centre, yet together they cover all."""
    rng = np.random.default_rng(7)
    xy, tris = grid_mesh(rng, 200, 10.25, 11.75, 84.25, 85.75, 0.24)
    r = coverage(W, H, clip_from_window(xy, W, H), indices=tris)
    np.testing.assert_array_equal(r["count"][..., 0], rect_expected(10.25, 11.75, 84.25, 85.75))
