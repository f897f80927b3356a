"""Float-sampled colour formats of one to three channels (R32F, RG32F, RGB32F, the 16F ones,
R11F_G11F_B10F, RGB9_E5, RGB565, SRGB8, ...) keep one float per channel of their base format
(Image::color_channels, surface/texture.h), and the sampler reads the absent channels as their
defaults (SampledLevel::color_fill: 0, alpha 1). Sampling one must give the same floats, bit for
bit, as the same values uploaded RGBA32F with the channels the format implies (ES 3.0 table 3.24:
R -> (r, 0, 0, 1), RG -> (r, g, 0, 1), RGB -> (r, g, b, 1)), for NEAREST, LINEAR and trilinear
filters, REPEAT and CLAMP_TO_EDGE, 2D arrays and cube maps, every SIMD level, 1 and 2 threads
and the general (lane by lane) path. The draw writes the sampled floats to an RGBA32F target, so
every bit of the filter is compared; float colour targets of fewer channels are drawn, blended,
cleared and read back too."""
import numpy as np
import pytest

import softgl
from helpers import RECEDING_FS_ARRAY as FS_ARRAY, RECEDING_FS_CUBE as FS_CUBE, RECEDING_VS as VS
from helpers import STORAGE_FILTERS as FILTERS, float_sampling_context, read_float_quad
from helpers import rgba_expansion as expand, sample_float_levels, sampling_configs as configs


# internal format -> (client format, channels, values): values(rng, shape) are floats the format
# holds exactly (so the RGBA32F upload of the same floats is the same texture).


def _halves(rng, shape):      # float16 values, signed, some beyond 1
    return rng.uniform(-4, 4, shape).astype(np.float16).astype(np.float32)


def _dyadic(rng, shape):      # k / 32 for k < 64: exact in 6 mantissa bits (11F, 10F) and RGB9_E5
    return (rng.integers(0, 64, shape) / 32.0).astype(np.float32)


FORMATS = {
    "R32F": ("RED", 1, lambda rng, s: rng.uniform(-3, 3, s).astype(np.float32)),
    "RG32F": ("RG", 2, lambda rng, s: rng.uniform(-3, 3, s).astype(np.float32)),
    "RGB32F": ("RGB", 3, lambda rng, s: rng.uniform(-3, 3, s).astype(np.float32)),
    "R16F": ("RED", 1, _halves),
    "RG16F": ("RG", 2, _halves),
    "RGB16F": ("RGB", 3, _halves),
    "R11F_G11F_B10F": ("RGB", 3, _dyadic),
    "RGB9_E5": ("RGB", 3, _dyadic),
}
W, H = 64, 48


