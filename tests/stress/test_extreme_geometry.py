"""Geometry at the edges of the number line, against an exact homogeneous-clipping reference:
coordinates near +-2^24 and far beyond, tiny ones, w -> 0+, w < 0 and vertices behind the eye,
slivers and zero-area triangles. Defined behaviour (docs/reliability.md): a triangle covers the
pixel centres of its part inside the clip volume (ES 3.0 §2.13, -w <= x, y, z <= w), which for a
vertex with w <= 0 is the projective triangle the clipper keeps; nothing is drawn twice."""
import math
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from stress_helpers import Painter, centres_inside, context, pixels

W = H = 32
STEP = 3 / 255
PLANES = [(1, 0, 0, 1), (-1, 0, 0, 1), (0, 1, 0, 1), (0, -1, 0, 1), (0, 0, 1, 1), (0, 0, -1, 1)]


def clip_polygon(verts):
    """Sutherland-Hodgman in homogeneous coordinates against the six planes of the clip volume
    -w <= x, y, z <= w (ES 3.0 §2.17), in exact rational arithmetic (float64 loses everything at
    2^100 or near w = 0; Fractions lose nothing)."""
    poly = [[Fraction(float(c)) for c in v] for v in verts]
    for plane in PLANES:
        out = []
        for i in range(len(poly)):
            a, b = poly[i], poly[(i + 1) % len(poly)]
            da = sum(p * c for p, c in zip(plane, a))
            db = sum(p * c for p, c in zip(plane, b))
            if da >= 0:
                out.append(a)
            if (da >= 0) != (db >= 0):
                t = da / (da - db)
                out.append([ca + t * (cb - ca) for ca, cb in zip(a, b)])
        poly = out
        if not poly:
            return []
    return poly


def reference(tri, margin=0.01):
    """(inside, ambiguous) pixel masks of a clip-space triangle (float32 values). Exact: the side
    of every pixel centre of every edge of the clipped polygon is an integer's sign; only the
    distance compared with `margin` (pixels) is rounded."""
    poly = clip_polygon(np.asarray(tri, np.float32).astype(np.float64))
    # Inside the clip volume only the origin has w = 0. It is no point of the projective plane and
    # adds nothing to the picture: a point t*O + (1-t)*Q divides to the same window position as Q.
    poly = [(p[0], p[1], p[3]) for p in poly if p[3] != 0]
    inside = np.zeros((H, W), bool)
    if len(poly) < 3:
        return inside, inside.copy()
    ndc = [(x / w, y / w) for x, y, w in poly]
    area2 = sum(a[0] * b[1] - b[0] * a[1] for a, b in zip(ndc, ndc[1:] + ndc[:1]))
    orient = 1 if area2 > 0 else -1
    # Pixel centres in NDC times W (= H): (2 px + 1 - W, 2 py + 1 - H), as Python integers.
    cx, cy = (c.astype(object) for c in np.meshgrid(np.arange(W) * 2 + 1 - W, np.arange(H) * 2 + 1 - H))
    d_min = np.full((H, W), np.inf)
    for a, b in zip(poly, poly[1:] + poly[:1]):
        # The edge's line L = a x b in homogeneous (x, y, w): with w_a, w_b > 0, L . (X, Y, 1) has
        # the sign of the orientation of (a/w_a, b/w_b, (X, Y)); times `orient`, >= 0 inside.
        line = [orient * (a[1] * b[2] - a[2] * b[1]), orient * (a[2] * b[0] - a[0] * b[2]),
                orient * (a[0] * b[1] - a[1] * b[0])]
        if not any(line):
            continue   # a repeated vertex
        den = math.lcm(*(c.denominator for c in line))
        lx, ly, lw = (int(c * den) for c in line)
        side = np.sign(lx * cx + ly * cy + lw * W).astype(float)
        # Distance in pixels for the margin: (L . centre) / |(lx, ly)| in NDC units of W/2 pixels.
        big = max(abs(lx), abs(ly), abs(lw))
        fx, fy, fw = (float(Fraction(c, big)) for c in (lx, ly, lw))
        with np.errstate(divide="ignore"):
            dist = np.abs(fx * cx.astype(float) + fy * cy.astype(float) + fw * W) / (2 * np.hypot(fx, fy))
        d_min = np.minimum(d_min, np.where(side == 0, 0.0, side * dist))
    if area2 == 0:
        return inside, np.abs(d_min) <= margin
    return d_min > margin, np.abs(d_min) <= margin


