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
