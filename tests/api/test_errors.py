"""WebGL error semantics (issue 2): first error kept, nothing changes, warning names the call."""
import math
import warnings

import numpy as np
import pytest

import softgl


def snapshot(gl):
    """Every parameter the context answers, as comparable Python values."""
    values = {}
    for name, value, version in softgl._core.ENUMS:
        if version > gl.version:
            continue
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", softgl.GLWarning)
            result = gl.getParameter(value)
            if gl.getError() != gl.NO_ERROR:
                continue
        values[name] = result.tolist() if isinstance(result, np.ndarray) else result
    return values


def test_first_error_is_kept_until_get_error(quiet):
    gl = softgl.Context(2, 2)
    gl.enable(0x1234)             # INVALID_ENUM
    gl.lineWidth(-1)              # INVALID_VALUE, not kept: an error is already pending
    assert gl.getError() == gl.INVALID_ENUM
    assert gl.getError() == gl.NO_ERROR
    gl.lineWidth(-1)
    assert gl.getError() == gl.INVALID_VALUE


def test_warning_names_call_and_reason():
    gl = softgl.Context(2, 2)
    with pytest.warns(softgl.GLWarning, match=r"INVALID_ENUM: depthFunc: .*comparison") as record:
        gl.depthFunc(gl.BLEND)
    warning = record[0].message
    assert (warning.code, warning.call) == (gl.INVALID_ENUM, "depthFunc")
    assert record[0].filename == __file__   # points at the user's line, like a console


def test_strict_mode_raises_and_changes_nothing():
    gl = softgl.Context(2, 2, strict=True)
    with pytest.raises(softgl.GLError, match="INVALID_OPERATION: depthRange"):
        gl.depthRange(0.9, 0.1)
    assert gl.getParameter(gl.DEPTH_RANGE).tolist() == [0.0, 1.0]
    assert gl.getError() == gl.INVALID_OPERATION


def test_valid_calls_emit_no_warning():
    gl = softgl.Context(2, 2)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        gl.enable(gl.BLEND)
        gl.blendFuncSeparate(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA, gl.ONE, gl.ZERO)
        gl.clear(gl.COLOR_BUFFER_BIT)
    assert gl.getError() == gl.NO_ERROR


# Each invalid call below must record `error` and leave every parameter as it was.
# (version, call, args, error); versions: 0 = both.
INVALID_CALLS = [
    (0, "enable", (0x0B60,), "INVALID_ENUM"),                # desktop GL FOG: not a WebGL cap
    (0, "enable", ("TEXTURE_2D",), "INVALID_ENUM"),
    (1, "enable", ("RASTERIZER_DISCARD",), "INVALID_ENUM"),  # WebGL 2 only
    (0, "disable", (0x1234,), "INVALID_ENUM"),
    (0, "blendFunc", ("CONSTANT_COLOR", "CONSTANT_ALPHA"), "INVALID_OPERATION"),
    (0, "blendFunc", ("ONE_MINUS_CONSTANT_ALPHA", "CONSTANT_COLOR"), "INVALID_OPERATION"),
    (0, "blendFuncSeparate", ("CONSTANT_ALPHA", "ONE_MINUS_CONSTANT_COLOR", "ONE", "ONE"), "INVALID_OPERATION"),
    (1, "blendFunc", ("ONE", "SRC_ALPHA_SATURATE"), "INVALID_ENUM"),
    (0, "blendFunc", ("BLEND", "ONE"), "INVALID_ENUM"),
    (0, "blendFunc", (0x1234, "CONSTANT_ALPHA"), "INVALID_ENUM"),  # enum checked before pairing
    (1, "blendEquation", (0x8007,), "INVALID_ENUM"),         # MIN without EXT_blend_minmax
    (0, "blendEquation", ("ONE",), "INVALID_ENUM"),
    (0, "blendEquationSeparate", ("FUNC_ADD", 0x1234), "INVALID_ENUM"),
    (0, "depthFunc", ("BLEND",), "INVALID_ENUM"),
    (0, "depthRange", (0.7, 0.3), "INVALID_OPERATION"),
    (0, "stencilFunc", ("KEEP", 0, 0xFF), "INVALID_ENUM"),
    (0, "stencilFuncSeparate", ("CW", "ALWAYS", 0, 0xFF), "INVALID_ENUM"),
    (0, "stencilOp", ("KEEP", 0x1234, "KEEP"), "INVALID_ENUM"),
    (0, "stencilOpSeparate", ("FRONT", "KEEP", "KEEP", "NEVER"), "INVALID_ENUM"),
    (0, "stencilMaskSeparate", ("CCW", 0), "INVALID_ENUM"),
    (0, "cullFace", ("CW",), "INVALID_ENUM"),
    (0, "frontFace", ("BACK",), "INVALID_ENUM"),
    (0, "lineWidth", (0.0,), "INVALID_VALUE"),
    (0, "lineWidth", (-1.0,), "INVALID_VALUE"),
    (0, "lineWidth", (math.nan,), "INVALID_VALUE"),
    (0, "scissor", (0, 0, -1, 1), "INVALID_VALUE"),
    (0, "viewport", (0, 0, 1, -1), "INVALID_VALUE"),
    (0, "hint", (0x1234, "NICEST"), "INVALID_ENUM"),
    (0, "hint", ("GENERATE_MIPMAP_HINT", "BLEND"), "INVALID_ENUM"),
    (1, "hint", (0x8B8B, "NICEST"), "INVALID_ENUM"),         # derivative hint needs WebGL 2
    (0, "pixelStorei", ("PACK_ALIGNMENT", 3), "INVALID_VALUE"),
    (0, "pixelStorei", ("UNPACK_ALIGNMENT", 0), "INVALID_VALUE"),
    (0, "pixelStorei", ("UNPACK_COLORSPACE_CONVERSION_WEBGL", 5), "INVALID_VALUE"),
    (0, "pixelStorei", (0x1234, 1), "INVALID_ENUM"),
    (1, "pixelStorei", (0x0D02, 4), "INVALID_ENUM"),         # PACK_ROW_LENGTH is WebGL 2
    (2, "pixelStorei", ("PACK_ROW_LENGTH", -1), "INVALID_VALUE"),
    (0, "activeTexture", (0x84C0 + 32,), "INVALID_ENUM"),
    (0, "activeTexture", (0x84C0 - 1,), "INVALID_ENUM"),
    (0, "clear", (0x8000,), "INVALID_VALUE"),
    (0, "getParameter", (0x1234,), "INVALID_ENUM"),
    (1, "getParameter", (0x8C89,), "INVALID_ENUM"),          # RASTERIZER_DISCARD in WebGL 1
    (0, "isEnabled", (0x0B60,), "INVALID_ENUM"),
]


