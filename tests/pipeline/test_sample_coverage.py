"""SAMPLE_COVERAGE and SAMPLE_ALPHA_TO_COVERAGE (ES 3.0 §4.1.3): round(v * samples) samples kept."""
import numpy as np
import pytest

import softgl

VS = "attribute vec4 p; void main() { gl_Position = p; }"
FS = "precision mediump float; uniform vec4 c; void main() { gl_FragColor = c; }"


def draw_quad(gl, color):
    prog = softgl.program(gl, VS, FS)
    gl.useProgram(prog)
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.bufferData(gl.ARRAY_BUFFER, np.array([-1, -1, 0, 1, 1, -1, 0, 1, -1, 1, 0, 1, 1, 1, 0, 1], np.float32),
                  gl.STATIC_DRAW)
    gl.enableVertexAttribArray(0)
    gl.vertexAttribPointer(0, 4, gl.FLOAT, False, 0, 0)
    gl.uniform4f(gl.getUniformLocation(prog, "c"), *color)
    gl.drawArrays(gl.TRIANGLE_STRIP, 0, 4)
    return gl.readPixels(0, 0, 2, 2, gl.RGBA, gl.UNSIGNED_BYTE)[0, 0].tolist()


@pytest.mark.parametrize("value, invert, kept", [(0.25, False, 1), (0.5, False, 2), (0.75, False, 3),
                                                 (0.25, True, 3), (1.0, True, 0), (0.0, False, 0)])
def test_sample_coverage_keeps_a_share_of_the_samples(value, invert, kept):
    gl = softgl.Context(2, 2, samples=4)
    gl.enable(gl.SAMPLE_COVERAGE)
    gl.sampleCoverage(value, invert)
    level = int(np.floor(255 * kept / 4 + 0.5))
    assert draw_quad(gl, (1, 1, 1, 1)) == [level] * 4


def test_alpha_to_coverage():
    gl = softgl.Context(2, 2, samples=4)
    gl.enable(gl.SAMPLE_ALPHA_TO_COVERAGE)
    # alpha 0.5: 2 of 4 samples get (255, 255, 255, 128); the resolve averages with 2 zero samples.
    assert draw_quad(gl, (1, 1, 1, 0.5)) == [128, 128, 128, 64]


def test_no_effect_without_multisampling():
    gl = softgl.Context(2, 2, antialias=False)
    gl.enable(gl.SAMPLE_COVERAGE)
    gl.enable(gl.SAMPLE_ALPHA_TO_COVERAGE)
    gl.sampleCoverage(0.0, False)
    assert draw_quad(gl, (1, 1, 1, 0.0)) == [255, 255, 255, 0]
