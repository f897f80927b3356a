"""Homogeneous clipping: vertices behind the eye, w -> 0+, huge coordinates, NaN/Inf, near/far,
watertight clipped meshes. Reference: for each pixel centre, solve for the barycentrics b of the
point of the (homogeneous) triangle that the pixel sees; the pixel is covered when b >= 0, w > 0 and
-w <= z <= w (ES 3.0 §2.17). Pixels within a small margin of any boundary are not compared."""
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from conftest import core, coverage

W = H = 48
MARGIN = 2e-3


def analytic(clip, width=W, height=H):
    c = np.asarray(clip, np.float32).astype(np.float64)
    py, px = np.mgrid[0:height, 0:width] + 0.5
    nx, ny = 2 * px / width - 1, 2 * py / height - 1
    cov = np.zeros((height, width), bool)
    sure = np.zeros((height, width), bool)
    bary = np.zeros((height, width, 3))
    for y in range(height):
        for x in range(width):
            a = np.array([c[:, 0] - nx[y, x] * c[:, 3], c[:, 1] - ny[y, x] * c[:, 3], np.ones(3)])
            try:
                b = np.linalg.solve(a, [0, 0, 1])
            except np.linalg.LinAlgError:
                continue
            p = b @ c
            # Scale-free distances to each boundary, relative to the point's w.
            d = np.concatenate([b / np.abs(b).sum(), [(p[3] + p[2]) / abs(p[3]) if p[3] else -1,
                                                     (p[3] - p[2]) / abs(p[3]) if p[3] else -1]])
            inside = p[3] > 0 and (d >= 0).all()
            cov[y, x] = inside
            sure[y, x] = np.abs(d).min() > MARGIN
            bary[y, x] = b
    return cov, sure, bary


def check(clip, **kw):
    r = coverage(W, H, clip, **kw)
    cov, sure, bary = analytic(clip)
    got = r["count"][..., 0]
    assert got.max() <= 1
    np.testing.assert_array_equal(got[sure], cov[sure].astype(np.uint32))
    both = sure & cov
    np.testing.assert_allclose(r["weights"][both], bary[both], atol=5e-3)
    return r


def test_vertex_behind_the_eye():
    # A floor plane in perspective, one vertex behind the camera (w < 0).
    clip = [[-3.0, -1.0, 2.0, 3.0], [3.0, -1.0, 2.0, 3.0], [0.0, -1.0, -2.2, -2.0]]
    r = check(clip)
    assert r["setup"]["clipped"] == 1 and r["count"].sum() > 50


@pytest.mark.parametrize("seed", range(20))
def test_random_triangles_crossing_w_zero_and_near_far(seed):
    rng = np.random.default_rng(seed)
    clip = rng.uniform(-2, 2, (3, 4))
    clip[:, 3] = rng.uniform(-1, 2, 3)
    check(clip.astype(np.float32))


@pytest.mark.parametrize("w", [1e-3, 1e-7, 1e-20, 1e-30, 1e-38, 1e-45])
def test_w_approaching_zero(w):
    # One vertex at a tiny positive w (down to float32's smallest, 2^-149): no w > 0 is too small
    # to be drawn, and the triangle is the one its three projected vertices span.
    clip = [[-0.5, -0.5, 0, 1], [0.5, -0.6, 0, 1], [0.3 * w, 0.9 * w, 0, w]]
    r = check(clip)
    assert r["count"].sum() > 0


@pytest.mark.parametrize("w", [-1e-3, -1e-6, -1e-9, -1e-20, -1e-30, -1e-38])
def test_w_just_behind_the_eye(w):
    # The same vertex mirrored just behind the eye: the part with w > 0 runs off to infinity
    # between the two other vertices' directions. Its crossing of w = 0 lies next to the tiny
    # vertex, so an error relative to the w = 1 vertices (1e-16) would be larger than the point.
    clip = [[-0.5, -0.5, 0, 1], [0.5, -0.6, 0, 1], [0.3 * -w, 0.9 * -w, 0, w]]
    r = check(clip)
    assert r["count"].sum() > 0 and r["setup"]["clipped"] == 1


def clip_triangle(tri):
    return core.testing.clip_triangle(np.asarray(tri, np.float32), W, H)


EXTREME = [0.0, -0.0, 2.0**-149, 1e-38, 1e-30, 1e-6, 0.25, 1.0, 3.0, 1e6, 2.0**24 + 2, 1e30, 3e38]
COMPONENT = st.sampled_from(EXTREME).flatmap(lambda v: st.sampled_from([v, -v]))


