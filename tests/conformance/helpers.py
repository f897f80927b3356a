"""Small helpers shared by the conformance port (our own code, not theirs)."""
from __future__ import annotations

import numpy as np

import softgl

VS_POS = "attribute vec4 aPos; void main() { gl_Position = aPos; gl_PointSize = 1.0; }"
FS_GREEN = "void main() { gl_FragColor = vec4(0.0, 1.0, 0.0, 1.0); }"
FS_COLOR = "precision mediump float; uniform vec4 uColor; void main() { gl_FragColor = uColor; }"

# Two triangles covering the whole viewport.
QUAD = np.array([-1, -1, 1, -1, -1, 1, -1, 1, 1, -1, 1, 1], np.float32)


def context(width=16, height=16, version=2, **kw):
    kw.setdefault("antialias", False)
    return softgl.Context(width, height, version=version, **kw)


def errors(gl) -> list[int]:
    """Every pending error, then NO_ERROR is next (drains the error state)."""
    out = []
    for _ in range(8):
        e = gl.getError()
        if e == gl.NO_ERROR:
            return out
        out.append(e)
    raise AssertionError("getError never returned NO_ERROR")


def error(gl) -> int:
    """The one pending error (NO_ERROR if none); fails if there is more than one."""
    errs = errors(gl)
    assert len(errs) <= 1, errs
    return errs[0] if errs else gl.NO_ERROR


def program(gl, vs=VS_POS, fs=FS_GREEN, locations=None, use=True):
    prog = softgl.program(gl, vs, fs, locations)
    if use:
        gl.useProgram(prog)
    return prog


def try_link(gl, vs, fs, locations=None):
    """(compiled_vs, compiled_fs, linked) without raising."""
    shaders = []
    status = []
    for kind, src in ((gl.VERTEX_SHADER, vs), (gl.FRAGMENT_SHADER, fs)):
        s = gl.createShader(kind)
        gl.shaderSource(s, src)
        gl.compileShader(s)
        status.append(bool(gl.getShaderParameter(s, gl.COMPILE_STATUS)))
        shaders.append(s)
    p = gl.createProgram()
    for s in shaders:
        gl.attachShader(p, s)
    for name, loc in (locations or {}).items():
        gl.bindAttribLocation(p, loc, name)
    gl.linkProgram(p)
    return status[0], status[1], bool(gl.getProgramParameter(p, gl.LINK_STATUS)), p


def compiles(gl, kind, src) -> bool:
    s = gl.createShader(kind)
    gl.shaderSource(s, src)
    gl.compileShader(s)
    return bool(gl.getShaderParameter(s, gl.COMPILE_STATUS))


def array_buffer(gl, data, target=None):
    buf = gl.createBuffer()
    gl.bindBuffer(target or gl.ARRAY_BUFFER, buf)
    gl.bufferData(target or gl.ARRAY_BUFFER, np.ascontiguousarray(data), gl.STATIC_DRAW)
    return buf


def attribute(gl, loc, data, size, type_=None, normalized=False, stride=0, offset=0):
    buf = array_buffer(gl, data)
    gl.enableVertexAttribArray(loc)
    gl.vertexAttribPointer(loc, size, type_ or gl.FLOAT, normalized, stride, offset)
    return buf


def draw_quad(gl, loc=0):
    attribute(gl, loc, QUAD, 2)
    gl.drawArrays(gl.TRIANGLES, 0, 6)


def read(gl, x=0, y=0, w=None, h=None):
    w = gl.drawingBufferWidth if w is None else w
    h = gl.drawingBufferHeight if h is None else h
    return gl.readPixels(x, y, w, h, gl.RGBA, gl.UNSIGNED_BYTE)


def pixel(gl, x, y):
    return tuple(int(v) for v in read(gl, x, y, 1, 1)[0, 0])


GREEN = (0, 255, 0, 255)
RED = (255, 0, 0, 255)
BLACK0 = (0, 0, 0, 0)
