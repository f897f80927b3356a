"""Multiple render targets: WebGL 2 drawBuffers with `layout(location = n) out`, WebGL 1
WEBGL_draw_buffers with gl_FragData[n] and the gl_FragColor broadcast, DRAW_BUFFERi state,
clearBuffer per draw buffer, blending per buffer (ES 3.0 §4.2.1, §4.1.7; EXT_draw_buffers).

Expected bytes are hand computed: a unorm8 channel stores round(255 * clamp(v, 0, 1))."""
import numpy as np
import pytest

import softgl

TRI = np.array([-1, -1, 3, -1, -1, 3], np.float32)   # one triangle covering the viewport

VS3 = "#version 300 es\nin vec2 pos; void main() { gl_Position = vec4(pos, 0.0, 1.0); }"
VS1 = "attribute vec2 pos; void main() { gl_Position = vec4(pos, 0.0, 1.0); }"

FS3 = """#version 300 es
precision highp float;
layout(location = 0) out vec4 o0;
layout(location = 1) out vec4 o1;
layout(location = 2) out vec4 o2;
void main() {
    o0 = vec4(0.25, 0.5, 0.75, 1.0);
    o1 = vec4(1.0, 0.0, 0.0, 0.5);
    o2 = vec4(0.0, 1.0, 0.2, 1.0);
}
"""
EXPECTED = [(64, 128, 191, 255), (255, 0, 0, 128), (0, 255, 51, 255)]
CLEAR = (0.0, 0.0, 1.0, 1.0)


def draw(gl, prog):
    gl.useProgram(prog)
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.bufferData(gl.ARRAY_BUFFER, TRI, gl.STATIC_DRAW)
    loc = gl.getAttribLocation(prog, "pos")
    gl.enableVertexAttribArray(loc)
    gl.vertexAttribPointer(loc, 2, gl.FLOAT, False, 0, 0)
    gl.drawArrays(gl.TRIANGLES, 0, 3)


def mrt_framebuffer(gl, n, size=4, internal=None, fmt=None, type_=None, attach=None):
    """A bound framebuffer with n colour textures (COLOR_ATTACHMENT0..n-1), cleared to CLEAR."""
    attach = attach or (lambda i: gl.COLOR_ATTACHMENT0 + i)
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    texs = []
    for i in range(n):
        t = gl.createTexture()
        gl.bindTexture(gl.TEXTURE_2D, t)
        gl.texImage2D(gl.TEXTURE_2D, 0, internal or gl.RGBA, size, size, 0, fmt or gl.RGBA,
                      type_ or gl.UNSIGNED_BYTE, None)
        gl.framebufferTexture2D(gl.FRAMEBUFFER, attach(i), gl.TEXTURE_2D, t, 0)
        texs.append(t)
    assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == gl.FRAMEBUFFER_COMPLETE
    return fb, texs


def read_attachment(gl, tex, size=4, type_=None):
    """The texture's pixels, through a second framebuffer (works in WebGL 1 and 2)."""
    current = gl.getParameter(gl.FRAMEBUFFER_BINDING)
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0)
    px = gl.readPixels(0, 0, size, size, gl.RGBA, type_ or gl.UNSIGNED_BYTE)
    gl.bindFramebuffer(gl.FRAMEBUFFER, current)
    return px


def clear_all(gl, n):
    gl.drawBuffers([gl.COLOR_ATTACHMENT0 + i for i in range(n)])
    gl.clearColor(*CLEAR)
    gl.clear(gl.COLOR_BUFFER_BIT)


def test_limits_and_default_state():
    gl = softgl.Context(4, 4, antialias=False)
    assert gl.getParameter(gl.MAX_DRAW_BUFFERS) == 8
    assert gl.getParameter(gl.MAX_COLOR_ATTACHMENTS) == 8
    # The drawing buffer: BACK, then NONE for the others (ES 3.0 table 6.13).
    assert [gl.getParameter(gl.DRAW_BUFFER0 + i) for i in range(8)] == [gl.BACK] + [gl.NONE] * 7
    mrt_framebuffer(gl, 1)
    assert [gl.getParameter(gl.DRAW_BUFFER0 + i) for i in range(8)] == [gl.COLOR_ATTACHMENT0] + [gl.NONE] * 7
    gl.drawBuffers([gl.NONE, gl.COLOR_ATTACHMENT1])
    assert [gl.getParameter(gl.DRAW_BUFFER0 + i) for i in range(3)] == [gl.NONE, gl.COLOR_ATTACHMENT1, gl.NONE]
    assert gl.getError() == gl.NO_ERROR


