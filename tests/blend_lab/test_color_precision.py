"""Colour precision of the drawing buffer (issue 6): softgl's ``color_format`` option.

'rgba8' is WebGL's drawing buffer; 'rgba16f' and 'rgba32f' behave like RGBA16F / RGBA32F colour
attachments: blending without clamping (ES 3.0 §4.1.7), IEEE binary16 round-to-nearest-even for
16F, readPixels(RGBA, FLOAT) (ES 3.0 §4.3.2), float MSAA resolve, unclamped clears, and a canvas
shown like a browser shows one (clamp, round to 8 bits, composite). References are float64
formulas in NumPy and numpy.float16.
"""
import numpy as np
import pytest

import softgl
from softgl import display
from softgl.display import canvas_image, composite

FORMATS = ["rgba8", "rgba16f", "rgba32f"]

VS = """#version 300 es
in vec2 aPos; in vec4 aColor; out vec4 vColor;
void main() { gl_Position = vec4(aPos, 0.0, 1.0); gl_PointSize = 1.0; vColor = aColor; }"""
FS = """#version 300 es
precision highp float; in vec4 vColor; out vec4 o;
void main() { o = vColor; }"""


def make(fmt, size=8, **kw):
    kw.setdefault("antialias", False)
    gl = softgl.Context(size, size, color_format=fmt, preserveDrawingBuffer=True, strict=True, **kw)
    prog = softgl.program(gl, VS, FS)
    gl.useProgram(prog)
    gl._prog = prog
    return gl


def draw_points(gl, colors):
    """One 1-pixel point per pixel (row-major from the bottom), repeated for colors' leading
    axis: colors has shape (layers, h*w, 4); layer k is drawn over layer k-1 (primitive order)."""
    w, h = gl.drawingBufferWidth, gl.drawingBufferHeight
    colors = np.asarray(colors, np.float32).reshape(-1, h * w, 4)
    ys, xs = np.mgrid[0:h, 0:w]
    pos = np.stack([(xs.ravel() + 0.5) / w * 2 - 1, (ys.ravel() + 0.5) / h * 2 - 1], 1).astype(np.float32)
    pos = np.tile(pos, (colors.shape[0], 1))
    for name, data, n in (("aPos", pos, 2), ("aColor", colors.reshape(-1, 4), 4)):
        buf = gl.createBuffer()
        gl.bindBuffer(gl.ARRAY_BUFFER, buf)
        gl.bufferData(gl.ARRAY_BUFFER, np.ascontiguousarray(data), gl.STATIC_DRAW)
        loc = gl.getAttribLocation(gl._prog, name)
        gl.enableVertexAttribArray(loc)
        gl.vertexAttribPointer(loc, n, gl.FLOAT, False, 0, 0)
    gl.drawArrays(gl.POINTS, 0, len(pos))


def read(gl):
    fmt = gl.getContextAttributes().get("color_format", "rgba8")
    w, h = gl.drawingBufferWidth, gl.drawingBufferHeight
    if fmt == "rgba8":
        return gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE).astype(np.float64) / 255.0
    return gl.readPixels(0, 0, w, h, gl.RGBA, gl.FLOAT).astype(np.float64)


# ---------------------------------------------------------------- attributes and parameters

@pytest.mark.parametrize("fmt,bits,read_type", [("rgba8", 8, "UNSIGNED_BYTE"), ("rgba16f", 16, "HALF_FLOAT"),
                                                ("rgba32f", 32, "FLOAT")])