@settings(max_examples=400, deadline=None, database=None, derandomize=True)
@given(st.lists(COMPONENT, min_size=12, max_size=12))
def test_clipped_vertices_never_divide_to_nan(values):
    """Every vertex the clipper hands to setup has w >= 2^-1022 (so 1/w is finite), finite x/w,
    y/w, z/w inside the guard band and the near/far planes (up to rounding), and is the point
    of the triangle its weights say: the perspective division in setup never sees 0/0 and
    snap() never gets NaN. Components from 0 and float32's smallest to its largest."""
    tri = np.array(values, np.float32).reshape(3, 4)
    pos, weights = clip_triangle(tri)
    if len(pos) == 0:
        return
    assert len(pos) >= 3
    w = pos[:, 3]
    assert (w >= 2.0**-1022).all()
    with np.errstate(over="ignore"):
        ndc = pos[:, :3] / w[:, None]
    assert np.isfinite(ndc).all()
    guard = 2.0**20 / (W / 2)                         # the band's half-width in NDC units
    assert (np.abs(ndc[:, :2]) <= (guard + 1) * (1 + 1e-9)).all()
    assert (np.abs(ndc[:, 2]) <= 1 + 1e-9).all()
    assert (weights >= -1e-12).all() and np.allclose(weights.sum(1), 1, rtol=0, atol=1e-9)
    v = tri.astype(np.float64)
    expect = weights @ v
    assert (np.abs(pos - expect) <= 1e-9 * (np.abs(weights) @ np.abs(v)) + 1e-300).all()


@pytest.mark.parametrize("tri", [
    [[0, 0, 0, 1], [0, 1, 0, 1], [0, 0, 0, -1]],                      # x = 0 everywhere
    [[0.3, -0.2, 0.1, 1], [-0.5, 0.4, 0.2, 1], [-0.6, 0.4, -0.2, -2]],   # third vertex = -2 * first
    [[0.5, -0.75, 0.25, 1], [0.25, 0.5, 0.5, 2], [-0.5, 0.75, -0.25, -1]],   # third = -first
])
def test_triangle_crossing_w_zero_through_the_origin(tri):
    """A triangle whose plane contains the clip-space origin (its edge from the first to the third
    vertex passes through it) crosses w = 0 there: its clipped polygon has the origin as a vertex
    (ES 3.0 §2.17 keeps it: -0 <= 0 <= 0) and the whole of it divides to a line segment. The
    clipper drops the origin (no 0/0), nothing has area, nothing is drawn; that edge drawn as a
    line divides to a single point (its part with w > 0 is one ray) and draws nothing either."""
    pos, _ = clip_triangle(tri)
    assert (pos[:, 3] > 0).all()
    r = coverage(W, H, tri)
    assert r["count"].sum() == 0 and r["setup"]["invalid"] == 0
    line = np.array([tri[0], tri[2]], np.float32)
    r = coverage(W, H, line, primitive="lines")
    assert r["count"].sum() == 0 and r["setup"]["invalid"] == 0


def test_points_at_tiny_and_zero_w():
    # A point at w = 2^-149 (float32's smallest) is the point (0, 0) like w = 1; w = 0 is the
    # origin (no point) and w < 0 is behind the eye.
    pts = np.array([[0, 0, 0, 1], [0, 0, 0, 2.0**-149], [0, 0, 0, 0], [0, 0, 0, -2.0**-149]], np.float32)
    counts = [coverage(W, H, pts[i:i + 1], primitive="points")["count"][..., 0] for i in range(4)]
    assert counts[0].sum() == 1
    np.testing.assert_array_equal(counts[1], counts[0])
    assert counts[2].sum() == 0 and counts[3].sum() == 0


