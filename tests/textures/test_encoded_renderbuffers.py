"""Renderbuffers of sRGB and packed unorm formats (SRGB8_ALPHA8, RGB565, RGBA4, RGB5_A1,
RGB10_A2) keep their encoding at the format's size (Image::packed, surface/texture.h); textures
of the same formats keep float32 (the sampler reads floats). Drawing, blending, masked clears and
multisample resolves into either must give the same pixels; the packed unorm ones also hold what
ES 3.0 §2.1.6 (eq. 2.3: k = round(v (2^b - 1))) says, computed here in float64. The 16F formats
are covered by test_half_float_storage.py."""
import numpy as np
import pytest

import softgl
from helpers import draw_quad, float_source_texture as source
from softgl.programs import program

# name -> channel bits (ES 3.0 table 3.13)
FORMATS = {"SRGB8_ALPHA8": (8, 8, 8, 8), "RGB565": (5, 6, 5, 0), "RGBA4": (4, 4, 4, 4),
           "RGB5_A1": (5, 5, 5, 1), "RGB10_A2": (10, 10, 10, 2)}

VS = """#version 300 es
in vec2 pos; void main() { gl_Position = vec4(pos, 0.0, 1.0); }"""
FS = """#version 300 es
precision highp float; uniform highp sampler2D src; out vec4 o;
void main() { o = texelFetch(src, ivec2(gl_FragCoord.xy), 0); }"""
# A triangle over part of the canvas (edges cut pixels: partial multisample coverage).
VS_TRI = """#version 300 es
in vec2 pos; void main() { gl_Position = vec4(pos.x * 0.83 + pos.y * 0.21, pos.y * 0.77 - pos.x * 0.13, 0.0, 1.0); }"""


def target(gl, internal, w, h, kind, samples=0):
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    if kind == "texture":
        t = gl.createTexture()
        gl.bindTexture(gl.TEXTURE_2D, t)
        gl.texStorage2D(gl.TEXTURE_2D, 1, getattr(gl, internal), w, h)
        gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, t, 0)
    else:
        r = gl.createRenderbuffer()
        gl.bindRenderbuffer(gl.RENDERBUFFER, r)
        gl.renderbufferStorageMultisample(gl.RENDERBUFFER, samples, getattr(gl, internal), w, h)
        gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.RENDERBUFFER, r)
    assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == gl.FRAMEBUFFER_COMPLETE
    gl.viewport(0, 0, w, h)
    return fb


def scene(internal, kind, threads, samples=0):
    """Clear, a masked clear, a drawn quad of per-pixel values, a blended triangle; the pixels
    as readPixels(RGBA, UNSIGNED_BYTE) gives them (multisampled: after a blit to a texture)."""
    w, h = 29, 13
    gl = softgl.Context(8, 8, threads=threads, antialias=False, version=2)
    rng = np.random.default_rng(len(internal))
    fb = target(gl, internal, w, h, kind, samples)
    gl.clearColor(0.3, 0.62, 0.91, 0.4)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.colorMask(True, False, True, False)
    gl.clearColor(0.77, 0.1, 0.05, 0.9)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.colorMask(True, True, True, True)
    source(gl, rng.uniform(-0.1, 1.1, (h, w, 4)).astype(np.float32))
    prog = program(gl, VS, FS)
    gl.useProgram(prog)
    gl.uniform1i(gl.getUniformLocation(prog, "src"), 1)
    gl.scissor(3, 2, 20, 9)
    gl.enable(gl.SCISSOR_TEST)
    draw_quad(gl, prog)
    gl.disable(gl.SCISSOR_TEST)
    source(gl, rng.uniform(0, 1, (h, w, 4)).astype(np.float32))
    tri = program(gl, VS_TRI, FS)
    gl.useProgram(tri)
    gl.uniform1i(gl.getUniformLocation(tri, "src"), 1)
    gl.enable(gl.BLEND)
    gl.blendFuncSeparate(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA, gl.ONE, gl.ONE_MINUS_SRC_ALPHA)
    draw_quad(gl, tri)
    gl.disable(gl.BLEND)
    assert gl.getError() == gl.NO_ERROR
    if samples:
        resolved = target(gl, internal, w, h, "texture")
        gl.bindFramebuffer(gl.READ_FRAMEBUFFER, fb)
        gl.bindFramebuffer(gl.DRAW_FRAMEBUFFER, resolved)
        gl.blitFramebuffer(0, 0, w, h, 0, 0, w, h, gl.COLOR_BUFFER_BIT, gl.NEAREST)
        gl.bindFramebuffer(gl.FRAMEBUFFER, resolved)
        assert gl.getError() == gl.NO_ERROR
    out = np.empty((h, w, 4), np.uint8)
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, out)
    return out


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("internal", list(FORMATS))
def test_renderbuffer_pixels_are_the_textures(internal, threads):
    assert np.array_equal(scene(internal, "renderbuffer", threads), scene(internal, "texture", threads))


