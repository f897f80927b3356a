"""16-bit float textures are stored as binary16 (Image::packed, surface/texture.h) and the
sampler's texel loads decode them (F16C in the AVX2 / AVX-512 paths, half_to_float lane by lane;
binary16 -> float32 is exact). Sampling one must give, bit for bit, what the same texels held as
float32 give: an RGBA32F texture of NumPy's float16 rounding of the uploaded floats (ES 3.0 table
3.24 expansion: absent channels 0, alpha 1), for NEAREST, LINEAR and trilinear filters, REPEAT and
CLAMP_TO_EDGE, 2D, 2D arrays, 3D and cube maps, every SIMD level, 1 and 2 threads and the general
(lane by lane) path. The draws write the sampled floats to an RGBA32F target, so every bit of the
filter is compared. texSubImage2D, copyTexImage2D / copyTexSubImage2D and generateMipmap of such
textures are checked against NumPy (np.float16 rounding, float64 box averages)."""
import numpy as np
import pytest

import softgl
from helpers import RECEDING_FS_ARRAY as FS_ARRAY, RECEDING_FS_CUBE as FS_CUBE, RECEDING_VS as VS
from helpers import STORAGE_FILTERS as FILTERS, draw_quad, float_sampling_context, read_float_quad
from helpers import rgba_expansion as expand, sample_float_levels, sampling_configs as configs

FORMATS = {"R16F": ("RED", 1), "RG16F": ("RG", 2), "RGB16F": ("RGB", 3), "RGBA16F": ("RGBA", 4)}
W, H = 64, 48
FS_3D = """#version 300 es
precision highp float; uniform highp sampler3D tex; in vec2 uv; out vec4 o;
void main() { o = texture(tex, vec3(uv, uv.y * 0.7 + 0.1)); }"""


def as_half(v):
    """float32 v rounded to binary16 (IEEE round to nearest even) and back, by NumPy."""
    return v.astype(np.float16).astype(np.float32)


def raw(rng, shape):
    """float32 values most of which are not binary16 values (the upload rounds them)."""
    return rng.uniform(-4, 4, shape).astype(np.float32)


def levels_of(name, size):
    rng = np.random.default_rng(sum(map(ord, name)) + size[0])
    w, h = size
    out = []
    while True:
        out.append(raw(rng, (h, w, FORMATS[name][1])))
        if w == 1 and h == 1:
            return out
        w, h = max(w // 2, 1), max(h // 2, 1)


@pytest.mark.parametrize("name", list(FORMATS))
@pytest.mark.parametrize("filters", FILTERS, ids=["/".join(f) for f in FILTERS])
@pytest.mark.parametrize("wrap,size", [("REPEAT", (32, 16)), ("CLAMP_TO_EDGE", (13, 7))])
def test_16f_textures_sample_as_the_float32_texture_of_their_halves(name, filters, wrap, size):
    fmt = FORMATS[name][0]
    levels = levels_of(name, size)
    want = sample_float_levels([expand(as_half(v)) for v in levels], "RGBA32F", "RGBA", filters, wrap, 1, "scalar", "best",
                               W, H)
    assert np.ptp(want.reshape(-1, 4)[:, 0]) > 0.3   # not a constant image
    for threads, level, path in configs():
        got = sample_float_levels(levels, name, fmt, filters, wrap, threads, level, path, W, H)
        np.testing.assert_array_equal(got.view(np.uint32), want.view(np.uint32),
                                      err_msg=f"{name} {filters} {wrap} {size} threads {threads} {level} {path}")


def draw_volume(layers, internal, fmt, kind, filt, threads, simd, path):
    """layers: (n, h, w, channels) floats; kind: "array", "3d" (n layers) or "cube" (6 faces)."""
    gl = float_sampling_context(W, H, threads, simd, path)
    n, h, w = layers.shape[:3]
    target = {"array": gl.TEXTURE_2D_ARRAY, "3d": gl.TEXTURE_3D, "cube": gl.TEXTURE_CUBE_MAP}[kind]
    tex = gl.createTexture()
    gl.bindTexture(target, tex)
    if kind != "cube":
        gl.texImage3D(target, 0, getattr(gl, internal), w, h, n, 0, getattr(gl, fmt), gl.FLOAT, np.ascontiguousarray(layers))
    else:
        for face in range(6):
            gl.texImage2D(gl.TEXTURE_CUBE_MAP_POSITIVE_X + face, 0, getattr(gl, internal), w, h, 0, getattr(gl, fmt),
                          gl.FLOAT, np.ascontiguousarray(layers[face]))
    gl.texParameteri(target, gl.TEXTURE_MIN_FILTER, getattr(gl, filt))
    gl.texParameteri(target, gl.TEXTURE_MAG_FILTER, getattr(gl, filt))
    return read_float_quad(gl, VS, {"array": FS_ARRAY, "3d": FS_3D, "cube": FS_CUBE}[kind], W, H)


@pytest.mark.parametrize("name", ["R16F", "RGBA16F"])
@pytest.mark.parametrize("kind", ["array", "3d", "cube"])
@pytest.mark.parametrize("filt", ["NEAREST", "LINEAR"])
def test_16f_arrays_volumes_and_cube_maps_sample_as_their_float32_halves(name, kind, filt):
    fmt, channels = FORMATS[name]
    layers = raw(np.random.default_rng(sum(map(ord, name + kind))), (4 if kind != "cube" else 6, 16, 16, channels))
    want = draw_volume(expand(as_half(layers)), "RGBA32F", "RGBA", kind, filt, 1, "scalar", "best")
    assert np.ptp(want.reshape(-1, 4)[:, 0]) > 0.1
    for threads, level, path in configs():
        got = draw_volume(layers, name, fmt, kind, filt, threads, level, path)
        np.testing.assert_array_equal(got.view(np.uint32), want.view(np.uint32),
                                      err_msg=f"{name} {kind} {filt} threads {threads} {level} {path}")


# ---------------------------------------------------------------------------- uploads, copies, mipmaps

FETCH_VS = """#version 300 es
in vec2 pos; void main() { gl_Position = vec4(pos, 0.0, 1.0); }"""
FETCH_FS = """#version 300 es
precision highp float; uniform highp sampler2D src; uniform int lod; out vec4 o;
void main() { o = texelFetch(src, ivec2(gl_FragCoord.xy), lod); }"""


def fetched(gl, tex, w, h, lod=0):
    """Texels of level `lod` of tex as texelFetch returns them, drawn into an RGBA32F target."""
    target = gl.createTexture()
    gl.activeTexture(gl.TEXTURE2)
    gl.bindTexture(gl.TEXTURE_2D, target)
    gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA32F, w, h)
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, target, 0)
    gl.viewport(0, 0, w, h)
    gl.activeTexture(gl.TEXTURE1)
    gl.bindTexture(gl.TEXTURE_2D, tex)
    gl.activeTexture(gl.TEXTURE0)
    prog = softgl.program(gl, FETCH_VS, FETCH_FS)
    gl.useProgram(prog)
    gl.uniform1i(gl.getUniformLocation(prog, "src"), 1)
    gl.uniform1i(gl.getUniformLocation(prog, "lod"), lod)
    draw_quad(gl, prog)
    out = np.asarray(gl.readPixels(0, 0, w, h, gl.RGBA, gl.FLOAT), np.float32)
    assert gl.getError() == gl.NO_ERROR
    return out


