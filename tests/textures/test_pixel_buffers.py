"""WebGL 2 pixel buffer objects: texImage2D/texSubImage2D from PIXEL_UNPACK_BUFFER at a byte
offset, readPixels into PIXEL_PACK_BUFFER at an offset (WebGL 2.0 §3.7.6/§3.7.10, ES 3.0 §3.7.2,
§4.3.1), and the errors when the buffer and the argument form disagree."""
import numpy as np
import pytest

import softgl

from test_draw_buffers import read_attachment


def bound_buffer(gl, target, data):
    buf = gl.createBuffer()
    gl.bindBuffer(target, buf)
    gl.bufferData(target, data, gl.STATIC_DRAW)
    return buf


def texels(n, seed=1):
    return np.random.default_rng(seed).integers(0, 256, (n, 4), dtype=np.uint8)


def test_tex_image_2d_from_unpack_buffer_at_offset():
    gl = softgl.Context(4, 4, antialias=False)
    data = texels(16)
    raw = np.concatenate([np.full(12, 7, np.uint8), data.ravel()])   # 12 bytes before the image
    bound_buffer(gl, gl.PIXEL_UNPACK_BUFFER, raw)
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, 4, 4, 0, gl.RGBA, gl.UNSIGNED_BYTE, 12)
    assert gl.getError() == gl.NO_ERROR
    gl.bindBuffer(gl.PIXEL_UNPACK_BUFFER, None)
    assert np.array_equal(read_attachment(gl, tex), data.reshape(4, 4, 4))
    # texSubImage2D: a 2x2 block at (1, 2) from offset 4 of a second buffer.
    block = texels(4, seed=2)
    bound_buffer(gl, gl.PIXEL_UNPACK_BUFFER, np.concatenate([np.zeros(4, np.uint8), block.ravel()]))
    gl.texSubImage2D(gl.TEXTURE_2D, 0, 1, 2, 2, 2, gl.RGBA, gl.UNSIGNED_BYTE, 4)
    assert gl.getError() == gl.NO_ERROR
    gl.bindBuffer(gl.PIXEL_UNPACK_BUFFER, None)
    want = data.reshape(4, 4, 4).copy()
    want[2:4, 1:3] = block.reshape(2, 2, 4)
    assert np.array_equal(read_attachment(gl, tex), want)


def test_unpack_buffer_honours_unpack_state():
    """UNPACK_ALIGNMENT and UNPACK_ROW_LENGTH/SKIP_* apply to buffer data as to arrays."""
    gl = softgl.Context(4, 4, antialias=False)
    gl.pixelStorei(gl.UNPACK_ROW_LENGTH, 5)
    gl.pixelStorei(gl.UNPACK_SKIP_PIXELS, 1)
    gl.pixelStorei(gl.UNPACK_SKIP_ROWS, 1)
    src = texels(5 * 4, seed=3).reshape(4, 5, 4)    # rows of 5 pixels
    bound_buffer(gl, gl.PIXEL_UNPACK_BUFFER, src.ravel())
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, 3, 3, 0, gl.RGBA, gl.UNSIGNED_BYTE, 0)
    assert gl.getError() == gl.NO_ERROR
    for p in (gl.UNPACK_ROW_LENGTH, gl.UNPACK_SKIP_PIXELS, gl.UNPACK_SKIP_ROWS):
        gl.pixelStorei(p, 0)
    gl.bindBuffer(gl.PIXEL_UNPACK_BUFFER, None)
    assert np.array_equal(read_attachment(gl, tex, size=3), src[1:4, 1:4])


def test_float_texture_from_unpack_buffer():
    gl = softgl.Context(2, 2, antialias=False)
    assert gl.getExtension("EXT_color_buffer_float") is not None
    values = np.array([0.5, -2.0, 3.25, 1.0] * 4, np.float32)
    bound_buffer(gl, gl.PIXEL_UNPACK_BUFFER, np.concatenate([np.zeros(2, np.float32), values]))
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, 2, 2, 0, gl.RGBA, gl.FLOAT, 8)
    assert gl.getError() == gl.NO_ERROR
    gl.bindBuffer(gl.PIXEL_UNPACK_BUFFER, None)
    got = read_attachment(gl, tex, size=2, type_=gl.FLOAT)
    assert np.array_equal(got.reshape(-1), values)


@pytest.mark.parametrize("case, error", [
    ("offset without buffer", "INVALID_OPERATION"),
    ("array with buffer", "INVALID_OPERATION"),
    ("null with buffer", "INVALID_OPERATION"),
    ("negative offset", "INVALID_VALUE"),
    ("misaligned offset", "INVALID_OPERATION"),
    ("buffer too small", "INVALID_OPERATION"),
])
def test_unpack_errors(case, error, quiet):
    gl = softgl.Context(2, 2, antialias=False)
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    if case != "offset without buffer":
        bound_buffer(gl, gl.PIXEL_UNPACK_BUFFER, np.zeros(64, np.uint8))
    pixels = {"offset without buffer": 0, "array with buffer": np.zeros(64, np.uint8),
              "null with buffer": None, "negative offset": -4, "misaligned offset": 2,
              "buffer too small": 60}[case]
    type_ = gl.UNSIGNED_SHORT_4_4_4_4 if case == "misaligned offset" else gl.UNSIGNED_BYTE
    if case == "misaligned offset":
        pixels = 1   # not a multiple of 2 bytes
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, 2, 2, 0, gl.RGBA, type_, pixels)
    assert gl.getError() == getattr(gl, error)
    assert gl.getTexParameter(gl.TEXTURE_2D, gl.TEXTURE_IMMUTABLE_FORMAT) is False


