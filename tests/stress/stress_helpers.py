"""Shared helpers for the stress tests: a context with a GLSL program, drawing float32 positions
(and optional per-vertex colors), reading pixels as int64, and process memory figures."""
from __future__ import annotations

import os
import warnings

import numpy as np

import softgl

VS = """attribute vec4 aPos;
attribute vec4 aColor;
varying vec4 vColor;
void main() { gl_Position = aPos; vColor = aColor; }"""
FS = """precision highp float;
varying vec4 vColor;
void main() { gl_FragColor = vColor; }"""
VS_UNIFORM = """attribute vec4 aPos; void main() { gl_Position = aPos; }"""
FS_UNIFORM = """precision highp float; uniform vec4 uColor; void main() { gl_FragColor = uColor; }"""


def context(w=32, h=32, **kw):
    kw.setdefault("antialias", False)
    return softgl.Context(w, h, **kw)


class Painter:
    """One context, one GLSL program (aPos at 0, aColor at 1), one vertex buffer per attribute."""

    def __init__(self, gl, uniform_color=False):
        self.gl = gl
        if uniform_color:
            self.prog = softgl.program(gl, VS_UNIFORM, FS_UNIFORM, {"aPos": 0})
        else:
            self.prog = softgl.program(gl, VS, FS, {"aPos": 0, "aColor": 1})
        gl.useProgram(self.prog)
        self.uniform_color = uniform_color
        self.pos_buf = gl.createBuffer()
        self.col_buf = gl.createBuffer()
        self.idx_buf = gl.createBuffer()

    def color(self, rgba):
        gl = self.gl
        if self.uniform_color:
            gl.uniform4f(gl.getUniformLocation(self.prog, "uColor"), *rgba)
        else:
            gl.disableVertexAttribArray(1)
            gl.vertexAttrib4f(1, *rgba)

    def draw(self, mode, pos, colors=None, indices=None, color=None):
        """pos: (n, 4) (or (n, 2)/(n, 3)) clip coordinates, drawn as float32."""
        gl = self.gl
        pos = np.ascontiguousarray(pos, np.float32)
        gl.bindBuffer(gl.ARRAY_BUFFER, self.pos_buf)
        gl.bufferData(gl.ARRAY_BUFFER, pos, gl.STREAM_DRAW)
        gl.enableVertexAttribArray(0)
        gl.vertexAttribPointer(0, pos.shape[1], gl.FLOAT, False, 0, 0)
        if colors is not None and not self.uniform_color:
            gl.bindBuffer(gl.ARRAY_BUFFER, self.col_buf)
            gl.bufferData(gl.ARRAY_BUFFER, np.ascontiguousarray(colors, np.float32), gl.STREAM_DRAW)
            gl.enableVertexAttribArray(1)
            gl.vertexAttribPointer(1, 4, gl.FLOAT, False, 0, 0)
        elif color is not None:
            self.color(color)
        if indices is None:
            gl.drawArrays(mode, 0, len(pos))
        else:
            idx = np.ascontiguousarray(indices, np.uint32).ravel()
            gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, self.idx_buf)
            gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, idx, gl.STREAM_DRAW)
            gl.drawElements(mode, len(idx), gl.UNSIGNED_INT, 0)


def pixels(gl):
    return gl.readPixels(0, 0, gl.drawingBufferWidth, gl.drawingBufferHeight, gl.RGBA,
                         gl.UNSIGNED_BYTE).astype(np.int64)


def unorm8(x):
    return np.floor(np.clip(np.asarray(x, np.float64), 0, 1) * 255 + 0.5).astype(np.int64)


def clip_from_window(xy, w, h, z=0.0, wc=1.0):
    """Window coordinates (pixels) -> clip coordinates (x, y, z, w) for a full-canvas viewport."""
    xy = np.asarray(xy, np.float64)
    out = np.empty((len(xy), 4))
    out[:, 0] = (xy[:, 0] / w * 2 - 1) * wc
    out[:, 1] = (xy[:, 1] / h * 2 - 1) * wc
    out[:, 2] = z * wc
    out[:, 3] = wc
    return out


def centres_inside(polys, w, h, margin=0.004):
    """(inside, ambiguous): pixels whose centre is strictly inside one of the convex polygons (CCW,
    window coordinates) by more than `margin` pixels, and those within `margin` of an edge
    (snapping to 1/256 pixel moves an edge by up to 1/512 * sqrt(2))."""
    cx, cy = np.meshgrid(np.arange(w) + 0.5, np.arange(h) + 0.5)
    inside = np.zeros((h, w), bool)
    near = np.zeros((h, w), bool)
    for poly in polys:
        poly = np.asarray(poly, np.float64)
        d_min = np.full((h, w), np.inf)
        for i in range(len(poly)):
            (x0, y0), (x1, y1) = poly[i], poly[(i + 1) % len(poly)]
            length = np.hypot(x1 - x0, y1 - y0)
            if length == 0:
                continue
            d = ((x1 - x0) * (cy - y0) - (y1 - y0) * (cx - x0)) / length
            d_min = np.minimum(d_min, d)
        inside |= d_min > margin
        near |= np.abs(d_min) <= margin
    return inside, near & ~inside


def rss_bytes() -> int:
    """Resident set size of this process, from /proc/self/statm."""
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


class quiet(warnings.catch_warnings):
    """Context manager silencing GLWarnings (for calls that are invalid on purpose)."""

    def __enter__(self):
        r = super().__enter__()
        warnings.simplefilter("ignore", softgl.GLWarning)
        return r