@pytest.mark.parametrize("buffers, error", [
    (lambda gl: [gl.COLOR_ATTACHMENT1], "INVALID_OPERATION"),             # buffer i must be COLOR_ATTACHMENTi
    (lambda gl: [gl.BACK], "INVALID_OPERATION"),                          # BACK is for the drawing buffer
    (lambda gl: [gl.NONE] * 9, "INVALID_VALUE"),                          # more than MAX_DRAW_BUFFERS
    (lambda gl: [gl.TEXTURE_2D], "INVALID_ENUM"),
])
def test_draw_buffers_errors_on_framebuffers(buffers, error, quiet):
    gl = softgl.Context(4, 4, antialias=False)
    mrt_framebuffer(gl, 2)
    gl.drawBuffers([gl.COLOR_ATTACHMENT0, gl.COLOR_ATTACHMENT1])
    gl.drawBuffers(buffers(gl))
    assert gl.getError() == getattr(gl, error)
    # Nothing changed.
    assert gl.getParameter(gl.DRAW_BUFFER1) == gl.COLOR_ATTACHMENT1


def test_draw_buffers_errors_on_drawing_buffer(quiet):
    gl = softgl.Context(4, 4, antialias=False)
    gl.drawBuffers([gl.COLOR_ATTACHMENT0])
    assert gl.getError() == gl.INVALID_OPERATION
    gl.drawBuffers([gl.BACK, gl.NONE])
    assert gl.getError() == gl.INVALID_OPERATION
    assert gl.getParameter(gl.DRAW_BUFFER0) == gl.BACK


