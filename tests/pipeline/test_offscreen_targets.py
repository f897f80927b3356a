"""Off-screen targets on the canvas's paths, and the instanced vertex stage in full batches.

- A draw into a framebuffer object (RGBA8 texture + 24-bit depth attachment) takes the quad early
  depth test, depth bounds and hidden-surface removal as the canvas does, and gives the canvas's
  bytes; attachments that cannot (16-bit / float depth, a wider depth image) say why in the plan
  and still give the canvas's bytes; single- and multisampled, the quad kernel gives the bytes of the
  sample-by-sample test (forced by a no-op stencil test).
- Clears of every attachment format (colour, integer, depth 16/24/32F, depth-stencil, stencil),
  with scissor and masks, against values computed by hand.
- Instanced draws give the bytes of the same geometry drawn without instancing.
"""
import numpy as np
import pytest

import softgl

W, H = 96, 80

VS = """#version 300 es
in vec3 aPos; in vec2 aUV; out vec2 vUV;
void main() { vUV = aUV; gl_Position = vec4(aPos, 1.0); }"""
FS = """#version 300 es
precision mediump float; uniform sampler2D uTex; in vec2 vUV; out vec4 o;
void main() { o = texture(uTex, vUV); }"""


def _mesh(n, seed):
    """n x n grid of small triangles over [-1, 1]^2 with bumpy depth, overlapping a second layer."""
    rng = np.random.default_rng(seed)
    xs = np.linspace(-1.1, 1.1, n + 1)
    pos, uv = [], []
    for layer in range(2):
        z = rng.uniform(-0.9, 0.9, (n + 1, n + 1))
        for j in range(n):
            for i in range(n):
                corners = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j), (i + 1, j + 1), (i, j + 1)]
                for (a, b) in corners:
                    pos += [xs[a] + 0.013 * layer, xs[b], z[a, b]]
                    uv += [a / n * 3.0, b / n * 2.0]
    return np.array(pos, np.float32), np.array(uv, np.float32)


def _target(gl, kind, depth_format, wider_depth=False):
    """None for the canvas, else a framebuffer of an RGBA8 texture and a depth attachment."""
    if kind == "canvas":
        return None
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, W, H, 0, gl.RGBA, gl.UNSIGNED_BYTE, None)
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0)
    fmt = getattr(gl, depth_format)
    att = gl.DEPTH_STENCIL_ATTACHMENT if depth_format == "DEPTH24_STENCIL8" else gl.DEPTH_ATTACHMENT
    dw = W + 24 if wider_depth else W
    if kind == "renderbuffer":
        rb = gl.createRenderbuffer()
        gl.bindRenderbuffer(gl.RENDERBUFFER, rb)
        gl.renderbufferStorage(gl.RENDERBUFFER, fmt, dw, H)
        gl.framebufferRenderbuffer(gl.FRAMEBUFFER, att, gl.RENDERBUFFER, rb)
    else:
        dt = gl.createTexture()
        gl.bindTexture(gl.TEXTURE_2D, dt)
        fmt_, type_ = {"DEPTH_COMPONENT16": (gl.DEPTH_COMPONENT, gl.UNSIGNED_SHORT),
                       "DEPTH_COMPONENT24": (gl.DEPTH_COMPONENT, gl.UNSIGNED_INT),
                       "DEPTH_COMPONENT32F": (gl.DEPTH_COMPONENT, gl.FLOAT),
                       "DEPTH24_STENCIL8": (gl.DEPTH_STENCIL, gl.UNSIGNED_INT_24_8)}[depth_format]
        gl.texImage2D(gl.TEXTURE_2D, 0, fmt, dw, H, 0, fmt_, type_, None)
        gl.framebufferTexture2D(gl.FRAMEBUFFER, att, gl.TEXTURE_2D, dt, 0)
    assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == gl.FRAMEBUFFER_COMPLETE
    return fb


