"""Uploads (formats, UNPACK_* state, image sources) and completeness (texture-npot semantics of
WebGL 1, ES 3.0 §3.8.14), read back by drawing texel centres 1:1 into the drawing buffer."""
import warnings

import numpy as np
import pytest

import softgl
from helpers import draw_quad

VS = "attribute vec2 pos; varying vec2 uv; void main() { uv = pos * 0.5 + 0.5; gl_Position = vec4(pos, 0.0, 1.0); }"
FS = "precision mediump float; varying vec2 uv; uniform sampler2D tex; void main() { gl_FragColor = texture2D(tex, uv); }"


def show(gl, w, h):
    """Draw the bound TEXTURE_2D (unit 0) 1:1 into a w x h drawing buffer; (h, w, 4) bytes, row 0 = t 0."""
    prog = softgl.program(gl, VS, FS)
    gl.viewport(0, 0, w, h)
    draw_quad(gl, prog)
    return gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE)


def nearest(gl, target=None):
    target = gl.TEXTURE_2D if target is None else target
    gl.texParameteri(target, gl.TEXTURE_MIN_FILTER, gl.NEAREST)
    gl.texParameteri(target, gl.TEXTURE_MAG_FILTER, gl.NEAREST)


def test_one_pixel_rgb_texture_from_three_bytes(version):
    gl = softgl.Context(1, 1, version=version, antialias=False)
    gl.bindTexture(gl.TEXTURE_2D, gl.createTexture())
    # 3 bytes are enough: the last row is not padded to UNPACK_ALIGNMENT (ES 2.0 §3.6.2).
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGB, 1, 1, 0, gl.RGB, gl.UNSIGNED_BYTE, np.array([255, 0, 0], np.uint8))
    assert gl.getError() == gl.NO_ERROR
    np.testing.assert_array_equal(show(gl, 1, 1)[0, 0], [255, 0, 0, 255])


@pytest.mark.parametrize("alignment", [1, 2, 4, 8])
def test_unpack_alignment_pads_rows(alignment, version):
    gl = softgl.Context(3, 2, version=version, antialias=False)
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, alignment)
    w, h = 3, 2
    stride = -(-w * 3 // alignment) * alignment
    data = np.full(stride * (h - 1) + w * 3, 77, np.uint8)
    texels = np.arange(1, w * h * 3 + 1, dtype=np.uint8).reshape(h, w, 3) * 10
    for r in range(h):
        data[r * stride:r * stride + w * 3] = texels[r].ravel()
    gl.bindTexture(gl.TEXTURE_2D, gl.createTexture())
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGB, w, h, 0, gl.RGB, gl.UNSIGNED_BYTE, data)
    nearest(gl)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE)
    assert gl.getError() == gl.NO_ERROR
    np.testing.assert_array_equal(show(gl, w, h)[..., :3], texels)
    # One byte short is INVALID_OPERATION.
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", softgl.GLWarning)
        gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGB, w, h, 0, gl.RGB, gl.UNSIGNED_BYTE, data[:-1])
    assert gl.getError() == gl.INVALID_OPERATION


def test_flip_y_and_premultiply(version):
    gl = softgl.Context(2, 2, version=version, antialias=False)
    img = np.array([[[200, 100, 50, 128], [10, 20, 30, 255]],
                    [[255, 255, 255, 0], [90, 60, 30, 64]]], np.uint8)
    gl.bindTexture(gl.TEXTURE_2D, gl.createTexture())
    gl.pixelStorei(gl.UNPACK_FLIP_Y_WEBGL, True)
    gl.pixelStorei(gl.UNPACK_PREMULTIPLY_ALPHA_WEBGL, True)
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, 2, 2, 0, gl.RGBA, gl.UNSIGNED_BYTE, img)
    nearest(gl)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE)
    got = show(gl, 2, 2)
    expected = img[::-1].astype(np.float64)
    expected[..., :3] = np.floor(expected[..., :3] * expected[..., 3:] / 255 + 0.5)
    np.testing.assert_array_equal(got, expected.astype(np.uint8))


