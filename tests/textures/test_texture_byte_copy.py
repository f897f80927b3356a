"""The sampler reads 8-bit unorm 2D textures from a byte copy of their texels (Texture::rgba8),
refreshed when a draw binds the texture and the texture changed since. Every lookup must return
k / 255 exactly as the float storage holds it, and a changed texture must never sample its old
contents: after rendering into it through a framebuffer, copyTexSubImage2D, texSubImage2D, a blit
and generateMipmap, each draw is checked against a NumPy model of the new contents, on every
sampler path (general, fast scalar, AVX2 blocks, best SIMD: the context's tuning) and at 1 and 2
threads."""
import numpy as np
import pytest

import softgl
from softgl import _core
from helpers import VS3, draw_quad, float_target

GENERAL, SCALAR, BEST, AVX2 = "general", "scalar", "best", "avx2"
PATHS = [GENERAL, SCALAR, AVX2, BEST]
N = 32   # texture and target side: pixel (x, y) samples texel (x, y) of the level drawn

FS = """#version 300 es
precision highp float;
uniform highp sampler2D tex;
uniform float lod;
in vec3 uvw;
out vec4 color;
void main() { color = textureLod(tex, uvw.xy, lod); }
"""


def unorm8(k):
    """What an RGBA8 texel k holds and samples as (ES 3.0 §2.1.6.1: k / 255), in float32."""
    return np.asarray(k, np.float32) / np.float32(255)


class Scene:
    """A WebGL 2 context with an RGBA32F target and one RGBA8 NEAREST_MIPMAP_NEAREST texture on unit 0."""

    def __init__(self, threads):
        gl = self.gl = softgl.Context(8, 8, antialias=False, threads=threads)
        self.target_fb, _ = float_target(gl, N, N)
        self.prog = softgl.program(gl, VS3, FS)
        self.tex = gl.createTexture()
        gl.bindTexture(gl.TEXTURE_2D, self.tex)
        gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1)
        gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST_MIPMAP_NEAREST)
        gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST)

    def sample(self, level=0):
        """The texels of `level` as every sampler path returns them (asserted equal)."""
        gl = self.gl
        gl.bindFramebuffer(gl.FRAMEBUFFER, self.target_fb)
        gl.bindTexture(gl.TEXTURE_2D, self.tex)
        gl.viewport(0, 0, N, N)
        gl.useProgram(self.prog)
        gl.uniform1f(gl.getUniformLocation(self.prog, "lod"), float(level))
        side = N >> level
        images = []
        for path in PATHS:
            _core.testing.set_tuning(gl, sampler_path=path)
            gl.stats(reset=True)
            draw_quad(self.gl, self.prog)
            assert gl.getError() == gl.NO_ERROR
            assert (gl.stats()["texture_queries_fast"] > 0) == (path != GENERAL), path   # the path was taken
            images.append(gl.readPixels(0, 0, side, side, gl.RGBA, gl.FLOAT) if level == 0 else
                          gl.readPixels(0, 0, N, N, gl.RGBA, gl.FLOAT)[::1 << level, ::1 << level])
        _core.testing.set_tuning(gl, sampler_path=BEST)
        for path, img in zip(PATHS, images):
            np.testing.assert_array_equal(img.view(np.uint32), images[0].view(np.uint32), err_msg=f"path {path}")
        return images[0]

    def upload(self, data, level=0):
        gl = self.gl
        gl.bindTexture(gl.TEXTURE_2D, self.tex)
        gl.texImage2D(gl.TEXTURE_2D, level, gl.RGBA8, data.shape[1], data.shape[0], 0, gl.RGBA, gl.UNSIGNED_BYTE, data)


def random_texels(rng, h, w):
    return rng.integers(0, 256, (h, w, 4), dtype=np.uint8)


@pytest.mark.parametrize("threads", [1, 2])
def test_rgba8_copy_every_byte_value(threads):
    # All 256 byte values in every channel (texel i holds i + 67 c, mod 256, in channel c).
    s = Scene(threads)
    k = (np.arange(N * N)[:, None] + 67 * np.arange(4)[None, :]) % 256
    data = k.astype(np.uint8).reshape(N, N, 4)
    s.upload(data)
    s.gl.texParameteri(s.gl.TEXTURE_2D, s.gl.TEXTURE_MIN_FILTER, s.gl.NEAREST)
    np.testing.assert_array_equal(s.sample(), unorm8(data))