def _draw_textured(kind, depth_format="DEPTH_COMPONENT24", wider_depth=False, simd=None, depth_func="LESS"):
    gl = softgl.Context(W, H, antialias=False, threads=2)
    if simd:
        softgl._core.testing.set_tuning(gl, simd=simd)
    _target(gl, kind, depth_format, wider_depth)
    gl.viewport(0, 0, W, H)
    prog = softgl.program(gl, VS, FS)
    gl.useProgram(prog)
    pos, uv = _mesh(14, seed=3)
    for name, data, k in (("aPos", pos, 3), ("aUV", uv, 2)):
        b = gl.createBuffer()
        gl.bindBuffer(gl.ARRAY_BUFFER, b)
        gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW)
        loc = gl.getAttribLocation(prog, name)
        gl.enableVertexAttribArray(loc)
        gl.vertexAttribPointer(loc, k, gl.FLOAT, False, 0, 0)
    img = np.random.default_rng(5).integers(0, 256, (32, 32, 4), dtype=np.uint8)
    gl.activeTexture(gl.TEXTURE1)
    gl.bindTexture(gl.TEXTURE_2D, gl.createTexture())
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, 32, 32, 0, gl.RGBA, gl.UNSIGNED_BYTE, img)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.LINEAR)
    gl.uniform1i(gl.getUniformLocation(prog, "uTex"), 1)
    gl.enable(gl.DEPTH_TEST)
    gl.depthFunc(getattr(gl, depth_func))
    gl.clearColor(0.1, 0.2, 0.3, 1.0)
    gl.clearDepth(0.0 if depth_func.startswith("G") else 1.0)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    n = len(pos) // 3
    gl.drawArrays(gl.TRIANGLES, 0, n // 2)          # the first layer
    gl.drawArrays(gl.TRIANGLES, n // 2, n - n // 2)  # the second, tested against the first
    plan = gl.last_draw_plan()
    return gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE), plan, gl.stats()


@pytest.mark.parametrize("kind", ["renderbuffer", "texture"])
@pytest.mark.parametrize("depth_format", ["DEPTH_COMPONENT24", "DEPTH24_STENCIL8"])
@pytest.mark.parametrize("depth_func", ["LESS", "GEQUAL"])
def test_fbo_with_24_bit_depth_takes_the_canvas_paths_and_gives_its_bytes(kind, depth_format, depth_func):
    canvas, canvas_plan, canvas_stats = _draw_textured("canvas", depth_func=depth_func)
    fbo, plan, stats = _draw_textured(kind, depth_format, depth_func=depth_func)
    assert canvas_plan["quad_depth"] and canvas_plan["hidden_surface_removal"]
    assert plan["target"] == "framebuffer_object"
    assert plan["quad_depth"], plan["text"]
    assert plan["depth_bounds"] == canvas_plan["depth_bounds"]
    assert plan["hidden_surface_removal"], plan["text"]
    # The same work skipped the same way: the paths' counters agree with the canvas's.
    assert stats["fragments_killed_early"] > 0 and stats["fragments_killed_late"] == 0
    for counter in ("draws_early_depth", "fragments_killed_early", "fragments_hidden", "primitives_depth_hidden"):
        assert stats[counter] == canvas_stats[counter], counter
    np.testing.assert_array_equal(fbo, canvas)


@pytest.mark.parametrize("simd", ["scalar", "sse2", "avx2", "avx512"])
def test_fbo_bytes_at_every_simd_level(simd):
    if softgl._core.testing.simd_level() < ["scalar", "sse2", "avx2", "avx512"].index(simd):
        pytest.skip("CPU lacks the level")
    reference, _, _ = _draw_textured("canvas", simd="scalar")
    fbo, _, _ = _draw_textured("renderbuffer", simd=simd)
    np.testing.assert_array_equal(fbo, reference)


@pytest.mark.parametrize("depth_format,why", [("DEPTH_COMPONENT16", "depth_not_24_bit"),
                                              ("DEPTH_COMPONENT32F", "depth_not_24_bit")])
def test_other_depth_formats_say_why_and_draw_correctly(depth_format, why):
    fbo, plan, _ = _draw_textured("texture", depth_format)
    assert not plan["quad_depth"] and plan["quad_depth_why_not"] == why
    # The mesh's depths are far apart compared with 16-bit steps: the same picture as the canvas.
    canvas, _, _ = _draw_textured("canvas")
    assert np.count_nonzero(np.any(fbo != canvas, axis=2)) <= W * H // 200


def test_wider_depth_attachment_says_why_and_gives_the_canvas_bytes():
    canvas, _, _ = _draw_textured("canvas")
    fbo, plan, _ = _draw_textured("renderbuffer", wider_depth=True)
    assert not plan["quad_depth"] and plan["quad_depth_why_not"] == "attachment_sizes_differ"
    np.testing.assert_array_equal(fbo, canvas)


# ------------------------------------------------------------- RGBA8 colour on the byte paths

COLOR_VS = """#version 300 es
in vec3 aPos; in vec4 aColor; out vec4 vColor;
void main() { vColor = aColor; gl_Position = vec4(aPos, 1.0); }"""
COLOR_FS = """#version 300 es
precision mediump float; in vec4 vColor; out vec4 o;
void main() { o = vColor * vColor.a; }"""


def _draw_colored(kind, samples, blend, color_width=W):
    """Blended (or not) per-vertex-colour triangles with a depth test into the canvas or an FBO of
    an RGBA8 renderbuffer `color_width` wide and a W-wide DEPTH24_STENCIL8 renderbuffer (a wider
    colour image keeps the draw off the byte paths: rows of another pitch); multisampled FBOs are
    resolved into an RGBA8 texture by blitFramebuffer. Returns (W x H RGBA bytes, plan)."""
    gl = softgl.Context(W, H, antialias=samples > 1, version=2, threads=2)
    fb = None
    if kind == "fbo":
        fb = gl.createFramebuffer()
        gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
        for fmt, att, w in ((gl.RGBA8, gl.COLOR_ATTACHMENT0, color_width),
                            (gl.DEPTH24_STENCIL8, gl.DEPTH_STENCIL_ATTACHMENT, W)):
            rb = gl.createRenderbuffer()
            gl.bindRenderbuffer(gl.RENDERBUFFER, rb)
            gl.renderbufferStorageMultisample(gl.RENDERBUFFER, samples if samples > 1 else 0, fmt, w, H)
            gl.framebufferRenderbuffer(gl.FRAMEBUFFER, att, gl.RENDERBUFFER, rb)
        assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == gl.FRAMEBUFFER_COMPLETE
    gl.viewport(0, 0, W, H)
    prog = softgl.program(gl, COLOR_VS, COLOR_FS)
    gl.useProgram(prog)
    rng = np.random.default_rng(11)
    n = 3 * 60
    pos = np.column_stack([rng.uniform(-1.2, 1.2, (n, 2)), rng.uniform(-0.9, 0.9, n)]).astype(np.float32)
    col = rng.uniform(0, 1, (n, 4)).astype(np.float32)
    for name, data, k in (("aPos", pos, 3), ("aColor", col, 4)):
        gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
        gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW)
        loc = gl.getAttribLocation(prog, name)
        gl.enableVertexAttribArray(loc)
        gl.vertexAttribPointer(loc, k, gl.FLOAT, False, 0, 0)
    gl.enable(gl.DEPTH_TEST)
    if blend:
        gl.enable(gl.BLEND)
        gl.blendFuncSeparate(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA, gl.ONE, gl.ONE_MINUS_SRC_ALPHA)
    gl.clearColor(0.25, 0.5, 0.75, 0.5)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    gl.drawArrays(gl.TRIANGLES, 0, n)
    plan = gl.last_draw_plan()
    assert gl.getError() == gl.NO_ERROR
    if kind == "fbo" and samples > 1:
        resolved = gl.createFramebuffer()
        gl.bindFramebuffer(gl.DRAW_FRAMEBUFFER, resolved)
        tex = gl.createTexture()
        gl.bindTexture(gl.TEXTURE_2D, tex)
        gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA8, W, H)
        gl.framebufferTexture2D(gl.DRAW_FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0)
        gl.blitFramebuffer(0, 0, W, H, 0, 0, W, H, gl.COLOR_BUFFER_BIT, gl.NEAREST)
        gl.bindFramebuffer(gl.READ_FRAMEBUFFER, resolved)
    return gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE), plan