def test_image_source_overload_and_subimage(version):
    gl = softgl.Context(4, 3, version=version, antialias=False)
    img = np.random.default_rng(1).integers(0, 256, (3, 4, 3), dtype=np.uint8)   # H x W x RGB
    gl.bindTexture(gl.TEXTURE_2D, gl.createTexture())
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGB, gl.RGB, gl.UNSIGNED_BYTE, img)
    nearest(gl)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE)
    assert gl.getError() == gl.NO_ERROR
    np.testing.assert_array_equal(show(gl, 4, 3)[..., :3], img)   # image row 0 -> texel row 0
    patch = np.array([[[1, 2, 3, 4]]], np.uint8)
    gl.texSubImage2D(gl.TEXTURE_2D, 0, 2, 1, gl.RGB, gl.UNSIGNED_BYTE, patch)
    img[1, 2] = [1, 2, 3]
    np.testing.assert_array_equal(show(gl, 4, 3)[..., :3], img)


def test_load_image_feeds_tex_image(tmp_path, version):
    img = np.random.default_rng(2).integers(0, 256, (5, 6, 4), dtype=np.uint8)
    img[..., 3] = 255    # opaque: PNG stores unassociated alpha, the test is about the rows
    path = tmp_path / "t.png"
    softgl.io.save(img, path)
    loaded = softgl.io.load_image(path)
    gl = softgl.Context(6, 5, version=version, antialias=False)
    gl.bindTexture(gl.TEXTURE_2D, gl.createTexture())
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, gl.RGBA, gl.UNSIGNED_BYTE, loaded)
    nearest(gl)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE)
    np.testing.assert_array_equal(show(gl, 6, 5), img)


@pytest.mark.parametrize("fmt,type_,data,expected", [
    ("RGBA", "UNSIGNED_SHORT_4_4_4_4", np.array([0x1234], np.uint16), [17, 34, 51, 68]),
    ("RGBA", "UNSIGNED_SHORT_5_5_5_1", np.array([0b1111100000111111], np.uint16), [255, 0, 255, 255]),
    ("RGB", "UNSIGNED_SHORT_5_6_5", np.array([0b0000011111100000], np.uint16), [0, 255, 0, 255]),
    ("LUMINANCE", "UNSIGNED_BYTE", np.array([90], np.uint8), [90, 90, 90, 255]),
    ("LUMINANCE_ALPHA", "UNSIGNED_BYTE", np.array([90, 40], np.uint8), [90, 90, 90, 40]),
    ("ALPHA", "UNSIGNED_BYTE", np.array([40], np.uint8), [0, 0, 0, 40]),
])
def test_webgl1_formats(fmt, type_, data, expected):
    gl = softgl.Context(1, 1, version=1, antialias=False)
    gl.bindTexture(gl.TEXTURE_2D, gl.createTexture())
    gl.texImage2D(gl.TEXTURE_2D, 0, getattr(gl, fmt), 1, 1, 0, getattr(gl, fmt), getattr(gl, type_), data)
    assert gl.getError() == gl.NO_ERROR
    nearest(gl)
    np.testing.assert_array_equal(show(gl, 1, 1)[0, 0], expected)


def test_float_textures_need_the_extension(quiet):
    gl = softgl.Context(1, 1, version=1, antialias=False)
    gl.bindTexture(gl.TEXTURE_2D, gl.createTexture())
    data = np.array([0.25, 0.5, 0.75, 1.0], np.float32)
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, 1, 1, 0, gl.RGBA, gl.FLOAT, data)
    assert gl.getError() == gl.INVALID_ENUM
    assert gl.getExtension("OES_texture_float") is not None
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, 1, 1, 0, gl.RGBA, gl.FLOAT, data)
    assert gl.getError() == gl.NO_ERROR
    nearest(gl)
    np.testing.assert_array_equal(show(gl, 1, 1)[0, 0], [64, 128, 191, 255])
    ext = gl.getExtension("OES_texture_half_float")
    half = np.array([0.25, 0.5, 0.75, 1.0], np.float16).view(np.uint16)
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, 1, 1, 0, gl.RGBA, ext.HALF_FLOAT_OES, half)
    assert gl.getError() == gl.NO_ERROR
    np.testing.assert_array_equal(show(gl, 1, 1)[0, 0], [64, 128, 191, 255])