def test_parameters_report_the_format(fmt, bits, read_type):
    gl = softgl.Context(4, 4, color_format=fmt)
    for p in (gl.RED_BITS, gl.GREEN_BITS, gl.BLUE_BITS, gl.ALPHA_BITS):
        assert gl.getParameter(p) == bits
    assert gl.getParameter(gl.IMPLEMENTATION_COLOR_READ_FORMAT) == gl.RGBA
    assert gl.getParameter(gl.IMPLEMENTATION_COLOR_READ_TYPE) == getattr(gl, read_type)
    size = gl.getFramebufferAttachmentParameter(gl.FRAMEBUFFER, gl.BACK, gl.FRAMEBUFFER_ATTACHMENT_RED_SIZE)
    assert size == bits
    kind = gl.getFramebufferAttachmentParameter(gl.FRAMEBUFFER, gl.BACK, gl.FRAMEBUFFER_ATTACHMENT_COMPONENT_TYPE)
    assert kind == (gl.UNSIGNED_NORMALIZED if fmt == "rgba8" else gl.FLOAT)
    attrs = gl.getContextAttributes()
    # The WebGL dictionary is untouched for rgba8; float formats are reported.
    assert attrs.get("color_format") == (None if fmt == "rgba8" else fmt)
    assert gl.getParameter(gl.ALPHA_BITS) == bits
    assert softgl.Context(4, 4, color_format=fmt, alpha=False).getParameter(gl.ALPHA_BITS) == 0


def test_webgl1_float_buffer_reads_float():
    gl = softgl.Context(2, 2, version=1, color_format="rgba16f", strict=True)
    assert gl.getParameter(gl.IMPLEMENTATION_COLOR_READ_TYPE) == gl.FLOAT
    gl.clearColor(0.1, 2.0, -3.0, 1.0)
    gl.clear(gl.COLOR_BUFFER_BIT)
    px = gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.FLOAT)
    np.testing.assert_array_equal(px[0, 0], np.float16([0.1, 2.0, -3.0, 1.0]).astype(np.float32))


def test_bad_color_format():
    with pytest.raises(ValueError, match="color_format"):
        softgl.Context(4, 4, color_format="rgb565")
    with pytest.raises(TypeError):
        softgl.Context(4, 4, color_format=16)


# ---------------------------------------------------------------- clear, quantization

def special_values(rng, n):
    v = rng.standard_normal(n).astype(np.float32) * np.float32(4.0)
    halves = np.arange(0, 0x7BFF, 97, dtype=np.uint16).view(np.float16).astype(np.float32)
    nexts = (np.arange(1, 0x7BFF, 97, dtype=np.uint16) + 1).view(np.float16).astype(np.float32)
    ties = ((halves.astype(np.float64) + nexts.astype(np.float64)) / 2).astype(np.float32)   # exact ties
    extra = np.float32([0, -0.0, 1e-8, 6e-8, 3e-8, 2.98e-8, 65504, 65519.99, 65520, 1e6, -1e6,
                        6.1e-5, 6.09e-5, 1 / 3, 2 / 3, 0.1, 0.2, 0.3])
    return np.concatenate([v, ties, -ties, extra]).astype(np.float32)


def test_half_float_rounding_matches_numpy_float16():
    rng = np.random.default_rng(1)
    values = special_values(rng, 2000)
    n = int(np.ceil(np.sqrt(len(values) / 4)))
    padded = np.zeros(n * n * 4, np.float32)
    padded[:len(values)] = values
    gl = make("rgba16f", size=n)
    draw_points(gl, padded.reshape(1, n * n, 4))
    got = gl.readPixels(0, 0, n, n, gl.RGBA, gl.FLOAT).reshape(-1)[:len(values)]
    with np.errstate(over="ignore"):   # overflow to inf is the IEEE answer we want
        want16 = values.astype(np.float16)
    want = want16.astype(np.float32)   # IEEE round to nearest even, overflow -> inf
    np.testing.assert_array_equal(got, want)
    # The implementation-chosen pair gives the same values as binary16 bit patterns.
    bits = gl.readPixels(0, 0, n, n, gl.RGBA, gl.HALF_FLOAT)
    assert bits.dtype == np.uint16
    np.testing.assert_array_equal(bits.reshape(-1)[:len(values)], want16.view(np.uint16))


