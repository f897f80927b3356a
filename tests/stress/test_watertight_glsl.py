"""Watertightness through the whole GLSL draw path (buffers, vertex shader, clipping, setup,
raster, fragment shader, blending): a mesh drawn with blendFunc(ONE, ONE) in a small color adds
exactly one step to every pixel whose centre it covers, and nothing elsewhere. Random jittered
grids, fans and strips (hypothesis), in window coordinates and behind a perspective w."""
import numpy as np
from hypothesis import given, settings, strategies as st

from stress_helpers import Painter, centres_inside as _centres_inside, clip_from_window, context, pixels

W = H = 48
STEP = 3 / 255          # adds exactly 3 per hit in every channel (no rounding ties)


def additive(gl):
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.ONE, gl.ONE)
    gl.clearColor(0, 0, 0, 0)
    gl.clear(gl.COLOR_BUFFER_BIT)


def hits(gl):
    img = pixels(gl)
    assert (img % 3 == 0).all() and (img == img[..., :1]).all(), "channels disagree: not a clean count"
    return img[..., 0] // 3


def centres_inside(polys):
    return _centres_inside(polys, W, H)


def draw_window(gl, xy, tris=None, mode=None, wc=1.0):
    p = Painter(gl, uniform_color=True)
    p.draw(mode if mode is not None else gl.TRIANGLES, clip_from_window(xy, W, H, wc=wc),
           indices=tris, color=(STEP, STEP, STEP, STEP))


def jittered_grid(rng, n, x0, y0, x1, y1, jitter):
    xs, ys = np.linspace(x0, x1, n + 1), np.linspace(y0, y1, n + 1)
    gx, gy = np.meshgrid(xs, ys)
    jx = rng.uniform(-jitter, jitter, gx.shape) * (x1 - x0) / n
    jy = rng.uniform(-jitter, jitter, gy.shape) * (y1 - y0) / n
    jx[:, [0, -1]] = 0
    jy[[0, -1], :] = 0
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    tris = []
    for j in range(n):
        for i in range(n):
            a, b, c, d = idx[j, i], idx[j, i + 1], idx[j + 1, i], idx[j + 1, i + 1]
            tris += [(a, b, d), (a, d, c)] if rng.random() < 0.5 else [(a, b, c), (b, d, c)]
    tris = np.array(tris, np.uint32)
    flip = rng.random(len(tris)) < 0.5
    tris[flip] = tris[flip][:, [0, 2, 1]]
    return np.stack([(gx + jx).ravel(), (gy + jy).ravel()], 1), tris


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.sampled_from([2, 5, 13, 40]),
       jitter=st.floats(0, 0.24), wc=st.sampled_from([1.0, 0.125, 7.0, 2.0**20]))
def test_random_grid_hits_each_covered_pixel_once(seed, n, jitter, wc):
    rng = np.random.default_rng(seed)
    x0, y0 = rng.uniform(1, 12, 2)
    x1, y1 = rng.uniform(34, 47, 2)
    xy, tris = jittered_grid(rng, n, x0, y0, x1, y1, jitter)
    gl = context(W, H)
    additive(gl)
    draw_window(gl, xy, tris, wc=wc)
    count = hits(gl)
    assert count.max() <= 1, f"{int((count > 1).sum())} pixels hit twice"
    inside, ambiguous = centres_inside([[(x0, y0), (x1, y0), (x1, y1), (x0, y1)]])
    assert (count[inside] == 1).all(), "a pixel inside the mesh was missed (crack)"
    assert (count[~inside & ~ambiguous] == 0).all(), "a pixel outside the mesh was hit"


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), segments=st.sampled_from([3, 8, 50, 400]),
       mode=st.sampled_from(["TRIANGLE_FAN", "TRIANGLES"]))