def test_offset_is_a_type_error_in_webgl1():
    gl = softgl.Context(2, 2, version=1, antialias=False)
    with pytest.raises(TypeError):
        gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, 1, 1, 0, gl.RGBA, gl.UNSIGNED_BYTE, 0)
    with pytest.raises(TypeError):
        gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, 0)


def test_read_pixels_into_pack_buffer():
    gl = softgl.Context(3, 2, antialias=False, preserveDrawingBuffer=True)
    gl.enable(gl.SCISSOR_TEST)
    colors = {(0, 0): (1, 0, 0, 1), (1, 0): (0, 1, 0, 1), (2, 1): (0.2, 0.4, 0.6, 0.8)}
    for (x, y), c in colors.items():
        gl.scissor(x, y, 1, 1)
        gl.clearColor(*c)
        gl.clear(gl.COLOR_BUFFER_BIT)
    gl.disable(gl.SCISSOR_TEST)
    expected = gl.readPixels(0, 0, 3, 2, gl.RGBA, gl.UNSIGNED_BYTE)
    pbo = bound_buffer(gl, gl.PIXEL_PACK_BUFFER, np.full(64, 0xAA, np.uint8))
    assert gl.readPixels(0, 0, 3, 2, gl.RGBA, gl.UNSIGNED_BYTE, 8) is None
    assert gl.getError() == gl.NO_ERROR
    out = np.zeros(64, np.uint8)
    gl.getBufferSubData(gl.PIXEL_PACK_BUFFER, 0, out)
    assert np.all(out[:8] == 0xAA) and np.all(out[8 + 24:] == 0xAA)
    assert np.array_equal(out[8:8 + 24].reshape(2, 3, 4), expected)
    assert expected[1, 2].tolist() == [51, 102, 153, 204]
    # PACK_ALIGNMENT 8: rows of 12 bytes padded to 16; the last row is not padded.
    gl.pixelStorei(gl.PACK_ALIGNMENT, 8)
    gl.bufferData(gl.PIXEL_PACK_BUFFER, np.zeros(64, np.uint8), gl.STATIC_DRAW)
    gl.readPixels(0, 0, 3, 2, gl.RGBA, gl.UNSIGNED_BYTE, 4)
    gl.getBufferSubData(gl.PIXEL_PACK_BUFFER, 0, out)
    assert np.array_equal(out[4:16].reshape(3, 4), expected[0])
    assert np.array_equal(out[20:32].reshape(3, 4), expected[1])
    assert gl.getError() == gl.NO_ERROR
    del pbo


def test_read_float_attachment_into_pack_buffer():
    gl = softgl.Context(2, 2, antialias=False)
    assert gl.getExtension("EXT_color_buffer_float") is not None
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA32F, 2, 2)
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0)
    gl.clearBufferfv(gl.COLOR, 0, [1.5, -0.25, 3.0, 0.125])
    bound_buffer(gl, gl.PIXEL_PACK_BUFFER, np.zeros(20, np.float32))
    gl.readPixels(0, 0, 2, 2, gl.RGBA, gl.FLOAT, 16)
    assert gl.getError() == gl.NO_ERROR
    out = np.zeros(20, np.float32)
    gl.getBufferSubData(gl.PIXEL_PACK_BUFFER, 0, out)
    assert np.all(out[:4] == 0)
    assert np.array_equal(out[4:].reshape(4, 4), np.tile([1.5, -0.25, 3.0, 0.125], (4, 1)).astype(np.float32))


@pytest.mark.parametrize("case, error", [
    ("offset without buffer", "INVALID_OPERATION"),
    ("array with buffer", "INVALID_OPERATION"),
    ("negative offset", "INVALID_VALUE"),
    ("buffer too small", "INVALID_OPERATION"),
])
def test_pack_errors(case, error, quiet):
    gl = softgl.Context(2, 2, antialias=False)
    if case != "offset without buffer":
        bound_buffer(gl, gl.PIXEL_PACK_BUFFER, np.zeros(16, np.uint8))
    pixels = {"offset without buffer": 0, "array with buffer": np.zeros((2, 2, 4), np.uint8),
              "negative offset": -4, "buffer too small": 4}[case]
    gl.readPixels(0, 0, 2, 2, gl.RGBA, gl.UNSIGNED_BYTE, pixels)
    assert gl.getError() == getattr(gl, error)