@pytest.mark.parametrize("fmt", ["rgba16f", "rgba32f"])
def test_clear_is_unclamped_and_rounded_to_the_format(fmt):
    gl = softgl.Context(3, 2, color_format=fmt, strict=True)
    color = np.float32([1.7, -0.25, 1e-3 + 1e-7, 12345.678])
    gl.clearColor(*color)
    gl.clear(gl.COLOR_BUFFER_BIT)
    px = gl.readPixels(0, 0, 3, 2, gl.RGBA, gl.FLOAT)
    want = color.astype(np.float16).astype(np.float32) if fmt == "rgba16f" else color
    assert (px == want).all()
    # Colour mask and scissor apply; clearBufferfv clears with float values too.
    gl.colorMask(True, False, True, False)
    gl.enable(gl.SCISSOR_TEST)
    gl.scissor(0, 0, 1, 1)
    gl.clearBufferfv(gl.COLOR, 0, [-5.0, -5.0, 5.0, -5.0])
    px = gl.readPixels(0, 0, 3, 2, gl.RGBA, gl.FLOAT)
    assert list(px[0, 0]) == [-5.0, want[1], 5.0, want[3]]
    assert (px[1, 2] == want).all()


def test_no_alpha_reads_alpha_one():
    gl = softgl.Context(2, 2, color_format="rgba32f", alpha=False)
    gl.clearColor(0.5, 0.5, 0.5, 0.25)
    gl.clear(gl.COLOR_BUFFER_BIT)
    assert (gl.readPixels(0, 0, 2, 2, gl.RGBA, gl.FLOAT)[..., 3] == 1).all()


# ---------------------------------------------------------------- blending against float64

BLEND_CASES = [
    ("SRC_ALPHA", "ONE_MINUS_SRC_ALPHA", "FUNC_ADD"),
    ("ONE", "ONE", "FUNC_ADD"),
    ("DST_COLOR", "ZERO", "FUNC_ADD"),
    ("ONE", "ONE", "FUNC_SUBTRACT"),
    ("ONE", "ONE", "FUNC_REVERSE_SUBTRACT"),
    ("ONE_MINUS_DST_COLOR", "SRC_COLOR", "FUNC_ADD"),
    ("SRC_ALPHA_SATURATE", "ONE", "FUNC_ADD"),
    ("ONE", "ONE", "MIN"),
    ("ONE", "ONE", "MAX"),
]


def factor64(name, s, d, k):
    one = np.ones_like(s)
    a_s, a_d, a_k = s[:, 3:4] * one, d[:, 3:4] * one, k[3] * one
    table = {"ZERO": 0 * one, "ONE": one, "SRC_COLOR": s, "ONE_MINUS_SRC_COLOR": 1 - s, "DST_COLOR": d,
             "ONE_MINUS_DST_COLOR": 1 - d, "SRC_ALPHA": a_s, "ONE_MINUS_SRC_ALPHA": 1 - a_s, "DST_ALPHA": a_d,
             "ONE_MINUS_DST_ALPHA": 1 - a_d, "CONSTANT_COLOR": k * one, "CONSTANT_ALPHA": a_k}
    if name == "SRC_ALPHA_SATURATE":
        f = np.minimum(a_s, 1 - a_d)
        f[:, 3] = 1
        return f
    return table[name]


def blend64(s, d, sf, df, eq, k=np.zeros(4)):
    """ES 3.0 §4.1.7 for a float buffer: no clamping anywhere, in float64."""
    fs, fd = factor64(sf, s, d, k), factor64(df, s, d, k)
    return {"FUNC_ADD": s * fs + d * fd, "FUNC_SUBTRACT": s * fs - d * fd,
            "FUNC_REVERSE_SUBTRACT": d * fd - s * fs, "MIN": np.minimum(s, d), "MAX": np.maximum(s, d)}[eq]