def draw(tris, mode="TRIANGLES", w=W, h=H, **kw):
    gl = context(w, h, **kw)
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.ONE, gl.ONE)
    p = Painter(gl, uniform_color=True)
    p.draw(getattr(gl, mode), np.asarray(tris, np.float32).reshape(-1, 4), color=(STEP,) * 4)
    img = pixels(gl)
    assert (img % 3 == 0).all()
    return gl, img[..., 0] // 3


def check_against_reference(tri):
    gl, count = draw(tri)
    inside, ambiguous = reference(tri)
    assert count.max() <= 1
    missed = inside & (count == 0)
    extra = ~inside & ~ambiguous & (count > 0)
    assert not missed.any(), f"{int(missed.sum())} pixels inside the clipped triangle not drawn"
    assert not extra.any(), f"{int(extra.sum())} pixels outside the clipped triangle drawn"
    return gl, count


finite = st.floats(-4, 4, allow_nan=False, width=32)


def random_triangle(xy, z, w):
    return [[xy[2 * i] * abs(w[i]) if w[i] else xy[2 * i], xy[2 * i + 1] * abs(w[i]) if w[i] else xy[2 * i + 1],
             z[i] * abs(w[i]), w[i]] for i in range(3)]


XY = st.lists(finite, min_size=6, max_size=6)
Z = st.lists(st.floats(-2, 2, width=32), min_size=3, max_size=3)


@settings(max_examples=40, deadline=None)
@given(xy=XY, z=Z, w=st.lists(st.sampled_from([1.0, 0.5, 2.0, 1e-3, 2.0**-20, -0.25, -0.5, -1.0, -3.0]),
                               min_size=3, max_size=3))
def test_homogeneous_clipping_matches_exact_reference(xy, z, w):
    """Random triangles with any mix of w > 0, w -> 0+ and w < 0 (behind the eye), against exact
    rational clipping."""
    check_against_reference(random_triangle(xy, z, w))


@settings(max_examples=200, deadline=None, database=None, derandomize=True)
@given(xy=XY, z=Z, w=st.lists(st.sampled_from([1.0, 1e-30, 0.0, -1e-30, -2.0**-20, -1e-6, -1.0]), min_size=3, max_size=3))
def test_clipping_near_w_zero_matches_exact_reference(xy, z, w):
    """Vertices at w = 0, just in front of and just behind the eye, mixed with w = +-1: the clipper
    keeps every w > 0 (no epsilon plane) and computes crossings from the endpoints' minors, so the
    part in front of the eye is exact however close to w = 0 a vertex is (bugs 3, 4 and 11)."""
    check_against_reference(random_triangle(xy, z, w))


def test_triangle_through_the_clip_space_origin_draws_nothing():
    # All three vertices have x = 0, so every point of the triangle does: window x = 16 exactly, no
    # area. Clipping the edges to (0,0,0,-1) against w >= 0, near and far all meet at (0,0,0,0),
    # which once gave a 0/0 window vertex (NaN into snap()) and 320 pixels drawn.
    tri = [[0, 0, 0, 1], [0, 1, 0, 1], [0, 0, 0, -1]]
    gl, count = draw(tri)
    assert count.sum() == 0