@pytest.mark.parametrize("samples", [1, 4])
@pytest.mark.parametrize("blend", [False, True])
def test_rgba8_fbo_takes_the_colour_kernels_and_gives_the_general_paths_bytes(samples, blend):
    fast, plan = _draw_colored("fbo", samples, blend)
    general, general_plan = _draw_colored("fbo", samples, blend, color_width=W + 8)
    assert plan["target"] == "framebuffer_object" and plan["color_kernels"], plan["text"]
    assert general_plan["color_kernels_why_not"] == "framebuffer_object"
    np.testing.assert_array_equal(fast, general)
    if samples == 1:   # the canvas resolves multisamples by its own rounding; single-sampled it is the same
        canvas, canvas_plan = _draw_colored("canvas", samples, blend)
        assert canvas_plan["color_kernels"]
        np.testing.assert_array_equal(fast, canvas)


# ---------------------------------------------------------------------------------------- clears

SCISSOR = (10, 7, 33, 21)   # x, y, w, h


def _in_scissor():
    m = np.zeros((H, W), bool)
    x, y, w, h = SCISSOR
    m[y:y + h, x:x + w] = True
    return m


def _color_fbo(gl, internal, fmt, type_):
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    rb = gl.createRenderbuffer()
    gl.bindRenderbuffer(gl.RENDERBUFFER, rb)
    gl.renderbufferStorage(gl.RENDERBUFFER, internal, W, H)
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.RENDERBUFFER, rb)
    assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == gl.FRAMEBUFFER_COMPLETE