@pytest.mark.parametrize("sf,df,eq", BLEND_CASES)
def test_rgba32f_blend_equals_float64(sf, df, eq):
    rng = np.random.default_rng(7)
    n = 16
    dst = rng.uniform(-0.5, 2.0, (n * n, 4)).astype(np.float32)
    src = rng.uniform(-0.5, 2.0, (n * n, 4)).astype(np.float32)
    gl = make("rgba32f", size=n)
    draw_points(gl, dst[None])            # blending off: the destination, exactly
    np.testing.assert_array_equal(read(gl).reshape(-1, 4), dst)
    gl.enable(gl.BLEND)
    gl.blendFunc(getattr(gl, sf), getattr(gl, df))
    gl.blendEquation(getattr(gl, eq))
    draw_points(gl, src[None])
    want = blend64(src.astype(np.float64), dst.astype(np.float64), sf, df, eq)
    got = read(gl).reshape(-1, 4)
    np.testing.assert_allclose(got, want, rtol=1e-6, atol=1e-6)
    # Outside [0, 1] on purpose: float buffers keep it (no clamping).
    assert (got < 0).any() or (got > 1).any() or eq in ("MIN",)


def test_float_blend_constant_is_unclamped():
    gl = make("rgba32f", size=2)
    gl.enable(gl.BLEND)
    gl.blendColor(2.5, -1.0, 0.5, 3.0)
    gl.blendFunc(gl.CONSTANT_COLOR, gl.ZERO)
    draw_points(gl, np.full((1, 4, 4), 0.5, np.float32))
    np.testing.assert_allclose(read(gl)[0, 0], [1.25, -0.5, 0.25, 1.5], rtol=1e-7)
    # The same on rgba8 clamps everything (ES 3.0 §4.1.7).
    gl8 = make("rgba8", size=2)
    gl8.enable(gl8.BLEND)
    gl8.blendColor(2.5, -1.0, 0.5, 3.0)
    gl8.blendFunc(gl8.CONSTANT_COLOR, gl8.ZERO)
    draw_points(gl8, np.full((1, 4, 4), 0.5, np.float32))
    np.testing.assert_array_equal(gl8.readPixels(0, 0, 1, 1, gl8.RGBA, gl8.UNSIGNED_BYTE)[0, 0], [128, 0, 64, 128])


def chain_reference(colors, background):
    """Alpha-over (SRC_ALPHA, ONE_MINUS_SRC_ALPHA on every channel) in float64."""
    d = np.array(background, np.float64)
    for c in colors.astype(np.float64):
        d = c * c[..., 3:4] + d * (1 - c[..., 3:4])
    return d


def quantizer(fmt):
    if fmt == "rgba8":
        return lambda x: np.floor(np.clip(x, 0, 1) * 255 + 0.5) / 255
    if fmt == "rgba16f":
        return lambda x: x.astype(np.float32).astype(np.float16).astype(np.float64)
    return lambda x: x.astype(np.float32).astype(np.float64)


@pytest.fixture(scope="module")
def chain_errors():
    """RMSE against float64 of alpha-over chains of 10/100/1000 layers, per format."""
    rng = np.random.default_rng(3)
    n = 8
    out = {}
    for layers in (10, 100, 1000):
        colors = rng.uniform(0, 1, (layers, n * n, 4)).astype(np.float32)
        colors[..., 3] = rng.uniform(0.02, 0.2, (layers, n * n)).astype(np.float32)
        want = chain_reference(colors, np.zeros((n * n, 4)))
        for fmt in FORMATS:
            gl = make(fmt, size=n)
            gl.enable(gl.BLEND)
            gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)
            draw_points(gl, colors)
            got = read(gl).reshape(-1, 4)
            out[fmt, layers] = float(np.sqrt(np.mean((got - want) ** 2)))
    return out