def levels_of(name, size):
    rng = np.random.default_rng(sum(map(ord, name)) + size[0])
    w, h = size
    out = []
    while True:
        out.append(FORMATS[name][2](rng, (h, w, FORMATS[name][1])))
        if w == 1 and h == 1:
            return out
        w, h = max(w // 2, 1), max(h // 2, 1)


@pytest.mark.parametrize("name", list(FORMATS))
@pytest.mark.parametrize("filters", FILTERS, ids=["/".join(f) for f in FILTERS])
@pytest.mark.parametrize("wrap,size", [("REPEAT", (32, 16)), ("CLAMP_TO_EDGE", (13, 7))])
def test_float_formats_sample_as_their_rgba32f_expansion(name, filters, wrap, size):
    fmt = FORMATS[name][0]
    levels = levels_of(name, size)
    want = sample_float_levels([expand(v) for v in levels], "RGBA32F", "RGBA", filters, wrap, 1, "scalar", "best", W, H)
    assert np.ptp(want.reshape(-1, 4)[:, 0]) > 0.3   # not a constant image
    for threads, level, path in configs():
        got = sample_float_levels(levels, name, fmt, filters, wrap, threads, level, path, W, H)
        np.testing.assert_array_equal(got.view(np.uint32), want.view(np.uint32),
                                      err_msg=f"{name} {filters} {wrap} {size} threads {threads} {level} {path}")


def draw_layers(layers, internal, fmt, kind, threads, simd, path):
    """layers: (n, h, w, channels) floats; kind: "array" (n layers) or "cube" (6 faces)."""
    gl = float_sampling_context(W, H, threads, simd, path)
    n, h, w = layers.shape[:3]
    target = gl.TEXTURE_2D_ARRAY if kind == "array" else gl.TEXTURE_CUBE_MAP
    tex = gl.createTexture()
    gl.bindTexture(target, tex)
    if kind == "array":
        gl.texImage3D(target, 0, getattr(gl, internal), w, h, n, 0, getattr(gl, fmt), gl.FLOAT, np.ascontiguousarray(layers))
    else:
        for face in range(6):
            gl.texImage2D(gl.TEXTURE_CUBE_MAP_POSITIVE_X + face, 0, getattr(gl, internal), w, h, 0, getattr(gl, fmt),
                          gl.FLOAT, np.ascontiguousarray(layers[face]))
    gl.texParameteri(target, gl.TEXTURE_MIN_FILTER, gl.LINEAR)
    gl.texParameteri(target, gl.TEXTURE_MAG_FILTER, gl.LINEAR)
    return read_float_quad(gl, VS, FS_ARRAY if kind == "array" else FS_CUBE, W, H)


@pytest.mark.parametrize("name", ["R32F", "RG32F", "RGB16F"])
@pytest.mark.parametrize("kind", ["array", "cube"])
def test_float_arrays_and_cube_maps_sample_as_their_rgba32f_expansion(name, kind):
    fmt, channels, values = FORMATS[name]
    layers = values(np.random.default_rng(sum(map(ord, name + kind))), (4 if kind == "array" else 6, 16, 16, channels))
    want = draw_layers(expand(layers), "RGBA32F", "RGBA", kind, 1, "scalar", "best")
    assert np.ptp(want.reshape(-1, 4)[:, 0]) > 0.1
    for threads, level, path in configs():
        got = draw_layers(layers, name, fmt, kind, threads, level, path)
        np.testing.assert_array_equal(got.view(np.uint32), want.view(np.uint32),
                                      err_msg=f"{name} {kind} threads {threads} {level} {path}")


@pytest.mark.parametrize("name,channels", [("R32F", 1), ("RG32F", 2), ("R16F", 1), ("RG16F", 2),
                                           ("R11F_G11F_B10F", 3)])


def test_float_targets_of_fewer_channels_draw_blend_clear_and_read(name, channels):
    """A colour attachment of 1-3 float channels: clear (masked), a blended draw, readPixels and a
    blit to RGBA32F give the stored channels and the absent ones' defaults (0, alpha 1)."""
    gl = softgl.Context(8, 8, antialias=False, version=2)
    assert gl.getExtension("EXT_color_buffer_float") is not None
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    gl.texStorage2D(gl.TEXTURE_2D, 1, getattr(gl, name), 8, 8)
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0)
    assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == gl.FRAMEBUFFER_COMPLETE
    gl.clearColor(0.5, 0.25, 0.75, 0.125)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.colorMask(False, True, True, True)
    gl.clearColor(9.0, 2.0, 1.5, 0.0)
    gl.clear(gl.COLOR_BUFFER_BIT)   # red kept
    gl.colorMask(True, True, True, True)
    # A blended draw over the left half: ONE, ONE adds the source (0.25, 0.5, 0.25, 7).
    gl.useProgram(softgl.program(gl, "#version 300 es\nin vec2 p; void main() { gl_Position = vec4(p, 0, 1); }",
                                 "#version 300 es\nprecision highp float; out vec4 o;"
                                 "void main() { o = vec4(0.25, 0.5, 0.25, 7.0); }"))
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.bufferData(gl.ARRAY_BUFFER, np.array([-1, -1, 0, -1, -1, 1, -1, 1, 0, -1, 0, 1], np.float32), gl.STATIC_DRAW)
    gl.enableVertexAttribArray(0)
    gl.vertexAttribPointer(0, 2, gl.FLOAT, False, 0, 0)
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.ONE, gl.ONE)
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    got = np.asarray(gl.readPixels(0, 0, 8, 8, gl.RGBA, gl.FLOAT), np.float32)
    assert gl.getError() == gl.NO_ERROR
    cleared = np.array([0.5, 2.0, 1.5, 1.0], np.float32)
    cleared[channels:3] = 0.0
    drawn = cleared + np.array([0.25, 0.5, 0.25, 0.0], np.float32) * (np.arange(4) < channels)
    want = np.empty((8, 8, 4), np.float32)
    want[:, :4], want[:, 4:] = drawn, cleared
    np.testing.assert_array_equal(got, want)
    # A blit to an RGBA32F renderbuffer reads the same RGBA.
    rb = gl.createRenderbuffer()
    gl.bindRenderbuffer(gl.RENDERBUFFER, rb)
    gl.renderbufferStorage(gl.RENDERBUFFER, gl.RGBA32F, 8, 8)
    dst = gl.createFramebuffer()
    gl.bindFramebuffer(gl.DRAW_FRAMEBUFFER, dst)
    gl.framebufferRenderbuffer(gl.DRAW_FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.RENDERBUFFER, rb)
    gl.bindFramebuffer(gl.READ_FRAMEBUFFER, fb)
    gl.blitFramebuffer(0, 0, 8, 8, 0, 0, 8, 8, gl.COLOR_BUFFER_BIT, gl.NEAREST)
    gl.bindFramebuffer(gl.READ_FRAMEBUFFER, dst)
    np.testing.assert_array_equal(np.asarray(gl.readPixels(0, 0, 8, 8, gl.RGBA, gl.FLOAT), np.float32), want)
    assert gl.getError() == gl.NO_ERROR
