"""clear() with scissor and masks, and readPixels rules (issue 2).

Expected bytes are computed by hand from ES 3.0 §2.1.6.1 (unorm = round(clamp(c) * 255)) and
§4.2.3 (clear honours scissor and write masks, ignores the viewport); read-outside-the-buffer and
PACK_ALIGNMENT behaviour follow WebGL 1.0 §5.14.12.
"""
import numpy as np
import pytest

import softgl


def unorm8(c):
    c = float(np.float32(c))   # GLclampf arguments are float32
    return int(np.floor(min(max(c, 0.0), 1.0) * 255.0 + 0.5))


def read(gl, x=0, y=0, w=None, h=None):
    w = gl.drawingBufferWidth if w is None else w
    h = gl.drawingBufferHeight if h is None else h
    return gl.readPixels(x, y, w, h, gl.RGBA, gl.UNSIGNED_BYTE)


def test_new_buffer_is_transparent_black(version):
    gl = softgl.Context(3, 2, version=version, antialias=False)
    assert read(gl).shape == (2, 3, 4)
    assert not read(gl).any()


@pytest.mark.parametrize("color", [(0.2, 0.4, 0.6, 0.8), (1.5, -0.5, 0.5019607843, 0.0),
                                   (0.0019, 0.002, 0.998, 1.0)])
def test_clear_color_converts_by_clamp_and_round(color, version):
    gl = softgl.Context(4, 4, version=version, antialias=False)
    gl.clearColor(*color)
    gl.clear(gl.COLOR_BUFFER_BIT)
    expected = [unorm8(c) for c in color]
    assert (read(gl) == expected).all()


def test_clear_color_is_stored_unclamped_and_blend_color_clamped_in_webgl1():
    gl1 = softgl.Context(1, 1, version=1)
    gl1.clearColor(2, -1, 0.5, 1)
    gl1.blendColor(2, -1, 0.5, 3)
    assert gl1.getParameter(gl1.COLOR_CLEAR_VALUE).tolist() == [2, -1, 0.5, 1]   # as Chromium
    assert gl1.getParameter(gl1.BLEND_COLOR).tolist() == [1, 0, 0.5, 1]          # ES 2.0 clamps
    gl2 = softgl.Context(1, 1, version=2)
    gl2.blendColor(2, -1, 0.5, 3)
    assert gl2.getParameter(gl2.BLEND_COLOR).tolist() == [2, -1, 0.5, 3]          # ES 3.0 does not


