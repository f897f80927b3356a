"""Helpers for the Python layer's tests: bytes as WebGL stores them, drawing with a stock
program through the raw API."""
import numpy as np



def unorm(x):
    """Float colors -> the bytes WebGL stores (clamp, round to nearest)."""
    return np.floor(np.clip(np.asarray(x, np.float64), 0, 1) * 255 + 0.5).astype(np.int64)


def read(gl):
    """The drawing buffer as int64, row 0 at the bottom."""
    return gl.readPixels(0, 0, gl.drawingBufferWidth, gl.drawingBufferHeight, gl.RGBA,
                         gl.UNSIGNED_BYTE).astype(np.int64)


def draw_triangles(gl, prog, positions, normals=None, colors=None):
    """Draw unindexed triangles with a softgl.programs.Program through the WebGL API."""
    prog.use()
    for name, data in (("aPosition", positions), ("aNormal", normals), ("aColor", colors)):
        if data is None or name not in prog.attributes:
            continue
        data = np.asarray(data, np.float32)
        buf = gl.createBuffer()
        gl.bindBuffer(gl.ARRAY_BUFFER, buf)
        gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW)
        loc = prog.attributes[name]
        gl.enableVertexAttribArray(loc)
        gl.vertexAttribPointer(loc, data.shape[1], gl.FLOAT, False, 0, 0)
    gl.drawArrays(gl.TRIANGLES, 0, len(positions))


def fullscreen(z=0.0):
    """Two triangles covering clip space at depth z."""
    return np.array([[-1, -1, z], [1, -1, z], [-1, 1, z], [-1, 1, z], [1, -1, z], [1, 1, z]],
                    np.float32)


def pixel_centers_ndc(w, h):
    """NDC x, y of every pixel centre, arrays (h, w), row 0 at the bottom."""
    x = (np.arange(w) + 0.5) / w * 2 - 1
    y = (np.arange(h) + 0.5) / h * 2 - 1
    return np.meshgrid(x, y)