@pytest.mark.parametrize("internal", list(FORMATS))
def test_multisampled_renderbuffers_resolve_like_single_sampled_where_covered_alike(internal):
    """4 samples: where all samples of a pixel got the same values (the clears and the scissored
    quad: everything but the triangle's edge pixels) the resolve gives the single-sample pixel."""
    one = scene(internal, "renderbuffer", 1)
    four = scene(internal, "renderbuffer", 1, samples=4)
    differ = np.any(one != four, axis=-1)
    # Only pixels on the triangle's edges may differ: at most the perimeter's worth.
    assert differ.sum() <= 2 * (29 + 13), differ.sum()
    assert differ.sum() < differ.size // 4


@pytest.mark.parametrize("internal", ["RGB565", "RGBA4", "RGB5_A1", "RGB10_A2"])
def test_packed_renderbuffers_hold_the_rounded_unorm_values(internal):
    """ES 3.0 §2.1.6: k = round(clamp(v) (2^b - 1)); readPixels returns k / (2^b - 1) as a byte
    (round(255 k / (2^b - 1))); an absent alpha reads 255."""
    w, h = 31, 9
    gl = softgl.Context(8, 8, antialias=False, version=2)
    v = np.random.default_rng(4).uniform(-0.2, 1.2, (h, w, 4)).astype(np.float32)
    target(gl, internal, w, h, "renderbuffer")
    source(gl, v)
    prog = program(gl, VS, FS)
    gl.useProgram(prog)
    gl.uniform1i(gl.getUniformLocation(prog, "src"), 1)
    draw_quad(gl, prog)
    out = np.empty((h, w, 4), np.uint8)
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, out)
    want = np.full((h, w, 4), 255, np.float64)
    for c, bits in enumerate(FORMATS[internal]):
        if bits:
            top = 2.0 ** bits - 1
            k = np.floor(np.clip(v[..., c].astype(np.float64), 0, 1) * top + 0.5)
            want[..., c] = np.floor(k / top * 255 + 0.5)
    assert np.array_equal(out, want.astype(np.uint8))


@pytest.mark.parametrize("filter_", ["NEAREST", "LINEAR"])
@pytest.mark.parametrize("internal", list(FORMATS) + ["R16F", "RG16F", "RGBA16F"])
def test_blits_into_renderbuffers_store_what_they_store_into_textures(internal, filter_):
    """blitFramebuffer (1:1 and scaled) from a texture of the format into a renderbuffer and into
    a texture of the same format: the same pixels (the blit writes through Image::store_color)."""
    w, h = 29, 13
    results = []
    for kind in ("renderbuffer", "texture"):
        gl = softgl.Context(8, 8, antialias=False, version=2)
        assert gl.getExtension("EXT_color_buffer_float") is not None
        src = target(gl, internal, w, h, "texture")
        source(gl, np.random.default_rng(9).uniform(-0.1, 1.1, (h, w, 4)).astype(np.float32))
        prog = program(gl, VS, FS)
        gl.useProgram(prog)
        gl.uniform1i(gl.getUniformLocation(prog, "src"), 1)
        draw_quad(gl, prog)
        dst = target(gl, internal, w, h, kind)
        gl.bindFramebuffer(gl.READ_FRAMEBUFFER, src)
        gl.bindFramebuffer(gl.DRAW_FRAMEBUFFER, dst)
        gl.blitFramebuffer(0, 0, w, h, 0, 0, w, h, gl.COLOR_BUFFER_BIT, gl.NEAREST)
        gl.blitFramebuffer(2, 1, 17, 9, 3, 2, 28, 12, gl.COLOR_BUFFER_BIT, getattr(gl, filter_))
        assert gl.getError() == gl.NO_ERROR
        gl.bindFramebuffer(gl.FRAMEBUFFER, dst)
        floats = internal.endswith("16F")
        out = np.empty((h, w, 4), np.float32 if floats else np.uint8)
        gl.readPixels(0, 0, w, h, gl.RGBA, gl.FLOAT if floats else gl.UNSIGNED_BYTE, out)
        results.append(out)
    assert results[0].tobytes() == results[1].tobytes()
