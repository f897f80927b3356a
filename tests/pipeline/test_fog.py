"""SOFTGL_fog against the OpenGL 1.x fog formulas evaluated in float64 (GL 1.5 §3.10)."""
import math

import numpy as np
import pytest

import softgl

VS = """attribute vec4 aPos; void main() { gl_Position = aPos; }"""
FS = """precision highp float; uniform vec4 uColor; void main() { gl_FragColor = uColor; }"""
W, H = 32, 4
NEAR_W, FAR_W = 1.0, 9.0          # clip w at the left and right edges


def fogged_quad(gl, ext, color=(0.9, 0.6, 0.3, 1.0)):
    prog = softgl.program(gl, VS, FS)
    gl.useProgram(prog)
    # A full-screen quad whose clip w grows from left to right: c = w at each fragment.
    pos = []
    for x, y in ((-1, -1), (1, -1), (-1, 1), (1, 1)):
        w = NEAR_W if x < 0 else FAR_W
        pos += [x * w, y * w, 0.0, w]
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.bufferData(gl.ARRAY_BUFFER, np.array(pos, np.float32), gl.STATIC_DRAW)
    gl.enableVertexAttribArray(0)
    gl.vertexAttribPointer(0, 4, gl.FLOAT, False, 0, 0)
    gl.uniform4f(gl.getUniformLocation(prog, "uColor"), *color)
    gl.drawArrays(gl.TRIANGLE_STRIP, 0, 4)
    return gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE).astype(np.int64)


def eye_distance(x):
    # 1/w is linear in window space between the edges (ES 3.0 §3.6.1).
    t = (x + 0.5) / W
    return 1.0 / ((1 - t) / NEAR_W + t / FAR_W)


def expected(mode, c, density=0.3, start=2.0, end=8.0, color=(0.9, 0.6, 0.3), fog=(0.2, 0.4, 0.8)):
    f = {"LINEAR": (end - c) / (end - start), "EXP": math.exp(-density * c),
         "EXP2": math.exp(-(density * c) ** 2)}[mode]
    f = min(max(f, 0.0), 1.0)
    return [int(math.floor(min(max(f * s + (1 - f) * g, 0), 1) * 255 + 0.5)) for s, g in zip(color, fog)]


@pytest.mark.parametrize("mode", ["LINEAR", "EXP", "EXP2"])
def test_fog_modes_match_the_formulas(mode):
    gl = softgl.Context(W, H, antialias=False)
    ext = gl.getExtension("SOFTGL_fog")
    gl.enable(ext.FOG)
    ext.fogi(ext.FOG_MODE, getattr(ext, mode))
    ext.fogf(ext.FOG_DENSITY, 0.3)
    ext.fogf(ext.FOG_START, 2.0)
    ext.fogf(ext.FOG_END, 8.0)
    ext.fogfv(ext.FOG_COLOR, [0.2, 0.4, 0.8, 1.0])
    img = fogged_quad(gl, ext)
    assert gl.getError() == gl.NO_ERROR
    for x in range(W):
        want = expected(mode, eye_distance(x))
        assert np.abs(img[1, x, :3] - want).max() <= 1, (x, img[1, x], want)
        assert img[1, x, 3] == 255                    # alpha is not fogged


def test_window_depth_coordinate_and_blend_aware_fog():
    gl = softgl.Context(W, H, antialias=False)
    ext = gl.getExtension("SOFTGL_fog")
    gl.enable(ext.FOG)
    ext.fogi(ext.FOG_COORDINATE_SOURCE, ext.WINDOW_DEPTH_SOFTGL)
    ext.fogi(ext.FOG_MODE, ext.LINEAR)
    ext.fogf(ext.FOG_START, 0.0)
    ext.fogf(ext.FOG_END, 1.0)
    ext.fogfv(ext.FOG_COLOR, [1, 1, 1, 1])
    img = fogged_quad(gl, ext)   # z = 0 everywhere: window depth 0.5, f = 0.5
    assert np.abs(img[0, :, :3] - expected("LINEAR", 0.5, start=0, end=1, fog=(1, 1, 1))).max() <= 1
    # Additive geometry with blend-aware fog fades toward black (adds nothing), not toward white.
    gl.enable(ext.FOG_BLEND_AWARE_SOFTGL)
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.ONE, gl.ONE)
    gl.clearColor(0, 0, 0, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    img = fogged_quad(gl, ext)
    assert np.abs(img[0, :, :3] - expected("LINEAR", 0.5, start=0, end=1, fog=(0, 0, 0))).max() <= 1


def test_fog_state_and_validation(quiet):
    gl = softgl.Context(2, 2)
    gl.enable(0x0B60)
    assert gl.getError() == gl.INVALID_ENUM          # FOG is not a WebGL capability ...
    ext = gl.getExtension("SOFTGL_fog")              # ... until softgl's extension is enabled
    assert "SOFTGL_fog" in gl.getSupportedExtensions()
    gl.enable(ext.FOG)
    assert gl.isEnabled(ext.FOG) and gl.getError() == gl.NO_ERROR
    assert gl.getParameter(ext.FOG_MODE) == ext.EXP            # GL 1.x initial values
    assert gl.getParameter(ext.FOG_DENSITY) == 1.0
    assert (gl.getParameter(ext.FOG_START), gl.getParameter(ext.FOG_END)) == (0.0, 1.0)
    ext.fogi(ext.FOG_MODE, gl.BLEND)
    assert gl.getError() == gl.INVALID_ENUM
    ext.fogf(ext.FOG_DENSITY, -1)
    assert gl.getError() == gl.INVALID_VALUE
    ext.fogfv(ext.FOG_COLOR, [2, -1, 0.5, 1])
    assert gl.getParameter(ext.FOG_COLOR).tolist() == [1, 0, 0.5, 1]   # clamped, as GL 1.x
    ext.fogfv(ext.FOG_COLOR, [1, 1])
    assert gl.getError() == gl.INVALID_VALUE
