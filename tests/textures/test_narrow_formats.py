"""Textures of one or two 8-bit unorm channels (R8, RG8, LUMINANCE, ALPHA, LUMINANCE_ALPHA) keep
1-2 bytes a texel (Image::narrow, surface/texture.h) and the sampler's block paths decode them
(narrow_words8/16, surface/sampler.cpp). Sampling one must give the same floats, bit for bit, as
the same texture uploaded RGBA8 with the channels the format implies (ES 3.0 table 3.24:
R -> (r, 0, 0, 1), RG -> (r, g, 0, 1), L -> (l, l, l, 1), A -> (0, 0, 0, a), LA -> (l, l, l, a)),
for NEAREST, LINEAR and trilinear filters, REPEAT and CLAMP_TO_EDGE, every SIMD level, 1 and 2
threads and the general (lane by lane) path. The draw writes the sampled floats to an RGBA32F
target, so every bit of the filter is compared."""
import numpy as np
import pytest

import softgl
from helpers import RECEDING_FS as FS, RECEDING_FS_ARRAY as FS_ARRAY, RECEDING_FS_CUBE as FS_CUBE, RECEDING_VS as VS
from helpers import STORAGE_FILTERS as FILTERS, draw_quad
from softgl import _core


# (internal format, format, channels): the narrow formats and how RGBA8 spells them.
FORMATS = {"R8": ("R8", "RED", 1), "RG8": ("RG8", "RG", 2), "LUMINANCE": ("LUMINANCE", "LUMINANCE", 1),
           "ALPHA": ("ALPHA", "ALPHA", 1), "LUMINANCE_ALPHA": ("LUMINANCE_ALPHA", "LUMINANCE_ALPHA", 2)}
W, H = 64, 48


def expand(name, k):
    """The RGBA bytes of narrow texels k (..., channels), as ES 3.0 table 3.24 reads them."""
    z, one = np.zeros_like(k[..., 0]), np.full_like(k[..., 0], 255)
    a = k[..., 0]
    b = k[..., 1] if k.shape[-1] > 1 else z
    return np.stack({"R8": (a, z, z, one), "RG8": (a, b, z, one), "LUMINANCE": (a, a, a, one),
                     "ALPHA": (z, z, z, a), "LUMINANCE_ALPHA": (a, a, a, b)}[name], axis=-1)


def levels_of(name, size):
    rng = np.random.default_rng(sum(map(ord, name)) + size[0])
    w, h = size
    out = []
    while True:
        out.append(rng.integers(0, 256, (h, w, FORMATS[name][2])).astype(np.uint8))
        if w == 1 and h == 1:
            return out
        w, h = max(w // 2, 1), max(h // 2, 1)


def draw(levels, internal, fmt, filters, wrap, threads, simd, path):
    gl = softgl.Context(W, H, threads=threads, antialias=False, version=2)
    _core.testing.set_tuning(gl, simd=simd, sampler_path=path)
    assert gl.getExtension("EXT_color_buffer_float") is not None
    rb = gl.createRenderbuffer()
    gl.bindRenderbuffer(gl.RENDERBUFFER, rb)
    gl.renderbufferStorage(gl.RENDERBUFFER, gl.RGBA32F, W, H)
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.RENDERBUFFER, rb)
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1)
    for k, level in enumerate(levels):
        h, w = level.shape[:2]
        gl.texImage2D(gl.TEXTURE_2D, k, getattr(gl, internal), w, h, 0, getattr(gl, fmt), gl.UNSIGNED_BYTE,
                      np.ascontiguousarray(level))
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, getattr(gl, filters[0]))
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, getattr(gl, filters[1]))
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, getattr(gl, wrap))
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, getattr(gl, wrap))
    draw_quad(gl, softgl.program(gl, VS, FS))
    out = np.asarray(gl.readPixels(0, 0, W, H, gl.RGBA, gl.FLOAT), np.float32)
    assert gl.getError() == gl.NO_ERROR
    return out


@pytest.mark.parametrize("name", list(FORMATS))
@pytest.mark.parametrize("filters", FILTERS, ids=["/".join(f) for f in FILTERS])
@pytest.mark.parametrize("wrap,size", [("REPEAT", (32, 16)), ("CLAMP_TO_EDGE", (32, 16)), ("CLAMP_TO_EDGE", (13, 7)),
                                       ("REPEAT", (13, 7))])
