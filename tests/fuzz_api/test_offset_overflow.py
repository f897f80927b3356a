"""64-bit offsets and lengths at the edge (2^63 - 1) and 32-bit origins at -2^31: found by the
command-stream fuzzer under UndefinedBehaviorSanitizer (tools/build_asan_module.sh). The checks
`offset + length > size` overflow int64 (undefined behaviour; in practice they wrap and pass).
Each call must record INVALID_VALUE (or read nothing) and change nothing."""
import subprocess
import sys
import warnings

import numpy as np
import pytest

import softgl

BIG = 2**63 - 1


@pytest.fixture
def gl():
    gl = softgl.Context(4, 4)
    gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
    gl.bufferData(gl.ARRAY_BUFFER, 64, gl.STATIC_DRAW)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", softgl.GLWarning)
        yield gl


def test_buffer_data_source_range_overflow(gl):
    gl.bufferData(gl.ARRAY_BUFFER, np.zeros(4, np.uint8), gl.STATIC_DRAW, 1, BIG)
    assert gl.getError() == gl.INVALID_VALUE
    assert gl.getBufferParameter(gl.ARRAY_BUFFER, gl.BUFFER_SIZE) == 64


def test_buffer_sub_data_source_range_overflow(gl):
    # UB in byte_span (same line as above); the release build happens to reject it later.
    gl.bufferSubData(gl.ARRAY_BUFFER, 0, np.zeros(4, np.uint8), 1, BIG)
    assert gl.getError() == gl.INVALID_VALUE


def test_get_buffer_sub_data_destination_range_overflow(gl):
    # UB: dst_offset + length (bindings/context.cpp, getBufferSubData).
    gl.getBufferSubData(gl.ARRAY_BUFFER, 0, np.zeros(4, np.uint8), 1, BIG)
    assert gl.getError() == gl.INVALID_VALUE


def test_uniform_source_range_overflow(gl):
    # UB: src_offset + src_length (bindings/context.cpp, uniform_v).
    prog = softgl.program(gl, "attribute vec4 a; void main(){gl_Position=a;}",
                          "precision mediump float; uniform vec4 u[2]; void main(){gl_FragColor=u[1];}")
    gl.useProgram(prog)
    gl.uniform4fv(gl.getUniformLocation(prog, "u"), np.zeros(8, np.float32), 4, BIG)
    assert gl.getError() == gl.INVALID_VALUE


def test_copy_buffer_sub_data_offset_overflow_does_not_crash():
    code = """
import softgl, warnings
warnings.simplefilter('ignore')
gl = softgl.Context(4, 4)
gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer()); gl.bufferData(gl.ARRAY_BUFFER, 64, gl.STATIC_DRAW)
gl.bindBuffer(gl.COPY_WRITE_BUFFER, gl.createBuffer()); gl.bufferData(gl.COPY_WRITE_BUFFER, 64, gl.STATIC_DRAW)
gl.copyBufferSubData(gl.ARRAY_BUFFER, gl.COPY_WRITE_BUFFER, 2**63 - 1, 0, 21)
e1 = gl.getError()
gl.copyBufferSubData(gl.ARRAY_BUFFER, gl.COPY_WRITE_BUFFER, 0, 2**63 - 1, 64)
print(e1, gl.getError())
"""
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, f"exit {r.returncode}"
    assert r.stdout.split()[-2:] == [str(softgl.INVALID_VALUE)] * 2


def test_read_pixels_at_the_most_negative_origin(gl):
    # UB: r.x - x with x = -2^31 (surface/framebuffer.cpp read_rgba8); the bytes are right.
    out = gl.readPixels(-2**31, -2**31, 2, 2, gl.RGBA, gl.UNSIGNED_BYTE)
    assert out.shape == (2, 2, 4) and not out.any()
    assert gl.getError() == gl.NO_ERROR