def test_clear_rgba8_texture_with_scissor_and_mask():
    gl = softgl.Context(W, H, antialias=False)
    _target(gl, "texture", "DEPTH_COMPONENT24")
    first, second = (0.2, 0.4, 0.6, 0.8), (1.7, -0.3, 0.5019608, 0.25)   # out of range: clamped
    gl.clearColor(*first)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.enable(gl.SCISSOR_TEST)
    gl.scissor(*SCISSOR)
    gl.colorMask(True, False, True, False)
    gl.clearColor(*second)
    gl.clear(gl.COLOR_BUFFER_BIT)
    px = gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE)

    def unorm8(v):   # float64: clamp, then round half up
        return int(np.floor(min(max(v, 0.0), 1.0) * 255.0 + 0.5))
    outside = [unorm8(v) for v in first]
    inside = [unorm8(second[0]), outside[1], unorm8(second[2]), outside[3]]
    expected = np.empty((H, W, 4), np.uint8)
    expected[:] = outside
    expected[_in_scissor()] = inside
    np.testing.assert_array_equal(px, expected)


@pytest.mark.parametrize("internal,half", [("RGBA16F", True), ("RGBA32F", False)])
def test_clear_float_formats(internal, half):
    gl = softgl.Context(W, H, antialias=False)
    gl.getExtension("EXT_color_buffer_float")
    _color_fbo(gl, getattr(gl, internal), gl.RGBA, gl.FLOAT)
    first, second = (0.1, -2.5, 1e5, 3.3), (1 / 3, 7.0, -0.0, 65519.0)
    gl.clearColor(*first)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.enable(gl.SCISSOR_TEST)
    gl.scissor(*SCISSOR)
    gl.colorMask(True, True, False, True)
    gl.clearBufferfv(gl.COLOR, 0, np.array(second, np.float32))
    px = gl.readPixels(0, 0, W, H, gl.RGBA, gl.FLOAT)

    def stored(v):   # the clear colour is a float32; 16F rounds it to binary16 (ties to even)
        f = np.float32(v)
        with np.errstate(over="ignore"):
            return np.float32(np.float16(f)) if half else f
    outside = [stored(v) for v in first]
    inside = [stored(second[0]), stored(second[1]), outside[2], stored(second[3])]
    expected = np.empty((H, W, 4), np.float32)
    expected[:] = outside
    expected[_in_scissor()] = inside
    np.testing.assert_array_equal(px, expected)