@pytest.mark.parametrize("w", [-1e-5, -1e-6, -1e-9, -1e-20, -1e-30, -1e-38])
def test_vertex_just_behind_the_eye_keeps_its_visible_quadrant(w):
    # A = centre, B = top centre, C = a point at NDC (-1e-6, 0) with w < 0. The part with w > 0
    # is the quadrant x > 0, y > 0 of the screen (exact rational clipping agrees). At w = -1e-6
    # the crossing of w = 0 was once computed with an error larger than itself: nothing drawn.
    w = np.float32(w)
    tri = [[0, 0, 0, 1], [0, 1, 0, 1], [np.float32(1e-6) * -w, 0, 0, w]]
    gl, count = draw(tri)
    expected = np.zeros((H, W), int)
    expected[H // 2:, W // 2:] = 1
    np.testing.assert_array_equal(count, expected)
    check_against_reference(tri)


def test_all_vertices_behind_the_eye_draw_nothing():
    # w < 0 everywhere: no point satisfies -w <= x <= w (ES 3.0 §2.13), even when x/w is on screen.
    tri = [[-0.5, -0.5, 0, -1], [0.5, -0.5, 0, -1], [0, 0.5, 0, -1]]
    gl, count = draw(tri)
    assert count.sum() == 0
    assert gl.stats()["primitives_outside"] == 1


def test_vertex_behind_the_eye_is_clipped_not_projected():
    """A triangle with one vertex behind the eye draws its in-front part, not the mirrored image
    that dividing by a negative w would give."""
    tri = [[-0.8, -0.8, 0, 1], [0.8, -0.8, 0, 1], [0.0, 3.0, 0, -1]]
    gl, count = check_against_reference(tri)
    assert count.sum() > 0 and gl.stats()["primitives_clipped"] == 1


@pytest.mark.parametrize("scale", [2.0**24 - 1, 2.0**24, 2.0**24 + 2, 2.0**40, 2.0**100, 3.0e38])
def test_huge_coordinates_are_clipped_exactly(scale):
    """Vertices near and far beyond +-2^24: the half-plane x + y <= 0 cut by a huge triangle."""
    s = np.float32(scale)
    tri = [[-s, -s, 0, 1], [s, -s, 0, 1], [-s, s, 0, 1]]   # hypotenuse x + y = 0
    gl, count = check_against_reference(tri)
    cx, cy = np.meshgrid(np.arange(W) + 0.5, np.arange(H) + 0.5)
    assert (count[cx + cy < W - 0.01] == 1).all()
    assert (count[cx + cy > W + 0.01] == 0).all()


@pytest.mark.parametrize("w", [2.0**-110, 2.0**-100, 2.0**-60, 2.0**-20, 1.0, 2.0**20, 2.0**60, 2.0**100])
def test_scaling_all_of_xyzw_changes_nothing(w):
    """(x, y, z, w) and (kx, ky, kz, kw) are the same point: exact for powers of two, from tiny to
    huge w (float32 keeps every value exact). There is no smallest w: 2^-110 draws like 1."""
    rng = np.random.default_rng(11)
    tris = rng.uniform(-1.3, 1.3, (40, 3, 4)).astype(np.float32)
    tris[..., 3] = 1
    scaled_tris = tris * np.float32(w)
    assert np.array_equal(scaled_tris.astype(np.float64) / w, tris)   # the scaling is exact
    _, base = draw(tris)
    _, scaled = draw(scaled_tris)
    np.testing.assert_array_equal(scaled, base)


@pytest.mark.parametrize("size", [1e-3, 1e-7, 1e-20, 1e-38, 1e-45])
def test_tiny_triangles_draw_at_most_their_pixel(size):
    """A triangle much smaller than the 1/256-pixel grid snaps to zero area: nothing is drawn
    and the primitive is counted as zero-area, not as an error."""
    centre = np.float32(0.3)
    tri = [[centre, centre, 0, 1], [centre + size, centre, 0, 1], [centre, centre + size, 0, 1]]
    gl, count = draw(tri)
    assert count.sum() <= 1
    if size < 1e-4:
        assert count.sum() == 0
        s = gl.stats()
        assert s["primitives_zero_area"] + s["primitives_outside"] == 1 and s["primitives_invalid"] == 0


def test_mesh_finer_than_the_subpixel_grid_is_watertight():
    """A 400x400 grid over 2x2 pixels (cells of 0.003 pixel, under one subpixel): after snapping many
    triangles are degenerate, but the union still covers each pixel centre exactly once."""
    n = 400
    x0, x1 = 10.37, 11.61
    xs = np.linspace(x0, x1, n + 1)
    gx, gy = np.meshgrid(xs, xs)
    xy = np.stack([gx.ravel(), gy.ravel()], 1)
    clip = np.zeros((len(xy), 4), np.float32)
    clip[:, 0] = xy[:, 0] / W * 2 - 1
    clip[:, 1] = xy[:, 1] / H * 2 - 1
    clip[:, 3] = 1
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    tris = np.concatenate([np.stack([idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel()], 1),
                           np.stack([idx[:-1, :-1].ravel(), idx[1:, 1:].ravel(), idx[1:, :-1].ravel()], 1)])
    gl = context(W, H)
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.ONE, gl.ONE)
    Painter(gl, uniform_color=True).draw(gl.TRIANGLES, clip, indices=tris, color=(STEP,) * 4)
    count = pixels(gl)[..., 0] // 3
    c = np.arange(W) + 0.5
    inside = (c > x0) & (c < x1)
    np.testing.assert_array_equal(count, (inside[:, None] & inside[None, :]).astype(int))
    assert gl.stats()["primitives_zero_area"] > 0


