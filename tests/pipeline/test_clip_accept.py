"""Setup's no-clipping fast path (Clipper::accepts): a triangle it accepts must be exactly what the
clipper returns unchanged (same vertices, weights (1,0,0), (0,1,0), (0,0,1)), and it must accept
exactly the triangles whose vertices are finite, have w >= 2^-1022 and lie inside every clip plane
by the plane distance p.x*x + p.y*y + p.z*z + p.w*w rounded in float64 (the outcode's definition,
evaluated here in Python floats). Vertices are drawn on, next to and far from every plane, with
tiny, zero and negative w, NaN and Inf."""
import math

import numpy as np

from conftest import core

W, H = 64, 32                 # planes x = +-(2^20 + 32) w / 32 (and y) are exact in float32
G = 2.0 ** 20


def planes(width, height):
    sx, ox, sy, oy = 0.5 * width, 0.5 * width, 0.5 * height, 0.5 * height
    return [(0, 0, 0, 1), (0, 0, 1, 1), (0, 0, -1, 1), (sx, 0, 0, ox + G), (-sx, 0, 0, G - ox),
            (0, sy, 0, oy + G), (0, -sy, 0, G - oy)]


def reference_accepts(tri, width=W, height=H):
    for v in np.asarray(tri, np.float32).astype(np.float64):
        x, y, z, w = (float(t) for t in v)
        if not all(math.isfinite(t) for t in (x, y, z, w)) or not w >= 2.0 ** -1022:
            return False
        if not all(p[0] * x + p[1] * y + p[2] * z + p[3] * w >= 0 for p in planes(width, height)):
            return False
    return True


def random_vertex(rng):
    w = float(rng.choice([1.0, 2.0, 0.5, 1e-30, 2.0 ** -149, 1e30, 0.0, -0.0, -1.0, 3.7]))
    kind = rng.integers(0, 14)   # 8..13: inside when w > 0
    x, y, z = rng.uniform(-1, 1, 3) * w
    if kind == 1:      # on a guard-band plane
        x = float(rng.choice([-1, 1])) * (G + 32) / 32 * w
    elif kind == 2:
        y = float(rng.choice([-1, 1])) * (G + 16) / 16 * w
    elif kind == 3:    # on near or far, or just outside
        z = float(rng.choice([-1, 1])) * w * float(rng.choice([1, 1 + 2.0 ** -23, 1 - 2.0 ** -24]))
    elif kind == 4:    # far outside or huge
        x, y, z = rng.normal(0, 1, 3) * 10.0 ** rng.integers(-40, 39)
    elif kind == 5:
        x = float(rng.choice([np.nan, np.inf, -np.inf]))
    elif kind == 6:
        w = float(rng.choice([np.nan, np.inf, -np.inf]))
    elif kind == 7:    # just inside/outside the guard band
        x = float(np.nextafter(np.float32((G + 32) / 32 * w), np.float32(rng.choice([0, np.inf]))))
    return [x, y, z, w]


def test_accepts_exactly_the_unclipped_triangles():
    rng = np.random.default_rng(7)
    accepted = 0
    for _ in range(4000):
        tri = np.array([random_vertex(rng) for _ in range(3)], np.float32)
        got = core.testing.clip_accepts(tri, W, H)
        assert got == reference_accepts(tri), tri
        if got:
            accepted += 1
            pos, weights = core.testing.clip_triangle(tri, W, H)
            np.testing.assert_array_equal(pos, tri.astype(np.float64))
            np.testing.assert_array_equal(weights, np.eye(3))
    assert 300 < accepted < 3000, accepted


def test_accepts_on_the_planes():
    # Every vertex exactly on one or more planes is inside (distance 0 >= 0).
    on = [[0, 0, 1, 1], [0, 0, -1, 1], [-(G + 32) / 32, 0, 0, 1], [(G - 32) / 32 * 2, 0, 0, 2],
          [0, -(G + 16) / 16, 0, 1], [0, (G - 16) / 16, 1, 1]]
    for i in range(len(on) - 2):
        tri = np.array(on[i:i + 3], np.float32)
        assert reference_accepts(tri) and core.testing.clip_accepts(tri, W, H)
    # w = 0 (the origin) and w = -0 are not accepted; the smallest float32 w is.
    for w, ok in [(0.0, False), (-0.0, False), (2.0 ** -149, True)]:
        tri = np.array([[0, 0, 0, w], [0.5, 0, 0, 1], [0, 0.5, 0, 1]], np.float32)
        assert core.testing.clip_accepts(tri, W, H) == ok == reference_accepts(tri)