def test_clear_integer_format():
    gl = softgl.Context(W, H, antialias=False)
    _color_fbo(gl, gl.RGBA8UI, gl.RGBA_INTEGER, gl.UNSIGNED_BYTE)
    gl.clearBufferuiv(gl.COLOR, 0, np.array([1, 2, 3, 4], np.uint32))
    gl.enable(gl.SCISSOR_TEST)
    gl.scissor(*SCISSOR)
    gl.colorMask(False, True, True, True)
    gl.clearBufferuiv(gl.COLOR, 0, np.array([9, 300, 77, 255], np.uint32))   # 300 clamps to 255
    px = gl.readPixels(0, 0, W, H, gl.RGBA_INTEGER, gl.UNSIGNED_INT)
    expected = np.empty((H, W, 4), np.uint32)
    expected[:] = [1, 2, 3, 4]
    expected[_in_scissor()] = [1, 255, 77, 255]
    np.testing.assert_array_equal(px, expected)


FLAT_VS = """#version 300 es
in vec2 aPos; uniform float uZ;
void main() { gl_Position = vec4(aPos, uZ, 1.0); }"""
WHITE_FS = """#version 300 es
precision mediump float; out vec4 o; void main() { o = vec4(1.0); }"""


def _full_screen_quad(gl, z):
    prog = softgl.program(gl, FLAT_VS, WHITE_FS)
    gl.useProgram(prog)
    b = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, b)
    gl.bufferData(gl.ARRAY_BUFFER, np.array([-1, -1, 1, -1, -1, 1, 1, 1], np.float32), gl.STATIC_DRAW)
    loc = gl.getAttribLocation(prog, "aPos")
    gl.enableVertexAttribArray(loc)
    gl.vertexAttribPointer(loc, 2, gl.FLOAT, False, 0, 0)
    gl.uniform1f(gl.getUniformLocation(prog, "uZ"), z)


@pytest.mark.parametrize("kind", ["renderbuffer", "texture"])
@pytest.mark.parametrize("depth_format", ["DEPTH_COMPONENT16", "DEPTH_COMPONENT24", "DEPTH_COMPONENT32F",
                                          "DEPTH24_STENCIL8"])
def test_clear_depth_every_format(kind, depth_format):
    # Window depth 0.25 (NDC z = -0.5) is exact in every format's conversion; EQUAL passes exactly
    # where the cleared word is the word of 0.25, computed by the same conversion as the draw's.
    gl = softgl.Context(W, H, antialias=False)
    _target(gl, kind, depth_format)
    gl.viewport(0, 0, W, H)
    gl.clearColor(0, 0, 0, 0)
    gl.clearDepth(0.75)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    gl.enable(gl.SCISSOR_TEST)
    gl.scissor(*SCISSOR)
    gl.clearBufferfv(gl.DEPTH, 0, np.array([0.25], np.float32))
    gl.depthMask(False)
    gl.clearDepth(0.5)
    gl.clear(gl.DEPTH_BUFFER_BIT)   # masked: changes nothing
    gl.disable(gl.SCISSOR_TEST)
    _full_screen_quad(gl, -0.5)
    gl.enable(gl.DEPTH_TEST)
    gl.depthFunc(gl.EQUAL)
    gl.drawArrays(gl.TRIANGLE_STRIP, 0, 4)
    px = gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE)
    np.testing.assert_array_equal(px[..., 0] == 255, _in_scissor())