def test_typed_array_must_match_type(quiet):
    gl = softgl.Context(1, 1, version=1, antialias=False)
    gl.bindTexture(gl.TEXTURE_2D, gl.createTexture())
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, 1, 1, 0, gl.RGBA, gl.UNSIGNED_SHORT_4_4_4_4, np.zeros(4, np.uint8))
    assert gl.getError() == gl.INVALID_OPERATION
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGB, 1, 1, 0, gl.RGBA, gl.UNSIGNED_BYTE, np.zeros(4, np.uint8))
    assert gl.getError() == gl.INVALID_OPERATION   # internalformat != format in WebGL 1
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, 1, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, np.zeros(4, np.uint8))
    assert gl.getError() == gl.INVALID_VALUE       # border
    gl.bindTexture(gl.TEXTURE_2D, None)
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, 1, 1, 0, gl.RGBA, gl.UNSIGNED_BYTE, np.zeros(4, np.uint8))
    assert gl.getError() == gl.INVALID_OPERATION   # no texture bound


# ---- completeness: conformance/textures/misc/texture-npot.html semantics

def npot_texture(gl, w=5, h=3):
    gl.bindTexture(gl.TEXTURE_2D, gl.createTexture())
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, w, h, 0, gl.RGBA, gl.UNSIGNED_BYTE,
                  np.full((h, w, 4), [10, 200, 30, 255], np.uint8))


BLACK = [0, 0, 0, 255]
GREEN = [10, 200, 30, 255]


def test_webgl1_npot_rules(quiet):
    gl = softgl.Context(1, 1, version=1, antialias=False)
    npot_texture(gl)
    # Default: NEAREST_MIPMAP_LINEAR and REPEAT -> incomplete -> (0, 0, 0, 1).
    np.testing.assert_array_equal(show(gl, 1, 1)[0, 0], BLACK)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.LINEAR)
    np.testing.assert_array_equal(show(gl, 1, 1)[0, 0], BLACK)     # still REPEAT
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE)
    np.testing.assert_array_equal(show(gl, 1, 1)[0, 0], GREEN)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.LINEAR_MIPMAP_LINEAR)
    np.testing.assert_array_equal(show(gl, 1, 1)[0, 0], BLACK)
    gl.generateMipmap(gl.TEXTURE_2D)
    assert gl.getError() == gl.INVALID_OPERATION                    # no NPOT mipmaps in WebGL 1
    gl.texImage2D(gl.TEXTURE_2D, 1, gl.RGBA, 3, 1, 0, gl.RGBA, gl.UNSIGNED_BYTE, np.zeros(12, np.uint8))
    assert gl.getError() == gl.INVALID_VALUE                        # NPOT level > 0


def test_webgl2_npot_is_complete_with_mipmaps():
    gl = softgl.Context(1, 1, version=2, antialias=False)
    npot_texture(gl)
    np.testing.assert_array_equal(show(gl, 1, 1)[0, 0], BLACK)     # mipmaps missing
    gl.generateMipmap(gl.TEXTURE_2D)
    assert gl.getError() == gl.NO_ERROR
    np.testing.assert_array_equal(show(gl, 1, 1)[0, 0], GREEN)