def plain_context():
    gl = softgl.Context(8, 8, antialias=False, version=2)
    assert gl.getExtension("EXT_color_buffer_float") is not None
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1)
    return gl


def texture(gl, internal, w, h, data, client_type=None):
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    gl.texImage2D(gl.TEXTURE_2D, 0, getattr(gl, internal), w, h, 0, getattr(gl, FORMATS[internal][0]),
                  gl.FLOAT if client_type is None else client_type, data)
    for p in (gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER):
        gl.texParameteri(gl.TEXTURE_2D, p, gl.NEAREST)
    return tex


@pytest.mark.parametrize("internal", list(FORMATS))
def test_tex_sub_image_of_16f_textures(internal):
    """texSubImage2D of FLOAT and HALF_FLOAT data into a 16F texture: the rectangle holds the new
    binary16 values, the rest its old ones."""
    gl = plain_context()
    fmt, channels = FORMATS[internal]
    w, h = 19, 11
    rng = np.random.default_rng(channels + 40)
    v = raw(rng, (h, w, channels))
    tex = texture(gl, internal, w, h, v)
    sub = raw(rng, (4, 7, channels))
    gl.texSubImage2D(gl.TEXTURE_2D, 0, 3, 5, 7, 4, getattr(gl, fmt), gl.FLOAT, sub)
    bits = rng.integers(0, 0x7800, (2, 5, channels), dtype=np.uint16)   # finite halves, both signs below
    bits[..., 0] |= 0x8000
    gl.texSubImage2D(gl.TEXTURE_2D, 0, 12, 1, 5, 2, getattr(gl, fmt), gl.HALF_FLOAT, bits)
    assert gl.getError() == gl.NO_ERROR
    want = as_half(v)
    want[5:9, 3:10] = as_half(sub)
    want[1:3, 12:17] = bits.view(np.float16).astype(np.float32)
    np.testing.assert_array_equal(fetched(gl, tex, w, h).view(np.uint32), expand(want).view(np.uint32))