def test_drawing_buffer_none_writes_no_colour():
    gl = softgl.Context(4, 4, antialias=False, preserveDrawingBuffer=True)
    gl.clearColor(0, 0, 1, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.drawBuffers([gl.NONE])
    assert gl.getParameter(gl.DRAW_BUFFER0) == gl.NONE
    gl.clearColor(1, 0, 0, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)                     # no colour buffer: nothing cleared
    gl.clearBufferfv(gl.COLOR, 0, [1, 1, 0, 1])
    draw(gl, softgl.program(gl, VS3, FS3))
    assert gl.getError() == gl.NO_ERROR
    assert np.all(gl.readPixels(0, 0, 4, 4, gl.RGBA, gl.UNSIGNED_BYTE) == (0, 0, 255, 255))
    gl.drawBuffers([gl.BACK])
    draw(gl, softgl.program(gl, VS3, FS3))
    assert np.all(gl.readPixels(0, 0, 4, 4, gl.RGBA, gl.UNSIGNED_BYTE) == EXPECTED[0])


def test_three_outputs_reach_their_attachments():
    gl = softgl.Context(4, 4, antialias=False)
    _, texs = mrt_framebuffer(gl, 3)
    clear_all(gl, 3)
    draw(gl, softgl.program(gl, VS3, FS3))
    assert gl.getError() == gl.NO_ERROR
    for tex, want in zip(texs, EXPECTED):
        assert np.all(read_attachment(gl, tex) == want)
    # readBuffer picks the attachment readPixels reads.
    gl.readBuffer(gl.COLOR_ATTACHMENT2)
    assert np.all(gl.readPixels(0, 0, 4, 4, gl.RGBA, gl.UNSIGNED_BYTE) == EXPECTED[2])


def test_none_draw_buffer_leaves_its_attachment():
    gl = softgl.Context(4, 4, antialias=False)
    _, texs = mrt_framebuffer(gl, 3)
    clear_all(gl, 3)
    gl.drawBuffers([gl.COLOR_ATTACHMENT0, gl.NONE, gl.COLOR_ATTACHMENT2])
    draw(gl, softgl.program(gl, VS3, FS3))
    assert np.all(read_attachment(gl, texs[0]) == EXPECTED[0])
    assert np.all(read_attachment(gl, texs[1]) == (0, 0, 255, 255))   # still the clear colour
    assert np.all(read_attachment(gl, texs[2]) == EXPECTED[2])
    # Outputs beyond the draw buffers the shader writes: output 1 only to attachment 1.
    gl.drawBuffers([gl.NONE, gl.COLOR_ATTACHMENT1])
    gl.clearColor(0, 0, 0, 0)
    gl.clear(gl.COLOR_BUFFER_BIT)                      # clears attachment 1 only
    draw(gl, softgl.program(gl, VS3, FS3))
    assert np.all(read_attachment(gl, texs[0]) == EXPECTED[0])
    assert np.all(read_attachment(gl, texs[1]) == EXPECTED[1])


def test_array_output_takes_consecutive_locations():
    gl = softgl.Context(4, 4, antialias=False)
    _, texs = mrt_framebuffer(gl, 3)
    clear_all(gl, 3)
    fs = """#version 300 es
precision highp float;
layout(location = 1) out vec4 o[2];
void main() { o[0] = vec4(0.2, 0.4, 0.6, 0.8); o[1] = vec4(1.0); }
"""
    gl.drawBuffers([gl.NONE, gl.COLOR_ATTACHMENT1, gl.COLOR_ATTACHMENT2])   # location 0 is not written
    draw(gl, softgl.program(gl, VS3, fs))
    assert np.all(read_attachment(gl, texs[0]) == (0, 0, 255, 255))
    assert np.all(read_attachment(gl, texs[1]) == (51, 102, 153, 204))
    assert np.all(read_attachment(gl, texs[2]) == (255, 255, 255, 255))


def test_clear_buffer_per_draw_buffer():
    gl = softgl.Context(4, 4, antialias=False)
    _, texs = mrt_framebuffer(gl, 3)
    clear_all(gl, 3)
    gl.drawBuffers([gl.COLOR_ATTACHMENT0, gl.NONE, gl.COLOR_ATTACHMENT2])
    gl.clearBufferfv(gl.COLOR, 2, [0.5, 0.25, 0.0, 1.0])
    gl.clearBufferfv(gl.COLOR, 1, [1, 1, 1, 1])       # draw buffer 1 is NONE: nothing happens
    assert gl.getError() == gl.NO_ERROR
    assert np.all(read_attachment(gl, texs[0]) == (0, 0, 255, 255))
    assert np.all(read_attachment(gl, texs[1]) == (0, 0, 255, 255))
    assert np.all(read_attachment(gl, texs[2]) == (128, 64, 0, 255))


def test_blending_per_buffer_clamps_by_format():
    """One blend state, two formats: RGBA8 clamps source, destination and constant to [0, 1],
    RGBA32F blends unclamped (ES 3.0 §4.1.7), including blendColor."""
    gl = softgl.Context(2, 2, antialias=False)
    assert gl.getExtension("EXT_color_buffer_float") is not None
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    texs = []
    for i, internal in enumerate([gl.RGBA8, gl.RGBA32F]):
        t = gl.createTexture()
        gl.bindTexture(gl.TEXTURE_2D, t)
        gl.texStorage2D(gl.TEXTURE_2D, 1, internal, 2, 2)
        gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0 + i, gl.TEXTURE_2D, t, 0)
        texs.append(t)
    gl.drawBuffers([gl.COLOR_ATTACHMENT0, gl.COLOR_ATTACHMENT1])
    gl.clearBufferfv(gl.COLOR, 0, [0.5, 0.5, 0.5, 0.5])
    gl.clearBufferfv(gl.COLOR, 1, [0.5, 2.0, -1.0, 0.5])
    fs = """#version 300 es
precision highp float;
layout(location = 0) out vec4 o0;
layout(location = 1) out vec4 o1;
void main() { o0 = vec4(1.5, 0.25, -0.5, 0.75); o1 = vec4(1.5, 0.25, -0.5, 0.75); }
"""
    gl.enable(gl.BLEND)
    gl.blendColor(2.0, 0.5, -1.0, 0.25)
    gl.blendFuncSeparate(gl.CONSTANT_COLOR, gl.ONE, gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)
    assert np.allclose(gl.getParameter(gl.BLEND_COLOR), [2.0, 0.5, -1.0, 0.25])   # WebGL 2: not clamped
    draw(gl, softgl.program(gl, VS3, fs))
    assert gl.getError() == gl.NO_ERROR
    src = np.array([1.5, 0.25, -0.5, 0.75])
    k = np.array([2.0, 0.5, -1.0])
    # RGBA8: everything clamped. rgb = s * k + d; a = s_a * s_a + d_a * (1 - s_a).
    s8, k8, d8 = np.clip(src, 0, 1), np.clip(k, 0, 1), np.array([128, 128, 128, 128]) / 255
    rgb8 = s8[:3] * k8 + d8[:3]
    a8 = s8[3] * s8[3] + d8[3] * (1 - s8[3])
    want8 = np.round(np.clip(np.append(rgb8, a8), 0, 1) * 255)
    got8 = gl.readPixels(0, 0, 2, 2, gl.RGBA, gl.UNSIGNED_BYTE)
    assert np.all(got8 == want8), (got8[0, 0], want8)
    # RGBA32F: nothing clamped; float32 arithmetic agrees with float64 to float32 rounding.
    d32 = np.array([0.5, 2.0, -1.0, 0.5])
    rgb32 = src[:3] * k + d32[:3]
    a32 = src[3] * src[3] + d32[3] * (1 - src[3])
    gl.readBuffer(gl.COLOR_ATTACHMENT1)
    got32 = gl.readPixels(0, 0, 2, 2, gl.RGBA, gl.FLOAT)
    assert np.allclose(got32, np.append(rgb32, a32), rtol=1e-6, atol=1e-7), got32[0, 0]
    assert np.allclose(np.append(rgb32, a32), [3.5, 2.125, -0.5, 0.6875])   # by hand