def _resolve(gl, arg):
    return getattr(softgl, arg) if isinstance(arg, str) else arg


@pytest.mark.parametrize("case", INVALID_CALLS, ids=lambda c: f"{c[1]}{c[2]}-v{c[0]}")
def test_invalid_call_records_error_and_changes_nothing(case, version, quiet):
    only, call, args, error = case
    if only and only != version:
        pytest.skip("other version")
    gl = softgl.Context(4, 4, version=version, stencil=True)
    gl.clearColor(0.25, 0.5, 0.75, 1.0)
    gl.clear(gl.COLOR_BUFFER_BIT)
    before_state, before_pixels = snapshot(gl), gl.readPixels(0, 0, 4, 4, gl.RGBA, gl.UNSIGNED_BYTE)
    getattr(gl, call)(*[_resolve(gl, a) for a in args])
    assert gl.getError() == getattr(softgl, error)
    assert snapshot(gl) == before_state
    assert np.array_equal(gl.readPixels(0, 0, 4, 4, gl.RGBA, gl.UNSIGNED_BYTE), before_pixels)


def test_ext_blend_minmax(quiet):
    gl = softgl.Context(2, 2, version=1)
    assert "EXT_blend_minmax" in gl.getSupportedExtensions()
    gl.blendEquation(0x8008)
    assert gl.getError() == gl.INVALID_ENUM
    ext = gl.getExtension("EXT_blend_minmax")
    assert ext is gl.getExtension("EXT_blend_minmax")       # the same object every time
    assert (ext.MIN_EXT, ext.MAX_EXT) == (0x8007, 0x8008)
    gl.blendEquationSeparate(ext.MIN_EXT, ext.MAX_EXT)
    assert gl.getError() == gl.NO_ERROR
    assert gl.getParameter(gl.BLEND_EQUATION_RGB) == ext.MIN_EXT
    assert gl.getParameter(gl.BLEND_EQUATION_ALPHA) == ext.MAX_EXT
    # WebGL 2 has MIN/MAX in core and no such extension.
    gl2 = softgl.Context(2, 2)
    assert gl2.getExtension("EXT_blend_minmax") is None
    gl2.blendEquation(gl2.MAX)
    assert gl2.getError() == gl2.NO_ERROR


def test_unknown_extension_is_none():
    gl = softgl.Context(2, 2)
    assert gl.getExtension("WEBGL_not_a_thing") is None
    assert gl.getExtension("SOFTGL_smooth") is None   # not offered until it works


def test_errors_from_calls_that_release_the_gil():
    # Draws and compiles run without the GIL; their errors must still warn or raise cleanly.
    gl = softgl.Context(2, 2)
    with pytest.warns(softgl.GLWarning, match="drawArrays"):
        gl.drawArrays(gl.TRIANGLES, 0, 3)
    assert gl.getError() == gl.INVALID_OPERATION
    strict = softgl.Context(2, 2, strict=True)
    with pytest.raises(softgl.GLError, match="drawArrays: no valid program"):
        strict.drawArrays(strict.TRIANGLES, 0, 3)
    shader = strict.createShader(strict.VERTEX_SHADER)
    strict.deleteShader(shader)
    with pytest.raises(softgl.GLError, match="INVALID_VALUE: compileShader"):
        strict.compileShader(shader)