def test_blend_chains_error_growth(chain_errors):
    e = chain_errors
    for layers in (10, 100, 1000):
        assert e["rgba32f", layers] < 1e-5          # float32 rounding only
        assert e["rgba16f", layers] < 2e-3          # binary16: 11 significant bits
        assert e["rgba32f", layers] < e["rgba16f", layers] < e["rgba8", layers]
    # unorm8 rounding stalls alpha-over with small alphas: its error is of the order of the
    # step (1/255) and does not shrink with more layers.
    assert e["rgba8", 1000] > 1e-3


def test_rgba8_chain_equals_the_per_step_rounding_model():
    """The rgba8 chain is the float64 chain with each step rounded to unorm8 (and the others
    likewise rounded to their formats): the error comes from storage only."""
    rng = np.random.default_rng(5)
    n, layers = 4, 100
    colors = rng.uniform(0, 1, (layers, n * n, 4)).astype(np.float32)
    colors[..., 3] = rng.uniform(0.05, 0.3, (layers, n * n)).astype(np.float32)
    for fmt in FORMATS:
        q = quantizer(fmt)
        d = np.zeros((n * n, 4))
        for c in colors:
            if fmt == "rgba8":   # ES 3.0 §4.1.7: blended in float, clamped, rounded
                s = c.astype(np.float32)
                d32 = d.astype(np.float32)
                d = q((s * s[:, 3:4] + d32 * (np.float32(1) - s[:, 3:4])).astype(np.float64))
            else:
                s = c.astype(np.float32)
                d = q((s * s[:, 3:4] + d.astype(np.float32) * (np.float32(1) - s[:, 3:4])).astype(np.float64))
        gl = make(fmt, size=n)
        gl.enable(gl.BLEND)
        gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)
        draw_points(gl, colors)
        np.testing.assert_allclose(read(gl).reshape(-1, 4), d, rtol=0, atol=1e-7 if fmt != "rgba8" else 1e-9)


def test_additive_chain_exceeds_one_only_in_float():
    n, layers = 2, 1000
    colors = np.full((layers, n * n, 4), 0.01, np.float32)
    results = {}
    for fmt in FORMATS:
        gl = make(fmt, size=n)
        gl.enable(gl.BLEND)
        gl.blendFunc(gl.ONE, gl.ONE)
        draw_points(gl, colors)
        results[fmt] = read(gl)[0, 0, 0]
    assert results["rgba8"] == 1.0                       # saturated at 1
    assert abs(results["rgba32f"] - 10.0) < 1e-3         # 1000 * 0.01 without clamping
    # binary16: once the sum passes 8, the spacing (2^-7) swallows part of each 0.01 step.
    h = np.float16(0)
    for _ in range(layers):
        h = np.float16(np.float32(h) + np.float32(0.01))
    assert results["rgba16f"] == float(h) and results["rgba16f"] != 10.0


# ---------------------------------------------------------------- readPixels rules

def test_read_pixels_type_rules(quiet):
    gl = softgl.Context(4, 4, color_format="rgba32f")
    assert gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE) is None
    assert gl.getError() == gl.INVALID_OPERATION
    assert gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.HALF_FLOAT) is None   # 16F's pair, not 32F's
    assert gl.getError() == gl.INVALID_OPERATION
    assert gl.readPixels(0, 0, 1, 1, gl.RGB, gl.FLOAT) is None
    assert gl.getError() == gl.INVALID_OPERATION
    assert gl.readPixels(0, 0, 1, 1, gl.RGBA, 0x1234) is None
    assert gl.getError() == gl.INVALID_ENUM
    wrong = np.zeros((1, 1, 4), np.uint8)          # FLOAT needs a Float32Array
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.FLOAT, wrong)
    assert gl.getError() == gl.INVALID_OPERATION
    small = np.zeros(3, np.float32)
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.FLOAT, small)
    assert gl.getError() == gl.INVALID_OPERATION
    h = softgl.Context(4, 4, color_format="rgba16f")
    assert h.readPixels(0, 0, 1, 1, h.RGBA, h.FLOAT).dtype == np.float32
    assert h.readPixels(0, 0, 1, 1, h.RGBA, h.HALF_FLOAT).dtype == np.uint16
    h.readPixels(0, 0, 1, 1, h.RGBA, h.HALF_FLOAT, np.zeros(4, np.float32))   # needs Uint16Array
    assert h.getError() == h.INVALID_OPERATION
    assert h.getError() == h.NO_ERROR
    # And rgba8 keeps WebGL's rule: no FLOAT reads of the drawing buffer.
    g = softgl.Context(4, 4)
    assert g.readPixels(0, 0, 1, 1, g.RGBA, g.FLOAT) is None
    assert g.getError() == g.INVALID_OPERATION


