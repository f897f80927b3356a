import numpy as np
import pytest

core = pytest.importorskip("softgl._core")

GL_FRONT, GL_BACK, GL_FRONT_AND_BACK = 0x404, 0x405, 0x408
GL_CW, GL_CCW = 0x900, 0x901


def clip_from_window(xy, width, height, z=0.0, w=1.0):
    """Clip coordinates for window positions (pixels, y up) with the full-target viewport."""
    xy = np.asarray(xy, np.float64).reshape(-1, 2)
    out = np.empty((len(xy), 4), np.float64)
    out[:, 0] = (2 * xy[:, 0] / width - 1) * w
    out[:, 1] = (2 * xy[:, 1] / height - 1) * w
    out[:, 2] = np.broadcast_to(z, len(xy)) * w
    out[:, 3] = w
    return out.astype(np.float32)


def coverage(width, height, positions, **kw):
    return core.raster_coverage(width, height, np.asarray(positions, np.float32), **kw)


# ---- An independent float64/int64 reference of the coverage rule (setup.h), vectorised in NumPy ----

def window_from_clip(clip, width, height, viewport=None):
    """Window x, y (float64), computed exactly as setup does: scale * (x / w) + offset."""
    clip = np.asarray(clip, np.float32).astype(np.float64)
    vx, vy, vw, vh = viewport or (0, 0, width, height)
    x = (0.5 * vw) * (clip[:, 0] / clip[:, 3]) + (vx + 0.5 * vw)
    y = (0.5 * vh) * (clip[:, 1] / clip[:, 3]) + (vy + 0.5 * vh)
    return np.stack([x, y], 1)


def snap(xy):
    return np.floor(np.asarray(xy, np.float64) * 256 + 0.5).astype(np.int64)


CENTRE = np.array([[128, 128]], np.int64)


def ref_triangle_coverage(fixed, width, height, offsets=CENTRE):
    """(H, W, S) bool: samples covered by the triangle with snapped vertices `fixed` (3, 2) int64,
    under the tie rule: left edges and bottom edges (y up) are included."""
    v = np.asarray(fixed, np.int64)
    area2 = (v[1, 0] - v[0, 0]) * (v[2, 1] - v[0, 1]) - (v[2, 0] - v[0, 0]) * (v[1, 1] - v[0, 1])
    out = np.zeros((height, width, len(offsets)), bool)
    if area2 == 0:
        return out
    if area2 < 0:
        v = v[[0, 2, 1]]
    py, px = np.mgrid[0:height, 0:width]
    for s, (ox, oy) in enumerate(offsets):
        X, Y = px.astype(np.int64) * 256 + ox, py.astype(np.int64) * 256 + oy
        inside = np.ones((height, width), bool)
        for i in range(3):
            (xj, yj), (xk, yk) = v[(i + 1) % 3], v[(i + 2) % 3]
            a, b = yj - yk, xk - xj
            e = a * (X - xj) + b * (Y - yj)
            included = a > 0 or (a == 0 and b > 0)
            inside &= (e >= 0) if included else (e > 0)
        out[..., s] = inside
    return out


def ref_mesh_count(clip, tris, width, height, offsets=CENTRE):
    fixed = snap(window_from_clip(clip, width, height))
    count = np.zeros((height, width, len(offsets)), np.uint32)
    for t in tris:
        count += ref_triangle_coverage(fixed[list(t)], width, height, offsets)
    return count