@pytest.mark.parametrize("seed", range(4))
def test_sliver_pairs_share_their_long_edge(seed):
    """Quads 1e-3 to 0.5 pixel tall and 30 pixels long, split along the long diagonal: the two
    slivers together hit the pixel centres of the quad once."""
    rng = np.random.default_rng(seed)
    gl = context(W, H)
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.ONE, gl.ONE)
    p = Painter(gl, uniform_color=True)
    polys = []
    for k in range(12):
        y = 1.5 + 2.5 * k + rng.uniform(-0.3, 0.3)
        hgt = [1e-3, 0.01, 0.2, 0.5][k % 4]
        x0, x1 = rng.uniform(0.5, 2), rng.uniform(30, 31.5)
        slope = rng.uniform(-0.02, 0.02)
        quad = np.array([[x0, y], [x1, y + slope * (x1 - x0)], [x1, y + slope * (x1 - x0) + hgt], [x0, y + hgt]])
        polys.append(quad)
        clip = np.zeros((4, 4), np.float32)
        clip[:, 0] = quad[:, 0] / W * 2 - 1
        clip[:, 1] = quad[:, 1] / H * 2 - 1
        clip[:, 3] = 1
        p.draw(gl.TRIANGLES, clip, indices=[0, 1, 2, 0, 2, 3], color=(STEP,) * 4)
    count = pixels(gl)[..., 0] // 3
    assert count.max() <= 1
    inside, ambiguous = centres_inside(polys, W, H)
    assert (count[inside] == 1).all() and (count[~inside & ~ambiguous] == 0).all()


@pytest.mark.parametrize("kind", ["collinear", "repeated", "point"])
def test_zero_area_triangles_draw_nothing(kind):
    a, b = np.array([-0.5, -0.25]), np.array([0.5, 0.25])   # the midpoint is exactly collinear
    v = {"collinear": [a, b, (a + b) / 2 + 0], "repeated": [a, b, b], "point": [a, a, a]}[kind]
    tri = [[x, y, 0, 1] for x, y in v]
    gl, count = draw(tri)
    assert count.sum() == 0
    assert gl.stats()["primitives_zero_area"] == 1
