"""The ordinary-content benchmark (benchmarks/ordinary.py) keeps working: every scene renders on
softgl without a GL error and agrees with Mesa llvmpipe running the same WebGL calls through the
adapter (benchmarks/webgl_on_gles.py). No timing here: the benchmark itself measures speed.

Scenes render at 128x96 (their own size when smaller); llvmpipe runs in one worker process for the
module (LP_NUM_THREADS is per process).
"""
from __future__ import annotations

import ctypes.util
import sys
from pathlib import Path

import numpy as np
import pytest

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"
sys.path.insert(0, str(BENCHMARKS))  # the spawned worker inherits sys.path, so it finds them too
import ordinary  # noqa: E402
import webgl_on_gles  # noqa: E402

if not (ctypes.util.find_library("EGL") and ctypes.util.find_library("GLESv2")):
    pytest.skip("libEGL/libGLESv2 not installed (Debian: libegl1 libgles2 libegl-mesa0 "
                "libgl1-mesa-dri)", allow_module_level=True)

SIZE = (128, 96)
# Where two correct implementations may differ at this size: edge rules on a few pixels,
# llvmpipe's 8-bit mip-level weights (trilinear: a few levels on most pixels), blending rounding.
# A scene that draws something else (a wrong enum, matrix, binding) differs by far more than 16
# on far more than 1% of its pixels.
MAX_SHARE_OVER_16 = 0.01
MIN_SHARE_WITHIN_4 = 0.95


@pytest.fixture(scope="module")
def lp():
    try:
        proc = webgl_on_gles.GlesProcess(threads=1)
        proc.setup(ordinary.layers, 8, 8)   # fails here, not in every test, if EGL cannot start
    except Exception as e:  # ReferenceUnavailable or a worker that could not start Mesa
        pytest.skip(f"llvmpipe through EGL unavailable: {e}")
    with proc:
        yield proc


def _size(spec):
    if spec.width * spec.height <= SIZE[0] * SIZE[1] * 4:
        return spec.width, spec.height
    return SIZE


@pytest.mark.parametrize("spec", ordinary.SCENES + ordinary.EXTRA + ordinary.SCALING[:1],
                         ids=lambda s: s.key)
def test_scene_renders_and_agrees_with_llvmpipe(spec, lp):
    w, h = _size(spec)
    gl = ordinary.softgl_context(spec, w, h, threads=2)   # strict: a GL error raises
    frame = spec.setup(gl, w, h)
    frame()
    frame()   # twice: a frame must not depend on state the previous one left
    assert gl.getError() == gl.NO_ERROR
    ours = ordinary.canvas_pixels(gl)
    lp.setup(spec.setup, w, h, spec.samples)   # raises on a GL error in llvmpipe
    theirs = lp.render()
    assert ours.shape == theirs.shape == (h, w, 4)
    # Something was drawn: more than a clear colour.
    assert len(np.unique(ours.reshape(-1, 4), axis=0)) > 8
    c = ordinary.compare(ours, theirs)
    assert c["over16"] <= MAX_SHARE_OVER_16, c
    assert c["within4"] >= MIN_SHARE_WITHIN_4, c


def test_compare_counts_shares_of_pixels():
    a = np.zeros((2, 5, 4), np.uint8)
    b = a.copy()
    b[0, 0, 1] = 1     # within 1
    b[0, 1, 2] = 4     # within 4, not 1
    b[0, 2, 0] = 17    # over 16
    b[1, 4, 3] = 200   # over 16
    c = ordinary.compare(a, b)
    assert c == dict(maxdiff=200, within1=0.7, within4=0.8, over16=0.2)


def test_adapter_enums_are_webgl_values():
    """The adapter's enum table against softgl's (both from the specs; a typo in either fails)."""
    import softgl
    gl = softgl.Context(4, 4)
    checked = 0
    for name, value in webgl_on_gles.ENUMS.items():
        if hasattr(gl, name):
            assert getattr(gl, name) == value, name
            checked += 1
    assert checked >= len(webgl_on_gles.ENUMS) - 2   # all but softgl-less names, if any


def test_uniform_at_null_location_is_ignored_and_matrices_are_column_major(lp):
    """Two adapter rules the scenes lean on, seen through pixels: a uniform set at a null
    location changes nothing (WebGL), and uniformMatrix4fv takes column-major data."""
    lp.setup(_matrix_probe, 16, 16)
    img = lp.render()
    # The translation (0.5, 0, 0) sits in elements 12..14 (column-major): the quad covers the
    # right three quarters; uColor stays red although a null location got green.
    assert tuple(img[8, 2]) == (0, 0, 0, 0)
    assert tuple(img[8, 12]) == (255, 0, 0, 255)


def _matrix_probe(gl, w, h):
    prog = ordinary.program(gl, """#version 300 es
uniform mat4 uM;
in vec2 aPos;
void main() { gl_Position = uM * vec4(aPos * 0.5, 0.0, 1.0); }
""", """#version 300 es
precision mediump float;
uniform vec4 uColor;
out vec4 fragColor;
void main() { fragColor = uColor; }
""")
    ordinary.fullscreen_quad(gl, prog)
    gl.useProgram(prog)
    gl.uniformMatrix4fv(gl.getUniformLocation(prog, "uM"), False, ordinary.flat(ordinary.translate(0.5, 0, 0)))
    gl.uniform4f(gl.getUniformLocation(prog, "uColor"), 1, 0, 0, 1)
    gl.uniform4f(gl.getUniformLocation(prog, "uNoSuchUniform"), 0, 1, 0, 1)

    def frame():
        gl.clearColor(0, 0, 0, 0)
        gl.clear(gl.COLOR_BUFFER_BIT)
        gl.drawArrays(gl.TRIANGLES, 0, 6)
    return frame