def test_blend_color_clamp_in_webgl1():
    gl = softgl.Context(1, 1, version=1, antialias=False)
    gl.blendColor(2.0, -1.0, 0.5, 1.5)
    assert np.allclose(gl.getParameter(gl.BLEND_COLOR), [1.0, 0.0, 0.5, 1.0])   # ES 2.0 §4.1.6
    # EXT_color_buffer_half_float: blendColor no longer clamps its arguments on input.
    assert gl.getExtension("EXT_color_buffer_half_float") is not None
    gl.blendColor(2.0, -1.0, 0.5, 1.5)
    assert np.allclose(gl.getParameter(gl.BLEND_COLOR), [2.0, -1.0, 0.5, 1.5])


# ---------------------------------------------------------------------------- WebGL 1 extension

FS1_DATA = """#extension GL_EXT_draw_buffers : require
precision highp float;
void main() {
    gl_FragData[0] = vec4(0.25, 0.5, 0.75, 1.0);
    gl_FragData[1] = vec4(1.0, 0.0, 0.0, 0.5);
    gl_FragData[2] = vec4(0.0, 1.0, 0.2, 1.0);
}
"""


def test_webgl1_without_extension(quiet):
    gl = softgl.Context(4, 4, version=1, antialias=False)
    assert "WEBGL_draw_buffers" in gl.getSupportedExtensions()
    assert gl.getParameter(0x8824) is None and gl.getError() == gl.INVALID_ENUM   # MAX_DRAW_BUFFERS_WEBGL
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    t = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, t)
    gl.framebufferTexture2D(gl.FRAMEBUFFER, 0x8CE1, gl.TEXTURE_2D, t, 0)   # COLOR_ATTACHMENT1
    assert gl.getError() == gl.INVALID_ENUM
    assert not hasattr(gl, "drawBuffers")