@pytest.mark.parametrize("big", [2.0 ** 20, 2.0 ** 24, -(2.0 ** 24), 1e30])
def test_huge_coordinates(big):
    clip = [[-0.9, -0.9, 0, 1], [big, -0.7, 0, 1], [-0.8, 0.9, 0, 1]]
    check(clip)
    clip = [[big, big, 0, 1], [-big, big * 0.5, 0, 1], [0.1, -big, 0, 1]]
    check(clip)
    # An edge from -big to +big through the screen: its guard-band intersections are tiny
    # compared with its endpoints (catastrophic cancellation for plain interpolation).
    clip = [[-big, -big, 0, 1], [big, big, 0, 1], [-big, big, 0, 1]]
    r = check(clip)
    assert r["count"].sum() > W * H / 3


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
@pytest.mark.parametrize("component", range(4))
def test_non_finite_vertices_drop_the_primitive(bad, component):
    clip = np.array([[-0.9, -0.9, 0, 1], [0.9, -0.9, 0, 1], [0, 0.9, 0, 1],
                     [-0.5, -0.5, 0, 1], [0.5, -0.5, 0, 1], [0, 0.5, 0, 1]], np.float32)
    clip[1, component] = bad
    r = coverage(W, H, clip)
    assert r["setup"]["invalid"] == 1
    assert (r["last"][r["count"][..., 0] > 0] == 1).all()
    for prim, n in (("lines", 2), ("points", 1)):
        r = coverage(W, H, clip[:n * (6 // n)], primitive=prim)
        assert r["setup"]["invalid"] == 1


def test_entirely_behind_or_beyond_is_dropped():
    behind = [[-1, -1, 0, -1], [1, -1, 0, -1], [0, 1, 0, -1]]
    beyond_far = [[-1, -1, 2, 1], [1, -1, 3, 1], [0, 1, 2, 1]]
    zero = [[0, 0, 0, 0], [0, 0, 0, 0], [0, 0, 0, 0]]
    r = coverage(W, H, np.array(behind + beyond_far + zero, np.float32))
    assert r["count"].sum() == 0 and r["setup"]["outside"] == 3


def test_near_far_clipping_depth():
    # A triangle spanning z from -3w to 3w: only the part with |z| <= w remains; depth in [0, 1].
    clip = [[-0.9, -0.9, -3, 1], [0.9, -0.9, -3, 1], [0, 0.9, 3, 1]]
    r = check(clip)
    d = r["depth"][r["count"] > 0]
    assert d.min() >= 0 and d.max() <= 1
    rows = np.nonzero(r["count"][..., 0].any(1))[0]
    # z_ndc = -3 + 6 * (y_ndc + 0.9) / 1.8 is inside [-1, 1] for y_ndc in [-0.3, 0.3].
    assert rows.min() >= int((0.7 / 2) * H) - 1 and rows.max() <= int((1.3 / 2) * H)


@pytest.mark.parametrize("seed", range(5))
def test_clipped_mesh_is_watertight(seed):
    """A perspective grid that passes behind the eye and through near/far: shared clipped edges
    produce identical points, so no cracks and no double hits."""
    rng = np.random.default_rng(seed)
    n = 16
    gx, gz = np.meshgrid(np.linspace(-6, 6, n + 1), np.linspace(-4, 30, n + 1))
    gx = gx + rng.uniform(-0.1, 0.1, gx.shape)
    # Eye at the origin looking down -z... in clip space: x, y=-1 (floor), z mapped, w = -z_eye.
    z_eye = -gz
    near, far = 0.5, 20.0
    zc = -(far + near) / (far - near) * z_eye - 2 * far * near / (far - near)
    clip = np.stack([gx, np.full_like(gx, -1.0), zc, -z_eye], -1).reshape(-1, 4).astype(np.float32)
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    tris = []
    for j in range(n):
        for i in range(n):
            a, b, c, d = idx[j, i], idx[j, i + 1], idx[j + 1, i], idx[j + 1, i + 1]
            tris += [(a, b, d), (a, d, c)]
    r = coverage(W, H, clip, indices=np.array(tris, np.uint32))
    count = r["count"][..., 0]
    assert count.max() == 1
    assert r["setup"]["clipped"] > 0
    # The union is a single planar region: compare with the analytic floor between near and far.
    py, px = np.mgrid[0:H, 0:W] + 0.5
    ny = 2 * py / H - 1
    nx = 2 * px / W - 1
    # Floor point seen by the pixel: y_clip = -1 = ny * w  ->  w = -1 / ny (ny < 0).
    with np.errstate(divide="ignore", invalid="ignore"):
        w = -1.0 / ny
        x = nx * w
        zn = (-(far + near) / (far - near) * (-w) - 2 * far * near / (far - near)) / w
        inside = (ny < 0) & (w > 0) & (w <= 30) & (np.abs(zn) <= 1) & (np.abs(x) <= 6)
        edge = ((np.abs(w - 30) < 1) | (np.abs(np.abs(zn) - 1) < 1e-3)
                | (np.abs(np.abs(x) - 6) < 0.4))
    sure = ~edge
    np.testing.assert_array_equal(count[sure], inside[sure].astype(np.uint32))


def test_clipping_is_the_same_for_any_thread_count():
    # Triangles crossing w = 0, near and far, with vertices from 2^-149 to 1e30: the clipped
    # coverage, depth and weights are bit-identical whatever the number of threads.
    rng = np.random.default_rng(3)
    clip = rng.uniform(-2, 2, (600, 4)) * 10.0 ** rng.integers(-40, 30, (600, 1))
    clip[:, 3] = rng.uniform(-1, 2, 600) * 10.0 ** rng.integers(-40, 2, 600)
    clip = clip.astype(np.float32)
    runs = [coverage(W, H, clip, threads=t) for t in (1, 2, 3)]
    assert runs[0]["setup"]["clipped"] > 50
    for r in runs[1:]:
        for key in ("count", "depth", "last", "weights"):
            np.testing.assert_array_equal(r[key], runs[0][key])