def test_clear_honours_scissor_not_viewport(version):
    gl = softgl.Context(8, 6, version=version, antialias=False)
    gl.viewport(0, 0, 1, 1)
    gl.enable(gl.SCISSOR_TEST)
    gl.scissor(2, 1, 3, 4)
    gl.clearColor(1, 0, 0, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    expected = np.zeros((6, 8, 4), np.uint8)
    expected[1:5, 2:5] = [255, 0, 0, 255]
    assert np.array_equal(read(gl), expected)
    # A scissor box partly outside the buffer, or with negative origin, clips.
    gl.scissor(-3, 4, 5, 100)
    gl.clearColor(0, 0, 1, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    expected[4:6, 0:2] = [0, 0, 255, 255]
    assert np.array_equal(read(gl), expected)
    # Disabled scissor test: the whole buffer, whatever the box.
    gl.disable(gl.SCISSOR_TEST)
    gl.clearColor(0, 1, 0, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    assert (read(gl) == [0, 255, 0, 255]).all()


def test_zero_sized_scissor_clears_nothing():
    gl = softgl.Context(4, 4, antialias=False)
    gl.enable(gl.SCISSOR_TEST)
    gl.scissor(1, 1, 0, 2)
    gl.clearColor(1, 1, 1, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    assert not read(gl).any()


@pytest.mark.parametrize("mask", [(True, False, True, False), (False, False, False, True),
                                  (False, False, False, False)])
def test_clear_honours_color_mask(mask, version):
    gl = softgl.Context(2, 2, version=version, antialias=False)
    gl.clearColor(0.2, 0.4, 0.6, 0.8)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.colorMask(*mask)
    gl.clearColor(1, 1, 1, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    expected = [255 if m else unorm8(c) for m, c in zip(mask, (0.2, 0.4, 0.6, 0.8))]
    assert (read(gl) == expected).all()
    assert gl.getParameter(gl.COLOR_WRITEMASK) == list(mask)


def test_alpha_false_reads_alpha_one():
    gl = softgl.Context(2, 2, alpha=False, antialias=False)
    assert (read(gl) == [0, 0, 0, 255]).all()
    gl.clearColor(0.5, 0.5, 0.5, 0.0)
    gl.clear(gl.COLOR_BUFFER_BIT)
    assert (read(gl) == [128, 128, 128, 255]).all()


def test_multisampled_buffer_clears_every_sample():
    gl = softgl.Context(3, 3, samples=8)
    gl.clearColor(0.1, 0.7, 0.3, 0.5)
    gl.clear(gl.COLOR_BUFFER_BIT)
    assert (read(gl) == [unorm8(0.1), unorm8(0.7), unorm8(0.3), unorm8(0.5)]).all()


def test_depth_and_stencil_clear_with_masks():
    # Depth and stencil are not readable through readPixels in WebGL; check the stored values
    # through clearDepth/clearStencil state and the masks' effect on the buffer contents.
    gl = softgl.Context(2, 2, stencil=True, antialias=False)
    gl.clearDepth(0.25)
    gl.clearStencil(0x1AB)
    gl.stencilMask(0x0F)
    gl.clear(gl.DEPTH_BUFFER_BIT | gl.STENCIL_BUFFER_BIT)
    assert gl.getParameter(gl.DEPTH_CLEAR_VALUE) == 0.25
    assert gl.getParameter(gl.STENCIL_CLEAR_VALUE) == 0x1AB
    assert gl.getError() == gl.NO_ERROR


def test_clear_depth_clamps():
    gl = softgl.Context(1, 1)
    gl.clearDepth(5)
    assert gl.getParameter(gl.DEPTH_CLEAR_VALUE) == 1.0
    gl.clearDepth(-5)
    assert gl.getParameter(gl.DEPTH_CLEAR_VALUE) == 0.0


def test_read_partly_outside_leaves_destination_untouched(version):
    gl = softgl.Context(4, 4, version=version, antialias=False)
    gl.clearColor(0.2, 0.4, 0.6, 0.8)
    gl.clear(gl.COLOR_BUFFER_BIT)
    dst = np.full(2 * 2 * 4, 7, np.uint8)
    gl.readPixels(-1, -1, 2, 2, gl.RGBA, gl.UNSIGNED_BYTE, dst)
    assert gl.getError() == gl.NO_ERROR
    assert dst.tolist() == [7] * 12 + [51, 102, 153, 204]   # only (0, 0) is inside
    # A new array is zero outside the buffer.
    out = gl.readPixels(3, 3, 2, 2, gl.RGBA, gl.UNSIGNED_BYTE)
    assert out[0, 0].tolist() == [51, 102, 153, 204]
    assert not out[1].any() and not out[0, 1].any()
    # Entirely outside: all untouched.
    out = gl.readPixels(100, -100, 3, 3, gl.RGBA, gl.UNSIGNED_BYTE)
    assert not out.any()


def test_rows_are_bottom_up():
    gl = softgl.Context(2, 3, antialias=False)
    gl.enable(gl.SCISSOR_TEST)
    gl.scissor(0, 0, 2, 1)            # the bottom row in GL window coordinates
    gl.clearColor(1, 0, 0, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    img = read(gl)
    assert img[0].tolist() == [[255, 0, 0, 255]] * 2
    assert not img[1:].any()


def test_pack_alignment_pads_rows_of_a_destination_buffer():
    gl = softgl.Context(3, 2, antialias=False)
    gl.clearColor(1, 1, 1, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.pixelStorei(gl.PACK_ALIGNMENT, 8)
    # 3 RGBA pixels = 12 bytes, padded to 16; the last row is not padded: 16 + 12 = 28 bytes.
    small = np.zeros(27, np.uint8)
    with pytest.warns(softgl.GLWarning):
        gl.readPixels(0, 0, 3, 2, gl.RGBA, gl.UNSIGNED_BYTE, small)
    assert gl.getError() == gl.INVALID_OPERATION and not small.any()
    dst = np.zeros(28, np.uint8)
    gl.readPixels(0, 0, 3, 2, gl.RGBA, gl.UNSIGNED_BYTE, dst)
    assert gl.getError() == gl.NO_ERROR
    assert dst[:12].tolist() == [255] * 12 and dst[12:16].tolist() == [0] * 4
    assert dst[16:].tolist() == [255] * 12


def test_pack_row_length_and_skips_webgl2():
    gl = softgl.Context(2, 2, antialias=False)
    gl.clearColor(1, 1, 1, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.pixelStorei(gl.PACK_ROW_LENGTH, 4)
    gl.pixelStorei(gl.PACK_SKIP_PIXELS, 1)
    gl.pixelStorei(gl.PACK_SKIP_ROWS, 1)
    dst = np.zeros((3, 4, 4), np.uint8)       # 3 rows of 4 pixels
    gl.readPixels(0, 0, 2, 2, gl.RGBA, gl.UNSIGNED_BYTE, dst)
    assert gl.getError() == gl.NO_ERROR
    written = dst[..., 0] == 255
    assert written.tolist() == [[False] * 4, [False, True, True, False], [False, True, True, False]]


@pytest.mark.parametrize("fmt, typ, v1_error, v2_error", [
    ("RGB", "UNSIGNED_BYTE", "INVALID_OPERATION", "INVALID_OPERATION"),
    ("RGBA", "FLOAT", "INVALID_ENUM", "INVALID_OPERATION"),   # FLOAT is not a WebGL 1 read type
    (0x1234, "UNSIGNED_BYTE", "INVALID_ENUM", "INVALID_ENUM"),
    ("RGBA", 0x1234, "INVALID_ENUM", "INVALID_ENUM"),
])
def test_read_format_type_errors(fmt, typ, v1_error, v2_error, version, quiet):
    gl = softgl.Context(2, 2, version=version, antialias=False)
    resolve = lambda v: getattr(gl, v) if isinstance(v, str) else v
    dtype = np.float32 if typ == "FLOAT" else np.uint8
    dst = np.zeros(16, dtype)
    gl.readPixels(0, 0, 2, 2, resolve(fmt), resolve(typ), dst)
    assert gl.getError() == getattr(gl, v1_error if version == 1 else v2_error)
    assert gl.readPixels(0, 0, 2, 2, resolve(fmt), resolve(typ)) is None


def test_read_errors_for_sizes_and_destination(quiet):
    gl = softgl.Context(2, 2, antialias=False)
    assert gl.readPixels(0, 0, -1, 2, gl.RGBA, gl.UNSIGNED_BYTE) is None
    assert gl.getError() == gl.INVALID_VALUE
    gl.readPixels(0, 0, -1, 2, 0x1234, gl.UNSIGNED_BYTE)      # enum errors come first
    assert gl.getError() == gl.INVALID_ENUM
    gl.readPixels(0, 0, 2, 2, gl.RGBA, gl.UNSIGNED_BYTE, np.zeros(16, np.float32))
    assert gl.getError() == gl.INVALID_OPERATION               # Float32Array for UNSIGNED_BYTE
    gl.readPixels(0, 0, 2, 2, gl.RGBA, gl.UNSIGNED_BYTE, np.zeros(15, np.uint8))
    assert gl.getError() == gl.INVALID_OPERATION
    empty = gl.readPixels(0, 0, 0, 0, gl.RGBA, gl.UNSIGNED_BYTE)
    assert empty.shape == (0, 0, 4) and gl.getError() == gl.NO_ERROR
    with pytest.raises(TypeError):
        gl.readPixels(0, 0, 2, 2, gl.RGBA, gl.UNSIGNED_BYTE, [0] * 16)
    # A strided destination is written through a native copy (docs/reliability.md, "Array intake").
    strided = np.full((2, 16), 7, np.uint8)
    gl.readPixels(0, 0, 2, 2, gl.RGBA, gl.UNSIGNED_BYTE, strided[:, ::2])
    assert gl.getError() == gl.NO_ERROR
    assert np.array_equal(strided[:, ::2].reshape(-1), gl.readPixels(0, 0, 2, 2, gl.RGBA, gl.UNSIGNED_BYTE).reshape(-1))
    assert (strided[:, 1::2] == 7).all()


def test_huge_read_fails_cleanly(quiet):
    # A result that cannot fit is OUT_OF_MEMORY before anything is allocated.
    gl = softgl.Context(2, 2, antialias=False)
    assert gl.readPixels(0, 0, 2**31 - 1, 2**31 - 1, gl.RGBA, gl.UNSIGNED_BYTE) is None
    assert gl.getError() == gl.OUT_OF_MEMORY