def test_random_fan_hits_each_covered_pixel_once(seed, segments, mode):
    rng = np.random.default_rng(seed)
    c = rng.uniform(18, 30, 2)
    # Gaps below pi keep the ring around its centroid: a convex fan that never folds.
    angles = (np.arange(segments) + rng.uniform(0, 0.9, segments)) * 2 * np.pi / segments
    ring = c + rng.uniform(8, 17) * np.stack([np.cos(angles), np.sin(angles)], 1)
    centre = ring.mean(0)
    gl = context(W, H)
    additive(gl)
    if mode == "TRIANGLE_FAN":
        draw_window(gl, np.vstack([centre, ring, ring[:1]]), mode=gl.TRIANGLE_FAN)
    else:
        k = np.arange(segments)
        tris = np.stack([np.zeros(segments, int), 1 + k, 1 + (k + 1) % segments], 1)
        draw_window(gl, np.vstack([centre, ring]), tris)
    count = hits(gl)
    assert count.max() <= 1
    inside, ambiguous = centres_inside([ring])   # the ring is convex and CCW; centre is inside
    assert (count[inside] == 1).all()
    assert (count[~inside & ~ambiguous] == 0).all()


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), columns=st.integers(1, 60))
def test_random_strip_hits_each_covered_pixel_once(seed, columns):
    """A strip between a lower and an upper polyline over increasing x: trapezoids that never
    overlap, split along alternating diagonals."""
    rng = np.random.default_rng(seed)
    xs = np.sort(rng.uniform(2, 46, columns + 1))
    lo = rng.uniform(2, 20, columns + 1)
    hi = lo + rng.uniform(0.01, 26, columns + 1)
    xy = np.empty((2 * (columns + 1), 2))
    xy[0::2, 0] = xy[1::2, 0] = xs
    xy[0::2, 1], xy[1::2, 1] = lo, hi
    gl = context(W, H)
    additive(gl)
    draw_window(gl, xy, mode=gl.TRIANGLE_STRIP)
    count = hits(gl)
    assert count.max() <= 1
    quads = [[(xs[i], lo[i]), (xs[i + 1], lo[i + 1]), (xs[i + 1], hi[i + 1]), (xs[i], hi[i])]
             for i in range(columns) if xs[i + 1] > xs[i]]
    inside, ambiguous = centres_inside(quads)
    assert (count[inside] == 1).all()
    assert (count[~inside & ~ambiguous] == 0).all()


def test_perspective_ground_plane_is_watertight():
    """A grid on a ground plane seen in perspective, crossing the near plane and going behind
    the eye: clipped triangles still meet without cracks or double hits."""
    from softgl import transforms
    proj = np.asarray(transforms.perspective(np.radians(70), 1.0, 0.1, 50.0), np.float64)
    view = np.asarray(transforms.lookAt([0, 1, 3], [0, 0, -2], [0, 1, 0]), np.float64)
    rng = np.random.default_rng(3)
    n = 24
    g = np.linspace(-10, 10, n + 1)
    gx, gz = np.meshgrid(g, g)
    gx[1:-1, 1:-1] += rng.uniform(-0.15, 0.15, (n - 1, n - 1)) * 20 / n
    world = np.stack([gx.ravel(), np.zeros(gx.size), gz.ravel(), np.ones(gx.size)], 1)
    clip = world @ (proj @ view).T
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    tris = np.concatenate([np.stack([idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel()], 1),
                           np.stack([idx[:-1, :-1].ravel(), idx[1:, 1:].ravel(), idx[1:, :-1].ravel()], 1)])
    gl = context(W, H)
    additive(gl)
    Painter(gl, uniform_color=True).draw(gl.TRIANGLES, clip, indices=tris, color=(STEP,) * 4)
    count = hits(gl)
    assert count.max() <= 1
    assert gl.stats()["primitives_clipped"] > 0
    # The plane y = 0 seen from above covers the screen below the horizon entirely.
    horizon = proj @ view @ np.array([0, 0, -10.0, 1.0])   # the far edge of the grid
    ndc_y = horizon[1] / horizon[3]
    rows_below = int(np.floor((ndc_y + 1) / 2 * H)) - 1
    assert rows_below > 10
    assert (count[:rows_below] == 1).all()