def test_missing_level_and_base_level_rules():
    gl = softgl.Context(1, 1, version=2, antialias=False)
    gl.bindTexture(gl.TEXTURE_2D, gl.createTexture())
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, 2, 2, 0, gl.RGBA, gl.UNSIGNED_BYTE, np.full(16, 255, np.uint8))
    gl.texImage2D(gl.TEXTURE_2D, 1, gl.RGBA, 1, 1, 0, gl.RGBA, gl.UNSIGNED_BYTE, np.array([0, 0, 255, 255], np.uint8))
    # Complete chain; a 2x2 texture on one pixel has lambda = 1: level 1 (blue).
    np.testing.assert_array_equal(show(gl, 1, 1)[0, 0], [0, 0, 255, 255])
    gl.texImage2D(gl.TEXTURE_2D, 1, gl.RGBA, 2, 2, 0, gl.RGBA, gl.UNSIGNED_BYTE, np.zeros(16, np.uint8))
    np.testing.assert_array_equal(show(gl, 1, 1)[0, 0], BLACK)      # wrong size at level 1
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_BASE_LEVEL, 1)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST)
    np.testing.assert_array_equal(show(gl, 1, 1)[0, 0], [0, 0, 0, 0])   # level 1 alone (zeros)


def test_sampler_object_overrides_texture_state():
    gl = softgl.Context(1, 1, version=2, antialias=False)
    npot_texture(gl)
    sampler = gl.createSampler()
    gl.samplerParameteri(sampler, gl.TEXTURE_MIN_FILTER, gl.NEAREST)
    gl.bindSampler(0, sampler)
    np.testing.assert_array_equal(show(gl, 1, 1)[0, 0], GREEN)
    assert gl.getParameter(gl.SAMPLER_BINDING) is sampler
    assert gl.getSamplerParameter(sampler, gl.TEXTURE_MIN_FILTER) == gl.NEAREST
    gl.bindSampler(0, None)
    np.testing.assert_array_equal(show(gl, 1, 1)[0, 0], BLACK)


def test_parameters_and_bindings(version, quiet):
    gl = softgl.Context(1, 1, version=version, antialias=False)
    tex = gl.createTexture()
    assert not gl.isTexture(tex)
    gl.activeTexture(gl.TEXTURE3)
    gl.bindTexture(gl.TEXTURE_CUBE_MAP, tex)
    assert gl.isTexture(tex)
    assert gl.getParameter(gl.TEXTURE_BINDING_CUBE_MAP) is tex
    assert gl.getParameter(gl.TEXTURE_BINDING_2D) is None
    assert gl.getTexParameter(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_MIN_FILTER) == gl.NEAREST_MIPMAP_LINEAR
    gl.texParameteri(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_WRAP_S, gl.MIRRORED_REPEAT)
    assert gl.getTexParameter(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_WRAP_S) == gl.MIRRORED_REPEAT
    gl.texParameteri(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_WRAP_S, gl.LINEAR)
    assert gl.getError() == gl.INVALID_ENUM
    gl.bindTexture(gl.TEXTURE_2D, tex)
    assert gl.getError() == gl.INVALID_OPERATION    # first bound as a cube map
    gl.deleteTexture(tex)
    assert gl.getParameter(gl.TEXTURE_BINDING_CUBE_MAP) is None
    assert not gl.isTexture(tex)


def test_mismatched_sampler_types_on_one_unit_fail_the_draw(quiet):
    gl = softgl.Context(1, 1, version=1, antialias=False)
    fs = """precision mediump float; uniform sampler2D a; uniform samplerCube b;
    void main() { gl_FragColor = texture2D(a, vec2(0.5)) + textureCube(b, vec3(1.0)); }"""
    prog = softgl.program(gl, "attribute vec2 pos; void main() { gl_Position = vec4(pos, 0.0, 1.0); }", fs)
    draw_quad(gl, prog)
    assert gl.getError() == gl.INVALID_OPERATION    # both samplers default to unit 0
    gl.uniform1i(gl.getUniformLocation(prog, "b"), 1)
    draw_quad(gl, prog)
    assert gl.getError() == gl.NO_ERROR
