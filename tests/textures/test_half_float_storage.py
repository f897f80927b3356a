"""16-bit float formats (R16F, RG16F, RGB16F, RGBA16F): a texel or sample holds the binary16 value
of what was uploaded or rendered, rounded to nearest with ties to even, beyond the largest half
(65504) to +-Inf, NaN as NaN. Textures and renderbuffers keep it as binary16 (Image::packed,
surface/texture.h; the sampler's texel loads decode it); both must hold the same values. The expected values come from NumPy's float32 -> float16 conversion (IEEE 754
round to nearest even) or are exact by construction, never from softgl."""
import numpy as np
import pytest

import softgl
from helpers import draw_quad, float_source_texture as source_texture
from softgl import _core
from softgl.programs import program

FORMATS = {"R16F": ("RED", 1), "RG16F": ("RG", 2), "RGB16F": ("RGB", 3), "RGBA16F": ("RGBA", 4)}
# Colour-renderable with EXT_color_buffer_float (WebGL 2; RGB16F is not).
RENDERABLE = ["R16F", "RG16F", "RGBA16F"]

# Values that exercise every rounding case of float32 -> binary16.
SPECIAL = np.array([
    0.0, -0.0, 1.0, -2.5, 65504.0, -65504.0,
    65519.99, 65520.0, 1e5, -1e5, np.inf, -np.inf,   # 65520 and beyond round to Inf
    1.0 + 2.0 ** -11, 1.0 + 3 * 2.0 ** -11,          # ties: to even (down, then up)
    1.0 + 2.0 ** -11 + 2.0 ** -20,                   # just above a tie: up
    2.0 ** -14, 2.0 ** -15, 2.0 ** -24, 2.0 ** -25, 2.0 ** -25 * 1.5, 3 * 2.0 ** -26,   # subnormals
    2.0 ** -26, 0.1, 1 / 3, 3.14159265, 1000.1, -0.0001,
], np.float32)


def values(n, rng):
    v = rng.standard_normal(n).astype(np.float32) * np.float32(10.0) ** rng.integers(-8, 6, n).astype(np.float32)
    v[: len(SPECIAL)] = SPECIAL
    return v


def context(threads=1):
    gl = softgl.Context(8, 8, threads=threads, antialias=False, version=2)
    assert gl.getExtension("EXT_color_buffer_float") is not None
    return gl


def upload(gl, internal, w, h, data, client=None):
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1)
    gl.texImage2D(gl.TEXTURE_2D, 0, getattr(gl, internal), w, h, 0, getattr(gl, FORMATS[internal][0]),
                  gl.FLOAT if client is None else client, data)
    for p in (gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER):
        gl.texParameteri(gl.TEXTURE_2D, p, gl.NEAREST)
    return tex


def fetched(gl, tex, w, h):
    """The texels of tex as texelFetch returns them, drawn into an RGBA32F target (RGB16F is
    not colour-renderable in WebGL 2, so it cannot be read directly)."""
    target = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, target)
    gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA32F, w, h)
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, target, 0)
    gl.viewport(0, 0, w, h)
    gl.activeTexture(gl.TEXTURE1)
    gl.bindTexture(gl.TEXTURE_2D, tex)
    gl.activeTexture(gl.TEXTURE0)
    prog = program(gl, VS, FS_OUT)
    gl.useProgram(prog)
    gl.uniform1i(gl.getUniformLocation(prog, "src"), 1)
    draw_quad(gl, prog)
    assert gl.getError() == gl.NO_ERROR
    return read_rgba(gl, w, h)


def attach(gl, internal, w, h, data=None, kind="texture"):
    """A bound framebuffer whose colour attachment is a texture (with data, uploaded as FLOAT) or
    a renderbuffer of `internal`."""
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    if kind == "texture":
        tex = upload(gl, internal, w, h, data)
        gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0)
    else:
        rb = gl.createRenderbuffer()
        gl.bindRenderbuffer(gl.RENDERBUFFER, rb)
        gl.renderbufferStorage(gl.RENDERBUFFER, getattr(gl, internal), w, h)
        gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.RENDERBUFFER, rb)
    assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == gl.FRAMEBUFFER_COMPLETE
    gl.viewport(0, 0, w, h)
    return fb