def test_read_pixels_float_into_array_with_pack_parameters():
    gl = softgl.Context(4, 3, color_format="rgba32f", strict=True)
    gl.clearColor(0.25, 1.5, -2.0, 0.75)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.pixelStorei(gl.PACK_ROW_LENGTH, 6)
    gl.pixelStorei(gl.PACK_SKIP_PIXELS, 1)
    gl.pixelStorei(gl.PACK_SKIP_ROWS, 1)
    out = np.full(6 * 4 * 4, -9.0, np.float32)
    gl.readPixels(-1, 0, 3, 3, gl.RGBA, gl.FLOAT, out)   # column -1 is outside: left unchanged
    rows = out.reshape(4, 6, 4)
    assert (rows[0] == -9).all()
    assert (rows[1:, 1] == -9).all()                    # x = -1
    assert (rows[1:, 2:4] == np.float32([0.25, 1.5, -2.0, 0.75])).all()
    assert (rows[1:, 4:] == -9).all()


@pytest.mark.parametrize("fmt", ["rgba16f", "rgba32f"])
def test_msaa_resolve_is_the_mean_in_the_format(fmt):
    gl = softgl.Context(16, 16, color_format=fmt, antialias=True, samples=4, preserveDrawingBuffer=True)
    prog = softgl.program(gl, VS, FS)
    gl.useProgram(prog)
    gl._prog = prog
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.bufferData(gl.ARRAY_BUFFER, np.float32([-0.9, -0.8, 0.85, -0.3, -0.2, 0.95]), gl.STATIC_DRAW)
    loc = gl.getAttribLocation(prog, "aPos")
    gl.enableVertexAttribArray(loc)
    gl.vertexAttribPointer(loc, 2, gl.FLOAT, False, 0, 0)
    gl.vertexAttrib4f(gl.getAttribLocation(prog, "aColor"), 3.0, 1 / 3, -1.0, 1.0)
    gl.drawArrays(gl.TRIANGLES, 0, 3)
    px = gl.readPixels(0, 0, 16, 16, gl.RGBA, gl.FLOAT).astype(np.float64)
    k = px[..., 3] * 4                                   # covered samples per pixel
    assert np.allclose(k, np.round(k)) and ((k > 0) & (k < 4)).any()
    q = quantizer(fmt)
    third = float(q(np.float64(np.float32(1 / 3))))
    np.testing.assert_array_equal(px[..., 0], q(3.0 * k / 4))
    np.testing.assert_array_equal(px[..., 1], q(third * k / 4))
    np.testing.assert_array_equal(px[..., 2], q(-1.0 * k / 4))


# ---------------------------------------------------------------- display