@pytest.mark.parametrize("internal", ["R16F", "RG16F", "RGBA16F"])
def test_copy_tex_image_from_a_16f_framebuffer(internal):
    """copyTexImage2D / copyTexSubImage2D from a framebuffer whose attachment is a 16F texture
    into 16F textures: the copied texels are the source's binary16 values (already halves: the
    copy rounds nothing), the rest of a sub-copy's destination keeps its own."""
    gl = plain_context()
    fmt, channels = FORMATS[internal]
    w, h = 21, 13
    rng = np.random.default_rng(channels + 70)
    v = raw(rng, (h, w, channels))
    src = texture(gl, internal, w, h, v)
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, src, 0)
    assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == gl.FRAMEBUFFER_COMPLETE
    # readPixels of the 16F attachment: the halves as floats.
    np.testing.assert_array_equal(np.asarray(gl.readPixels(0, 0, w, h, gl.RGBA, gl.FLOAT), np.float32).view(np.uint32),
                                  expand(as_half(v)).view(np.uint32))
    copy = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, copy)
    gl.copyTexImage2D(gl.TEXTURE_2D, 0, getattr(gl, internal), 2, 3, 15, 8, 0)
    assert gl.getError() == gl.NO_ERROR
    for p in (gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER):
        gl.texParameteri(gl.TEXTURE_2D, p, gl.NEAREST)
    other = raw(rng, (9, 10, channels))
    dst = texture(gl, internal, 10, 9, other)
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    gl.copyTexSubImage2D(gl.TEXTURE_2D, 0, 1, 2, 4, 6, 6, 5)
    assert gl.getError() == gl.NO_ERROR
    np.testing.assert_array_equal(fetched(gl, copy, 15, 8).view(np.uint32), expand(as_half(v)[3:11, 2:17]).view(np.uint32))
    want = as_half(other)
    want[2:7, 1:7] = as_half(v)[6:11, 4:10]
    np.testing.assert_array_equal(fetched(gl, dst, 10, 9).view(np.uint32), expand(want).view(np.uint32))


@pytest.mark.parametrize("internal", ["R16F", "RG16F", "RGBA16F"])   # (RGB16F is not colour-renderable)
def test_generate_mipmap_of_16f_textures(internal):
    """generateMipmap's box filter (texture.cpp: the 2 x 2 texels averaged in double, rounded to
    float32, then stored as binary16) of a 16F texture: each level from the previous level's
    halves, by NumPy in float64."""
    gl = plain_context()
    channels = FORMATS[internal][1]
    w, h = 16, 8
    v = raw(np.random.default_rng(channels + 90), (h, w, channels))
    tex = texture(gl, internal, w, h, v)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST_MIPMAP_NEAREST)   # levels > 0 fetched
    gl.generateMipmap(gl.TEXTURE_2D)
    assert gl.getError() == gl.NO_ERROR
    level = as_half(v).astype(np.float64)
    for lod in range(1, 4):
        level = level.reshape(level.shape[0] // 2, 2, level.shape[1] // 2, 2, channels).mean(axis=(1, 3))
        level = as_half(level.astype(np.float32)).astype(np.float64)
        hh, ww = level.shape[:2]
        np.testing.assert_array_equal(fetched(gl, tex, ww, hh, lod).view(np.uint32),
                                      expand(level.astype(np.float32)).view(np.uint32), err_msg=f"level {lod}")


def test_webgl1_luminance_half_float_textures_keep_alpha_one():
    """WebGL 1 OES_texture_half_float LUMINANCE / ALPHA / LUMINANCE_ALPHA textures (kept expanded
    to RGBA halves): a texture allocated without data reads (0, 0, 0, 1) for LUMINANCE (alpha
    absent: 1), uploaded texels read as ES 3.0 table 3.24 expands them."""
    gl = softgl.Context(4, 4, antialias=False, version=1)
    ext = gl.getExtension("OES_texture_half_float")
    assert ext is not None
    half = ext.HALF_FLOAT_OES
    vs = "attribute vec2 pos; void main() { gl_Position = vec4(pos, 0.0, 1.0); }"
    fs = "precision highp float; uniform sampler2D t; void main() { gl_FragColor = texture2D(t, vec2(0.5)) * 0.5; }"
    prog = softgl.program(gl, vs, fs)
    for fmt, data, want in [
        ("LUMINANCE", None, [0, 0, 0, 128]),
        ("LUMINANCE", np.array([0.5], np.float16).view(np.uint16), [64, 64, 64, 128]),
        ("ALPHA", np.array([1.0], np.float16).view(np.uint16), [0, 0, 0, 128]),
        ("LUMINANCE_ALPHA", np.array([1.0, 0.25], np.float16).view(np.uint16), [128, 128, 128, 32]),
    ]:
        t = gl.createTexture()
        gl.bindTexture(gl.TEXTURE_2D, t)
        gl.texImage2D(gl.TEXTURE_2D, 0, getattr(gl, fmt), 1, 1, 0, getattr(gl, fmt), half, data)
        gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST)
        gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST)
        draw_quad(gl, prog)
        got = np.asarray(gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE)).reshape(4)
        assert gl.getError() == gl.NO_ERROR
        assert list(got) == want, (fmt, list(got))