def read_rgba(gl, w, h):
    out = np.empty((h, w, 4), np.float32)
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.FLOAT, out)
    return out


def expected_rgba(v, channels):
    """binary16 of v (..., channels) as float32, absent channels 0 and alpha 1 (ES 3.0 table 3.24)."""
    with np.errstate(over="ignore"):
        h = v.astype(np.float16).astype(np.float32)
    out = np.zeros(v.shape[:-1] + (4,), np.float32)
    out[..., 3] = 1.0
    out[..., :channels] = h
    return out


def same(a, b):
    """Equal as values, NaN where NaN, and the sign of zero kept."""
    return np.array_equal(np.isnan(a), np.isnan(b)) and np.array_equal(np.nan_to_num(a, nan=7.0), np.nan_to_num(b, nan=7.0)) \
        and np.array_equal(np.signbit(a[~np.isnan(a)]), np.signbit(b[~np.isnan(b)]))


@pytest.mark.parametrize("internal", list(FORMATS))
def test_float_uploads_round_to_nearest_even_binary16(internal):
    gl = context()
    channels = FORMATS[internal][1]
    w, h = 31, 7
    v = values(w * h * channels, np.random.default_rng(channels)).reshape(h, w, channels)
    v[0, 0, 0] = np.nan
    tex = upload(gl, internal, w, h, v)
    assert gl.getError() == gl.NO_ERROR
    assert same(fetched(gl, tex, w, h), expected_rgba(v, channels))


@pytest.mark.parametrize("internal", list(FORMATS))
def test_half_float_uploads_keep_their_bits(internal):
    gl = context()
    channels = FORMATS[internal][1]
    w, h = 16, 4
    bits = np.random.default_rng(5).integers(0, 1 << 16, (h, w, channels), dtype=np.uint16)
    bits[np.isnan(bits.view(np.float16))] = 0x7E00   # NaN: any NaN (softgl keeps one quiet NaN)
    tex = upload(gl, internal, w, h, bits, gl.HALF_FLOAT)
    assert same(fetched(gl, tex, w, h), expected_rgba(bits.view(np.float16).astype(np.float32), channels))


VS = """#version 300 es
in vec2 pos; void main() { gl_Position = vec4(pos, 0.0, 1.0); }"""
FS_OUT = """#version 300 es
precision highp float; uniform highp sampler2D src; out vec4 o;
void main() { o = texelFetch(src, ivec2(gl_FragCoord.xy), 0); }"""


@pytest.mark.parametrize("kind", ["texture", "renderbuffer"])
@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("internal", RENDERABLE)
def test_rendered_values_round_to_binary16(internal, threads, kind):
    """EXT_color_buffer_float: a 16F attachment holds the fragment's float32 output rounded to
    binary16 (the same as a FLOAT upload)."""
    gl = context(threads)
    channels = FORMATS[internal][1]
    w, h = 33, 9
    v = values(w * h * 4, np.random.default_rng(11 + channels)).reshape(h, w, 4)
    v[1, 2, 0] = np.nan
    source_texture(gl, v)
    attach(gl, internal, w, h, kind=kind)
    prog = program(gl, VS, FS_OUT)
    gl.useProgram(prog)
    gl.uniform1i(gl.getUniformLocation(prog, "src"), 1)
    draw_quad(gl, prog)
    assert gl.getError() == gl.NO_ERROR
    assert same(read_rgba(gl, w, h), expected_rgba(v[..., :channels], channels))