@pytest.mark.parametrize("kind", ["renderbuffer", "texture"])
def test_clear_stencil_with_write_mask(kind):
    gl = softgl.Context(W, H, antialias=False)
    _target(gl, kind, "DEPTH24_STENCIL8")
    gl.viewport(0, 0, W, H)
    gl.clearColor(0, 0, 0, 0)
    gl.clearStencil(0b10100101)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.STENCIL_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    gl.enable(gl.SCISSOR_TEST)
    gl.scissor(*SCISSOR)
    gl.stencilMask(0b00111100)
    gl.clearStencil(0b01011010)
    gl.clear(gl.STENCIL_BUFFER_BIT)
    gl.disable(gl.SCISSOR_TEST)
    inside = (0b10100101 & ~0b00111100) | (0b01011010 & 0b00111100)
    gl.stencilMask(0xFF)
    _full_screen_quad(gl, 0.0)
    gl.enable(gl.STENCIL_TEST)
    for value, where in ((inside, _in_scissor()), (0b10100101, ~_in_scissor())):
        gl.clear(gl.COLOR_BUFFER_BIT)
        gl.stencilFunc(gl.EQUAL, value, 0xFF)
        gl.drawArrays(gl.TRIANGLE_STRIP, 0, 4)
        px = gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE)
        np.testing.assert_array_equal(px[..., 0] == 255, where)


def test_cleared_texture_is_sampled_as_cleared():
    # The clear bumps the texture's generation: the next pass samples the new texels.
    gl = softgl.Context(W, H, antialias=False)
    fb = _target(gl, "texture", "DEPTH_COMPONENT24")
    tex = gl.getFramebufferAttachmentParameter(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0,
                                               gl.FRAMEBUFFER_ATTACHMENT_OBJECT_NAME)
    prog = softgl.program(gl, """#version 300 es
in vec2 aPos; out vec2 vUV; void main() { vUV = aPos * 0.5 + 0.5; gl_Position = vec4(aPos, 0.0, 1.0); }""",
                          """#version 300 es
precision mediump float; uniform sampler2D uTex; in vec2 vUV; out vec4 o;
void main() { o = texture(uTex, vUV); }""")
    gl.useProgram(prog)
    b = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, b)
    gl.bufferData(gl.ARRAY_BUFFER, np.array([-1, -1, 1, -1, -1, 1, 1, 1], np.float32), gl.STATIC_DRAW)
    gl.enableVertexAttribArray(0)
    gl.vertexAttribPointer(gl.getAttribLocation(prog, "aPos"), 2, gl.FLOAT, False, 0, 0)
    gl.bindTexture(gl.TEXTURE_2D, tex)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST)
    for color in ((1, 0, 0, 1), (0, 0.6, 0, 1)):
        gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
        gl.clearColor(*color)
        gl.clear(gl.COLOR_BUFFER_BIT)
        for _ in range(2):   # twice: the second draw may take the sampler's byte copy
            gl.bindFramebuffer(gl.FRAMEBUFFER, None)
            gl.drawArrays(gl.TRIANGLE_STRIP, 0, 4)
            px = gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE)
            assert (px == [round(c * 255) for c in color]).all()


# ---------------------------------------------------------------------------------------- instancing

INST_VS = """#version 300 es
in vec3 aPos; in vec3 aOff; in vec4 aCol; in uvec2 aTag; out vec4 vCol;
uniform int uUseId;
void main() {
    float id = uUseId == 1 ? float(gl_InstanceID) : float(aTag.x);
    vCol = aCol * (0.5 + 0.5 * fract(id * 0.37)) + vec4(float(aTag.y) / 255.0, 0.0, 0.0, 0.0);
    gl_Position = vec4(aPos * 0.06 + aOff, 1.0);
}"""
INST_FS = """#version 300 es
precision mediump float; in vec4 vCol; out vec4 o; void main() { o = vCol; }"""