@pytest.mark.parametrize("threads", [1, 2])
def test_texture_changes_between_draws_are_sampled(threads):
    rng = np.random.default_rng(5)
    s = Scene(threads)
    gl = s.gl
    model = random_texels(rng, N, N)
    s.upload(model)
    gl.generateMipmap(gl.TEXTURE_2D)
    np.testing.assert_array_equal(s.sample(), unorm8(model))

    # texSubImage2D of a block.
    block = random_texels(rng, 5, 7)
    gl.bindTexture(gl.TEXTURE_2D, s.tex)
    gl.texSubImage2D(gl.TEXTURE_2D, 0, 3, 9, 7, 5, gl.RGBA, gl.UNSIGNED_BYTE, block)
    model[9:14, 3:10] = block
    np.testing.assert_array_equal(s.sample(), unorm8(model))

    # Rendering into level 0 through a framebuffer: a uniform colour over a scissored rectangle.
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, s.tex, 0)
    assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == gl.FRAMEBUFFER_COMPLETE
    solid = softgl.program(gl, "#version 300 es\nin vec2 pos;\nvoid main() { gl_Position = vec4(pos, 0.0, 1.0); }\n",
                           "#version 300 es\nprecision highp float;\nout vec4 c;\n"
                           "void main() { c = vec4(51.0, 102.0, 204.0, 17.0) / 255.0; }\n")
    gl.viewport(0, 0, N, N)
    gl.enable(gl.SCISSOR_TEST)
    gl.scissor(4, 20, 11, 6)
    draw_quad(gl, solid)
    gl.disable(gl.SCISSOR_TEST)
    assert gl.getError() == gl.NO_ERROR
    model[20:26, 4:15] = (51, 102, 204, 17)
    np.testing.assert_array_equal(s.sample(), unorm8(model))

    # Another RGBA8 texture as the read framebuffer: copyTexSubImage2D, then a blit, from it.
    other = random_texels(rng, N, N)
    src_tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, src_tex)
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, N, N, 0, gl.RGBA, gl.UNSIGNED_BYTE, other)
    src_fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.READ_FRAMEBUFFER, src_fb)
    gl.framebufferTexture2D(gl.READ_FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, src_tex, 0)
    gl.bindTexture(gl.TEXTURE_2D, s.tex)
    gl.copyTexSubImage2D(gl.TEXTURE_2D, 0, 16, 1, 2, 18, 9, 4)   # source (2, 18), 9 x 4, to (16, 1)
    assert gl.getError() == gl.NO_ERROR
    model[1:5, 16:25] = other[18:22, 2:11]
    np.testing.assert_array_equal(s.sample(), unorm8(model))

    gl.bindFramebuffer(gl.READ_FRAMEBUFFER, src_fb)
    gl.bindFramebuffer(gl.DRAW_FRAMEBUFFER, fb)
    gl.blitFramebuffer(0, 0, 6, 3, 25, 27, 31, 30, gl.COLOR_BUFFER_BIT, gl.NEAREST)
    assert gl.getError() == gl.NO_ERROR
    model[27:30, 25:31] = other[0:3, 0:6]
    np.testing.assert_array_equal(s.sample(), unorm8(model))

    # generateMipmap again: level 1 is the 2x2 box filter of the new level 0 (ES 3.0 §3.8.10.5),
    # first without and then after the regeneration.
    old_level1 = s.sample(1)
    gl.bindTexture(gl.TEXTURE_2D, s.tex)
    gl.generateMipmap(gl.TEXTURE_2D)
    box = model.astype(np.float64).reshape(N // 2, 2, N // 2, 2, 4).mean(axis=(1, 3)) / 255
    level1 = s.sample(1)
    np.testing.assert_allclose(level1, box, atol=0.5 / 255 + 1e-7)
    np.testing.assert_array_equal(level1, unorm8(np.round(level1 * 255)))
    assert not np.array_equal(level1, old_level1)