def test_narrow_formats_sample_as_their_rgba8_expansion(name, filters, wrap, size):
    internal, fmt, _ = FORMATS[name]
    levels = levels_of(name, size)
    simd = ["scalar", "sse2", "avx2", "avx512"][:_core.testing.simd_level() + 1]
    want = draw([expand(name, k) for k in levels], "RGBA8", "RGBA", filters, wrap, 1, "scalar", "best")
    # Not a constant image: the texels' differences reach the result.
    assert np.ptp(want.reshape(-1, 4), axis=0).max() > 0.3
    configs = [(1, lv, "best") for lv in simd] + [(2, simd[-1], "best"), (1, simd[-1], "general")]
    for threads, level, path in configs:
        got = draw(levels, internal, fmt, filters, wrap, threads, level, path)
        np.testing.assert_array_equal(got.view(np.uint32), want.view(np.uint32),
                                      err_msg=f"{name} {filters} {wrap} {size} threads {threads} {level} {path}")
        if path == "best":   # and RGBA8 itself, at this configuration: the same bits
            rgba = draw([expand(name, k) for k in levels], "RGBA8", "RGBA", filters, wrap, threads, level, path)
            np.testing.assert_array_equal(rgba.view(np.uint32), want.view(np.uint32))


def draw_layers(layers, internal, fmt, kind, threads, simd, path):
    """layers: (n, h, w, channels) bytes; kind: "array" (n layers) or "cube" (6 faces)."""
    gl = softgl.Context(W, H, threads=threads, antialias=False, version=2)
    _core.testing.set_tuning(gl, simd=simd, sampler_path=path)
    assert gl.getExtension("EXT_color_buffer_float") is not None
    rb = gl.createRenderbuffer()
    gl.bindRenderbuffer(gl.RENDERBUFFER, rb)
    gl.renderbufferStorage(gl.RENDERBUFFER, gl.RGBA32F, W, H)
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.RENDERBUFFER, rb)
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1)
    n, h, w = layers.shape[:3]
    target = gl.TEXTURE_2D_ARRAY if kind == "array" else gl.TEXTURE_CUBE_MAP
    tex = gl.createTexture()
    gl.bindTexture(target, tex)
    if kind == "array":
        gl.texImage3D(target, 0, getattr(gl, internal), w, h, n, 0, getattr(gl, fmt), gl.UNSIGNED_BYTE,
                      np.ascontiguousarray(layers))
    else:
        for face in range(6):
            gl.texImage2D(gl.TEXTURE_CUBE_MAP_POSITIVE_X + face, 0, getattr(gl, internal), w, h, 0, getattr(gl, fmt),
                          gl.UNSIGNED_BYTE, np.ascontiguousarray(layers[face]))
    gl.generateMipmap(target)
    gl.texParameteri(target, gl.TEXTURE_MIN_FILTER, gl.LINEAR_MIPMAP_LINEAR)
    gl.texParameteri(target, gl.TEXTURE_MAG_FILTER, gl.LINEAR)
    draw_quad(gl, softgl.program(gl, VS, FS_ARRAY if kind == "array" else FS_CUBE))
    out = np.asarray(gl.readPixels(0, 0, W, H, gl.RGBA, gl.FLOAT), np.float32)
    assert gl.getError() == gl.NO_ERROR
    return out


@pytest.mark.parametrize("name", list(FORMATS))
@pytest.mark.parametrize("kind", ["array", "cube"])
def test_narrow_arrays_and_cube_maps_sample_as_their_rgba8_expansion(name, kind):
    """2D arrays (layers in the gathers' indices) and cube maps (faces filtered per block), trilinear."""
    internal, fmt, channels = FORMATS[name]
    rng = np.random.default_rng(sum(map(ord, name + kind)))
    layers = rng.integers(0, 256, (4 if kind == "array" else 6, 16, 16, channels)).astype(np.uint8)
    simd = ["scalar", "sse2", "avx2", "avx512"][:_core.testing.simd_level() + 1]
    want = draw_layers(expand(name, layers), "RGBA8", "RGBA", kind, 1, "scalar", "best")
    assert np.ptp(want.reshape(-1, 4), axis=0).max() > 0.1
    for threads, level, path in [(1, lv, "best") for lv in simd] + [(2, simd[-1], "best"), (1, simd[-1], "general")]:
        got = draw_layers(layers, internal, fmt, kind, threads, level, path)
        np.testing.assert_array_equal(got.view(np.uint32), want.view(np.uint32),
                                      err_msg=f"{name} {kind} threads {threads} {level} {path}")