def _cube(n_extra=0):
    v = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], np.float32)
    idx = np.array([0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5, 0, 4, 5, 0, 5, 1, 2, 3, 7, 2, 7, 6,
                    0, 2, 6, 0, 6, 4, 1, 5, 7, 1, 7, 3], np.uint16)
    if n_extra:   # a mesh of more than one vertex chunk (1,024 vertices) per instance
        rng = np.random.default_rng(9)
        extra = rng.uniform(-1, 1, (n_extra, 3)).astype(np.float32)
        v = np.concatenate([v, extra])
        tri = rng.integers(0, len(v), (n_extra, 3)).astype(np.uint16).ravel()
        idx = np.concatenate([idx, tri])
    return v, idx


def _draw_instances(instanced, instances, divisor, indexed, use_id, n_extra=0, threads=2):
    gl = softgl.Context(W, H, antialias=False, threads=threads)
    prog = softgl.program(gl, INST_VS, INST_FS)
    gl.useProgram(prog)
    gl.uniform1i(gl.getUniformLocation(prog, "uUseId"), int(use_id))
    v, idx = _cube(n_extra)
    rng = np.random.default_rng(2)
    groups = (instances + divisor - 1) // divisor
    off = rng.uniform(-0.95, 0.95, (groups, 3)).astype(np.float32)
    col = rng.uniform(0, 1, (groups, 4)).astype(np.float32)
    tag = np.stack([np.arange(instances), rng.integers(0, 256, instances)], 1).astype(np.uint32)

    def attr(name, data, k, div, integer=False):
        b = gl.createBuffer()
        gl.bindBuffer(gl.ARRAY_BUFFER, b)
        gl.bufferData(gl.ARRAY_BUFFER, np.ascontiguousarray(data), gl.STATIC_DRAW)
        loc = gl.getAttribLocation(prog, name)
        gl.enableVertexAttribArray(loc)
        if integer:
            gl.vertexAttribIPointer(loc, k, gl.UNSIGNED_INT, 0, 0)
        else:
            gl.vertexAttribPointer(loc, k, gl.FLOAT, False, 0, 0)
        gl.vertexAttribDivisor(loc, div)
    gl.enable(gl.DEPTH_TEST)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    if instanced:
        attr("aPos", v, 3, 0)
        attr("aOff", off, 3, divisor)
        attr("aCol", col, 4, divisor)
        attr("aTag", tag, 2, 1, integer=True)
        if indexed:
            eb = gl.createBuffer()
            gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, eb)
            gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, idx, gl.STATIC_DRAW)
            gl.drawElementsInstanced(gl.TRIANGLES, len(idx), gl.UNSIGNED_SHORT, 0, instances)
        else:
            attr("aPos", v[idx], 3, 0)
            gl.drawArraysInstanced(gl.TRIANGLES, 0, len(idx), instances)
    else:   # the same triangles, every vertex written out; gl_InstanceID is 0, so use the tag
        per = len(idx)
        inst = np.repeat(np.arange(instances), per)
        attr("aPos", np.tile(v[idx], (instances, 1)), 3, 0)
        attr("aOff", off[inst // divisor], 3, 0)
        attr("aCol", col[inst // divisor], 4, 0)
        attr("aTag", tag[inst], 2, 0, integer=True)
        gl.drawArrays(gl.TRIANGLES, 0, per * instances)
    return gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE), gl.stats()


@pytest.mark.parametrize("instances,divisor", [(1, 1), (127, 1), (1000, 3), (2049, 2)])
@pytest.mark.parametrize("indexed", [True, False])
def test_instanced_equals_the_same_geometry_drawn_plainly(instances, divisor, indexed):
    expected, _ = _draw_instances(False, instances, divisor, indexed, use_id=False)
    for use_id in (False, True):   # gl_InstanceID must equal the instance's tag
        got, stats = _draw_instances(True, instances, divisor, indexed, use_id)
        np.testing.assert_array_equal(got, expected)
    assert np.count_nonzero(expected[..., 3]) > 0


def test_instanced_mesh_larger_than_a_vertex_chunk():
    expected, _ = _draw_instances(False, 3, 1, True, use_id=False, n_extra=1500)
    got, _ = _draw_instances(True, 3, 1, True, use_id=True, n_extra=1500)
    np.testing.assert_array_equal(got, expected)


def test_instanced_bytes_for_any_thread_count():
    one, _ = _draw_instances(True, 3001, 1, True, use_id=True, threads=1)
    three, _ = _draw_instances(True, 3001, 1, True, use_id=True, threads=3)
    np.testing.assert_array_equal(one, three)


def _draw_into_depth_stencil_fbo(samples, stencil_always):
    """The mesh into an RGBA8 + DEPTH24_STENCIL8 renderbuffer framebuffer of `samples`, resolved
    into the canvas. With the stencil test on (ALWAYS, KEEP: no effect on the bytes) the depth
    test runs sample by sample, the reference of the quad kernel."""
    gl = softgl.Context(W, H, antialias=False, threads=2)
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    for fmt, att in ((gl.RGBA8, gl.COLOR_ATTACHMENT0), (gl.DEPTH24_STENCIL8, gl.DEPTH_STENCIL_ATTACHMENT)):
        rb = gl.createRenderbuffer()
        gl.bindRenderbuffer(gl.RENDERBUFFER, rb)
        if samples == 1:
            gl.renderbufferStorage(gl.RENDERBUFFER, fmt, W, H)
        else:
            gl.renderbufferStorageMultisample(gl.RENDERBUFFER, samples, fmt, W, H)
        gl.framebufferRenderbuffer(gl.FRAMEBUFFER, att, gl.RENDERBUFFER, rb)
    prog = softgl.program(gl, VS, """#version 300 es
precision mediump float; in vec2 vUV; out vec4 o; void main() { o = vec4(fract(vUV), 0.5, 1.0); }""")
    gl.useProgram(prog)
    pos, uv = _mesh(14, seed=4)
    for name, data, k in (("aPos", pos, 3), ("aUV", uv, 2)):
        b = gl.createBuffer()
        gl.bindBuffer(gl.ARRAY_BUFFER, b)
        gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW)
        loc = gl.getAttribLocation(prog, name)
        gl.enableVertexAttribArray(loc)
        gl.vertexAttribPointer(loc, k, gl.FLOAT, False, 0, 0)
    gl.enable(gl.DEPTH_TEST)
    if stencil_always:
        gl.enable(gl.STENCIL_TEST)
        gl.stencilFunc(gl.ALWAYS, 0, 0xFF)
    gl.clearColor(0.1, 0.2, 0.3, 1)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT | gl.STENCIL_BUFFER_BIT)
    n = len(pos) // 3
    gl.drawArrays(gl.TRIANGLES, 0, n // 2)
    gl.drawArrays(gl.TRIANGLES, n // 2, n - n // 2)
    plan = gl.last_draw_plan()
    gl.bindFramebuffer(gl.READ_FRAMEBUFFER, fb)
    gl.bindFramebuffer(gl.DRAW_FRAMEBUFFER, None)
    gl.blitFramebuffer(0, 0, W, H, 0, 0, W, H, gl.COLOR_BUFFER_BIT, gl.NEAREST)
    gl.bindFramebuffer(gl.FRAMEBUFFER, None)
    return gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE), plan


@pytest.mark.parametrize("samples", [1, 4])
def test_fbo_quad_depth_equals_the_sample_by_sample_test(samples):
    quad, plan = _draw_into_depth_stencil_fbo(samples, stencil_always=False)
    reference, ref_plan = _draw_into_depth_stencil_fbo(samples, stencil_always=True)
    assert plan["quad_depth"] and plan["samples"] == samples
    assert ref_plan["quad_depth_why_not"] == "stencil_test"
    np.testing.assert_array_equal(quad, reference)