def test_webgl1_extension_object_and_state():
    gl = softgl.Context(4, 4, version=1, antialias=False)
    ext = gl.getExtension("WEBGL_draw_buffers")
    assert ext is gl.getExtension("WEBGL_draw_buffers")
    assert ext.COLOR_ATTACHMENT0_WEBGL == 0x8CE0 and ext.COLOR_ATTACHMENT15_WEBGL == 0x8CEF
    assert ext.DRAW_BUFFER0_WEBGL == 0x8825 and ext.DRAW_BUFFER15_WEBGL == 0x8834
    assert ext.MAX_COLOR_ATTACHMENTS_WEBGL == 0x8CDF and ext.MAX_DRAW_BUFFERS_WEBGL == 0x8824
    assert gl.getParameter(ext.MAX_DRAW_BUFFERS_WEBGL) == 8
    assert gl.getParameter(ext.MAX_COLOR_ATTACHMENTS_WEBGL) == 8
    assert gl.getParameter(ext.DRAW_BUFFER0_WEBGL) == gl.BACK
    _, texs = mrt_framebuffer(gl, 3, attach=lambda i: ext.COLOR_ATTACHMENT0_WEBGL + i)
    ext.drawBuffersWEBGL([ext.COLOR_ATTACHMENT0_WEBGL, ext.COLOR_ATTACHMENT1_WEBGL, gl.NONE])
    assert [gl.getParameter(ext.DRAW_BUFFER0_WEBGL + i) for i in range(4)] == [0x8CE0, 0x8CE1, gl.NONE, gl.NONE]
    assert gl.getError() == gl.NO_ERROR


def test_webgl1_frag_data():
    gl = softgl.Context(4, 4, version=1, antialias=False)
    ext = gl.getExtension("WEBGL_draw_buffers")
    _, texs = mrt_framebuffer(gl, 3, attach=lambda i: ext.COLOR_ATTACHMENT0_WEBGL + i)
    ext.drawBuffersWEBGL([ext.COLOR_ATTACHMENT0_WEBGL + i for i in range(3)])
    gl.clearColor(*CLEAR)
    gl.clear(gl.COLOR_BUFFER_BIT)
    draw(gl, softgl.program(gl, VS1, FS1_DATA))
    assert gl.getError() == gl.NO_ERROR
    for tex, want in zip(texs, EXPECTED):
        assert np.all(read_attachment(gl, tex) == want)


@pytest.mark.parametrize("directive, broadcast", [(True, True), (False, False)])
def test_webgl1_frag_color_broadcast(directive, broadcast):
    """WEBGL_draw_buffers: with `#extension GL_EXT_draw_buffers` gl_FragColor goes to every draw
    buffer; without it, to draw buffer 0 only."""
    gl = softgl.Context(4, 4, version=1, antialias=False)
    ext = gl.getExtension("WEBGL_draw_buffers")
    _, texs = mrt_framebuffer(gl, 3, attach=lambda i: ext.COLOR_ATTACHMENT0_WEBGL + i)
    ext.drawBuffersWEBGL([ext.COLOR_ATTACHMENT0_WEBGL + i for i in range(3)])
    gl.clearColor(*CLEAR)
    gl.clear(gl.COLOR_BUFFER_BIT)
    fs = ("#extension GL_EXT_draw_buffers : enable\n" if directive else "") + \
        "precision mediump float; void main() { gl_FragColor = vec4(1.0, 0.5, 0.0, 1.0); }"
    draw(gl, softgl.program(gl, VS1, fs))
    assert np.all(read_attachment(gl, texs[0]) == (255, 128, 0, 255))
    for tex in texs[1:]:
        want = (255, 128, 0, 255) if broadcast else (0, 0, 255, 255)
        assert np.all(read_attachment(gl, tex) == want)


def test_uniform_only_and_varying_outputs_agree():
    """Outputs of a shader run on one quad and broadcast (uniform-only) equal per-lane shading."""
    gl = softgl.Context(8, 8, antialias=False)
    _, texs = mrt_framebuffer(gl, 2, size=8)
    gl.drawBuffers([gl.COLOR_ATTACHMENT0, gl.COLOR_ATTACHMENT1])
    fs = """#version 300 es
precision highp float;
layout(location = 0) out vec4 o0;
layout(location = 1) out vec4 o1;
void main() { o0 = vec4(gl_FragCoord.xy / 8.0, 0.0, 1.0); o1 = vec4(0.0, 0.0, gl_FragCoord.x / 8.0, 1.0); }
"""
    draw(gl, softgl.program(gl, VS3, fs))
    x = (np.arange(8) + 0.5) / 8
    a = read_attachment(gl, texs[0], 8)
    b = read_attachment(gl, texs[1], 8)
    assert np.all(a[:, :, 0] == np.round(x * 255)[None, :])
    assert np.all(a[:, :, 1] == np.round(x * 255)[:, None])
    assert np.all(b[:, :, 2] == np.round(x * 255)[None, :])