@pytest.mark.parametrize("premultiplied", [True, False])
def test_canvas_display_converts_like_a_browser(premultiplied):
    gl = softgl.Context(2, 1, color_format="rgba16f", premultipliedAlpha=premultiplied, preserveDrawingBuffer=False)
    gl.enable(gl.SCISSOR_TEST)
    gl.scissor(0, 0, 1, 1)
    gl.clearColor(2.0, -1.0, 0.5, 0.6)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.scissor(1, 0, 1, 1)
    gl.clearColor(0.2, 0.4, float("nan"), 1.5)
    gl.clear(gl.COLOR_BUFFER_BIT)
    floats = gl.readPixels(0, 0, 2, 1, gl.RGBA, gl.FLOAT)
    # clamp to [0, 1], round to 8 bits, then composite over the page
    as8 = np.floor(np.clip(np.nan_to_num(floats.astype(np.float64)), 0, 1) * 255 + 0.5).astype(np.uint8)
    want = composite(as8[::-1], premultiplied=premultiplied)
    shown = canvas_image(gl)
    np.testing.assert_array_equal(shown, want)
    assert tuple(shown[0, 0]) == ((255, 102, 230) if premultiplied else (255, 102, 179))
    # Showing never clears; the end of a frame (present) clears, as in a browser.
    np.testing.assert_array_equal(gl.readPixels(0, 0, 2, 1, gl.RGBA, gl.FLOAT), floats)
    assert gl._repr_png_().startswith(b"\x89PNG")
    display.present(gl)
    assert (gl.readPixels(0, 0, 2, 1, gl.RGBA, gl.FLOAT) == 0).all()


def test_blit_and_copy_from_a_float_drawing_buffer():
    gl = softgl.Context(4, 4, color_format="rgba32f", strict=True)
    gl.clearColor(1.5, -0.5, 0.25, 1.0)
    gl.clear(gl.COLOR_BUFFER_BIT)
    assert gl.getExtension("EXT_color_buffer_float") is not None
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA32F, 4, 4)
    fbo = gl.createFramebuffer()
    gl.bindFramebuffer(gl.DRAW_FRAMEBUFFER, fbo)
    gl.framebufferTexture2D(gl.DRAW_FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0)
    gl.blitFramebuffer(0, 0, 4, 4, 0, 0, 4, 4, gl.COLOR_BUFFER_BIT, gl.NEAREST)
    gl.bindFramebuffer(gl.READ_FRAMEBUFFER, fbo)
    want = np.float32([1.5, -0.5, 0.25, 1.0]) * np.ones((4, 4, 1), np.float32)
    np.testing.assert_array_equal(gl.readPixels(0, 0, 4, 4, gl.RGBA, gl.FLOAT), want)
    # copyTexSubImage2D from the float drawing buffer into an RGBA32F texture, values kept.
    gl.bindFramebuffer(gl.FRAMEBUFFER, None)
    gl.clearColor(-3.0, 7.0, 0.5, 2.0)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.copyTexSubImage2D(gl.TEXTURE_2D, 0, 0, 0, 0, 0, 2, 2)
    gl.bindFramebuffer(gl.READ_FRAMEBUFFER, fbo)
    got = gl.readPixels(0, 0, 4, 4, gl.RGBA, gl.FLOAT)
    np.testing.assert_array_equal(got[:2, :2], np.float32([-3.0, 7.0, 0.5, 2.0]) * np.ones((2, 2, 1), np.float32))
    np.testing.assert_array_equal(got[2:, 2:], want[2:, 2:])


@pytest.mark.parametrize("fmt", ["rgba16f", "rgba32f"])
def test_every_nan_is_stored_as_the_one_quiet_nan(fmt):
    """Which NaN an IEEE operation returns depends on operand order, which SIMD and scalar code
    need not share; float buffers therefore store every NaN as the canonical quiet NaN
    0x7fc00000 (so the bytes are the same on every CPU). Input NaNs with other signs and payloads
    reach the buffer unchanged through a point's (uninterpolated) varying."""
    gl = make(fmt, size=2)
    payloads = np.array([0xFFC00000, 0x7FC00001, 0xFFFFFFFF, 0x7FA00000], np.uint32)
    colors = np.zeros((4, 4), np.float32)
    colors.view(np.uint32)[:] = payloads[:, None]
    draw_points(gl, colors)
    bits = read(gl).astype(np.float32).view(np.uint32)
    assert np.all(bits == 0x7FC00000), [hex(b) for b in np.unique(bits)]