@pytest.mark.parametrize("kind", ["texture", "renderbuffer"])
@pytest.mark.parametrize("internal", RENDERABLE)
def test_blending_into_16f_rounds_the_float_sum(internal, kind):
    """ES 3.0 §4.1.7: float buffers blend unclamped; with ONE, ONE the float32 sum of two values
    that are multiples of 2^-12 below 8 is exact, so the stored value is that sum rounded to binary16."""
    gl = context()
    channels = FORMATS[internal][1]
    w, h = 24, 6
    rng = np.random.default_rng(3)
    dst = (rng.integers(-8 * 4096, 8 * 4096, (h, w, 4)) / 4096.0).astype(np.float32)
    src = (rng.integers(-8 * 4096, 8 * 4096, (h, w, 4)) / 4096.0).astype(np.float32)
    attach(gl, internal, w, h, np.ascontiguousarray(dst[..., :channels]), kind)
    if kind == "renderbuffer":   # the destination values drawn first, unblended
        source_texture(gl, np.ascontiguousarray(dst))
        prog = program(gl, VS, FS_OUT)
        gl.useProgram(prog)
        gl.uniform1i(gl.getUniformLocation(prog, "src"), 1)
        draw_quad(gl, prog)
    source_texture(gl, src)
    prog = program(gl, VS, FS_OUT)
    gl.useProgram(prog)
    gl.uniform1i(gl.getUniformLocation(prog, "src"), 1)
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.ONE, gl.ONE)
    draw_quad(gl, prog)
    held = dst[..., :channels].astype(np.float16).astype(np.float64)
    want = expected_rgba((held + src[..., :channels].astype(np.float64)).astype(np.float32), channels)
    if channels < 4:   # the absent alpha reads 1 and is not stored
        want[..., 3] = 1.0
    assert same(read_rgba(gl, w, h), want)


@pytest.mark.parametrize("kind", ["texture", "renderbuffer"])
@pytest.mark.parametrize("internal", RENDERABLE)
def test_masked_clear_of_16f_keeps_the_masked_channels(internal, kind):
    gl = context()
    channels = FORMATS[internal][1]
    w, h = 9, 5
    v = values(w * h * 4, np.random.default_rng(2)).reshape(h, w, 4)
    attach(gl, internal, w, h, np.ascontiguousarray(v[..., :channels]), kind)
    if kind == "renderbuffer":   # the first values drawn
        source_texture(gl, v)
        prog = program(gl, VS, FS_OUT)
        gl.useProgram(prog)
        gl.uniform1i(gl.getUniformLocation(prog, "src"), 1)
        draw_quad(gl, prog)
    v = v[..., :channels]
    gl.colorMask(False, True, True, False)
    gl.clearColor(1e6, 1 / 3, -70000.0, 0.25)
    gl.clear(gl.COLOR_BUFFER_BIT)
    want = expected_rgba(v, channels)
    cleared = expected_rgba(np.array([[[1e6, 1 / 3, -70000.0, 0.25][:channels]]], np.float32), channels)[0, 0]
    for c in (1, 2):
        if c < channels:
            want[..., c] = cleared[c]
    assert same(read_rgba(gl, w, h), want)


def test_16f_renderbuffers_and_textures_take_two_bytes_a_channel():
    """The ledger's charge: a 16F renderbuffer 2 bytes a channel a sample (ES 3.0 table 3.13: 16
    bits; before: 4), a 16F texture 2 a texel's channel plus 6 bytes below 4 channels (a 4-half
    load at the last texel stays inside; before: float32, 4 a channel plus 12)."""
    gl = context()
    for internal, (_, channels) in FORMATS.items():
        before = softgl._core.memory_in_use()
        t = gl.createTexture()
        gl.bindTexture(gl.TEXTURE_2D, t)
        gl.texStorage2D(gl.TEXTURE_2D, 1, getattr(gl, internal), 40, 24)
        assert softgl._core.memory_in_use() - before == 40 * 24 * 2 * channels + (6 if channels < 4 else 0), internal
        gl.deleteTexture(t)
        if internal not in RENDERABLE:
            continue
        before = softgl._core.memory_in_use()
        r = gl.createRenderbuffer()
        gl.bindRenderbuffer(gl.RENDERBUFFER, r)
        gl.renderbufferStorageMultisample(gl.RENDERBUFFER, 4, getattr(gl, internal), 40, 24)
        assert softgl._core.memory_in_use() - before == 40 * 24 * 4 * 2 * channels, internal
        gl.deleteRenderbuffer(r)
