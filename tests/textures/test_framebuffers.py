"""Framebuffer objects: completeness status codes, render-to-texture round trips (colour and depth
textures, float targets), readPixels from attachments, clear/clearBuffer, copyTexImage2D and
blitFramebuffer with scaling (ES 3.0 §4.3.3, §4.4)."""
import numpy as np
import pytest

import softgl
from helpers import draw_quad

VS = "attribute vec2 pos; varying vec2 uv; void main() { uv = pos * 0.5 + 0.5; gl_Position = vec4(pos, pos.x * 0.5, 1.0); }"
FS_UV = "precision highp float; varying vec2 uv; void main() { gl_FragColor = vec4(uv, 0.25, 1.0); }"
FS_TEX = "precision highp float; varying vec2 uv; uniform sampler2D tex; void main() { gl_FragColor = texture2D(tex, uv); }"


def color_texture(gl, w, h, internal=None, fmt=None, type_=None):
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    gl.texImage2D(gl.TEXTURE_2D, 0, internal or gl.RGBA, w, h, 0, fmt or gl.RGBA, type_ or gl.UNSIGNED_BYTE, None)
    for p in (gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER):
        gl.texParameteri(gl.TEXTURE_2D, p, gl.NEAREST)
    for p in (gl.TEXTURE_WRAP_S, gl.TEXTURE_WRAP_T):
        gl.texParameteri(gl.TEXTURE_2D, p, gl.CLAMP_TO_EDGE)
    return tex


def test_status_codes(version, quiet):
    gl = softgl.Context(4, 4, version=version, antialias=False)
    fb = gl.createFramebuffer()
    assert not gl.isFramebuffer(fb)
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    assert gl.isFramebuffer(fb) and gl.getParameter(gl.FRAMEBUFFER_BINDING) is fb
    assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == gl.FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0)
    assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == gl.FRAMEBUFFER_INCOMPLETE_ATTACHMENT   # no image
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, 4, 4, 0, gl.RGBA, gl.UNSIGNED_BYTE, None)
    assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == gl.FRAMEBUFFER_COMPLETE
    rb = gl.createRenderbuffer()
    gl.bindRenderbuffer(gl.RENDERBUFFER, rb)
    gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH_COMPONENT16, 8, 8)
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.RENDERBUFFER, rb)
    expected = gl.FRAMEBUFFER_INCOMPLETE_DIMENSIONS if version == 1 else gl.FRAMEBUFFER_COMPLETE
    assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == expected
    gl.renderbufferStorage(gl.RENDERBUFFER, gl.RGBA4, 4, 4)
    assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == gl.FRAMEBUFFER_INCOMPLETE_ATTACHMENT   # colour as depth
    gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH_COMPONENT16, 4, 4)
    stencil = gl.createRenderbuffer()
    gl.bindRenderbuffer(gl.RENDERBUFFER, stencil)
    gl.renderbufferStorage(gl.RENDERBUFFER, gl.STENCIL_INDEX8, 4, 4)
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.STENCIL_ATTACHMENT, gl.RENDERBUFFER, stencil)
    assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == gl.FRAMEBUFFER_UNSUPPORTED     # separate depth + stencil
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.STENCIL_ATTACHMENT, gl.RENDERBUFFER, None)
    assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == gl.FRAMEBUFFER_COMPLETE
    assert gl.getFramebufferAttachmentParameter(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0,
                                                gl.FRAMEBUFFER_ATTACHMENT_OBJECT_NAME) is tex
    assert gl.getFramebufferAttachmentParameter(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT,
                                                gl.FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE) == gl.RENDERBUFFER
    # Drawing into an incomplete framebuffer is INVALID_FRAMEBUFFER_OPERATION.
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, None, 0)
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.RENDERBUFFER, None)
    gl.clear(gl.COLOR_BUFFER_BIT)
    assert gl.getError() == gl.INVALID_FRAMEBUFFER_OPERATION
    gl.deleteFramebuffer(fb)
    assert gl.getParameter(gl.FRAMEBUFFER_BINDING) is None


def test_render_to_texture_equals_direct_rendering(version):
    W, H = 16, 12
    direct = softgl.Context(W, H, version=version, antialias=False)
    draw_quad(direct, softgl.program(direct, VS, FS_UV))
    expected = direct.readPixels(0, 0, W, H, direct.RGBA, direct.UNSIGNED_BYTE)

    gl = softgl.Context(W, H, version=version, antialias=False)
    tex = color_texture(gl, W, H)
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0)
    draw_quad(gl, softgl.program(gl, VS, FS_UV))
    # readPixels from the attachment, then sample the texture 1:1 into the drawing buffer.
    np.testing.assert_array_equal(gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE), expected)
    gl.bindFramebuffer(gl.FRAMEBUFFER, None)
    draw_quad(gl, softgl.program(gl, VS, FS_TEX))
    assert gl.getError() == gl.NO_ERROR
    np.testing.assert_array_equal(gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE), expected)


@pytest.mark.parametrize("version", [1, 2])
def test_depth_texture_round_trip(version):
    W = H = 8
    gl = softgl.Context(W, H, version=version, antialias=False)
    if version == 1:
        assert gl.getExtension("WEBGL_depth_texture") is not None
        internal, type_ = gl.DEPTH_COMPONENT, gl.UNSIGNED_INT
    else:
        internal, type_ = gl.DEPTH_COMPONENT24, gl.UNSIGNED_INT
    color = color_texture(gl, W, H)
    depth = color_texture(gl, W, H, internal, gl.DEPTH_COMPONENT, type_)
    assert gl.getError() == gl.NO_ERROR
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, color, 0)
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.TEXTURE_2D, depth, 0)
    assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == gl.FRAMEBUFFER_COMPLETE
    gl.enable(gl.DEPTH_TEST)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    draw_quad(gl, softgl.program(gl, VS, FS_UV))    # z_ndc = x / 2
    gl.bindFramebuffer(gl.FRAMEBUFFER, None)
    gl.disable(gl.DEPTH_TEST)
    gl.bindTexture(gl.TEXTURE_2D, depth)
    draw_quad(gl, softgl.program(gl, VS, FS_TEX))
    assert gl.getError() == gl.NO_ERROR
    got = gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE).astype(int)
    x = (np.arange(W) + 0.5) / W * 2 - 1
    window_z = (x / 2) * 0.5 + 0.5                      # ES 2.0 §2.12: depth range [0, 1]
    expected = np.floor(window_z * 255 + 0.5)
    np.testing.assert_allclose(got[..., 0], np.broadcast_to(expected, (H, W)), atol=1)
    if version == 1:   # WEBGL_depth_texture samples as luminance
        np.testing.assert_array_equal(got[..., 1], got[..., 0])


def test_float_render_target_keeps_values_outside_0_1():
    gl = softgl.Context(4, 4, antialias=False)
    assert gl.getExtension("EXT_color_buffer_float") is not None
    tex = color_texture(gl, 4, 4, gl.RGBA32F, gl.RGBA, gl.FLOAT)
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0)
    assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == gl.FRAMEBUFFER_COMPLETE
    fs = "precision highp float; varying vec2 uv; void main() { gl_FragColor = vec4(uv * 7.0 - 3.0, -0.125, 1e6); }"
    draw_quad(gl, softgl.program(gl, VS, fs))
    got = gl.readPixels(0, 0, 4, 4, gl.RGBA, gl.FLOAT)
    assert got.dtype == np.float32
    u = ((np.arange(4) + 0.5) / 4).astype(np.float32)
    np.testing.assert_allclose(got[0, :, 0], u * 7 - 3, rtol=1e-6)
    np.testing.assert_array_equal(got[..., 2], -0.125)
    np.testing.assert_array_equal(got[..., 3], 1e6)
    # Additive blending is not clamped on float targets.
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.ONE, gl.ONE)
    draw_quad(gl, softgl.program(gl, VS, fs))
    np.testing.assert_array_equal(gl.readPixels(0, 0, 4, 4, gl.RGBA, gl.FLOAT)[..., 2], -0.25)
    # RGBA/UNSIGNED_BYTE is not the read format of a float buffer.
    with pytest.warns(softgl.GLWarning):
        gl.readPixels(0, 0, 4, 4, gl.RGBA, gl.UNSIGNED_BYTE)
    assert gl.getError() == gl.INVALID_OPERATION


def test_half_float_target_rounds_to_half():
    gl = softgl.Context(1, 1, antialias=False)
    gl.getExtension("EXT_color_buffer_float")
    tex = color_texture(gl, 1, 1, gl.RGBA16F, gl.RGBA, gl.HALF_FLOAT)
    gl.bindFramebuffer(gl.FRAMEBUFFER, gl.createFramebuffer())
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0)
    gl.clearColor(0.1, 1000.3, -2.0, 70000.0)
    gl.clear(gl.COLOR_BUFFER_BIT)
    got = gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.FLOAT)[0, 0]
    # float16: 0.1 and 1000.3 round to the nearest half; 70000 overflows to infinity.
    np.testing.assert_array_equal(got, [np.float16(0.1), np.float16(1000.3), -2.0, np.inf])


def test_clear_buffer_integer_and_depth_stencil():
    gl = softgl.Context(2, 2, antialias=False)
    tex = color_texture(gl, 2, 2, gl.RGBA32I, gl.RGBA_INTEGER, gl.INT)
    rb = gl.createRenderbuffer()
    gl.bindRenderbuffer(gl.RENDERBUFFER, rb)
    gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH24_STENCIL8, 2, 2)
    gl.bindFramebuffer(gl.FRAMEBUFFER, gl.createFramebuffer())
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0)
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_STENCIL_ATTACHMENT, gl.RENDERBUFFER, rb)
    assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == gl.FRAMEBUFFER_COMPLETE
    gl.clearBufferiv(gl.COLOR, 0, [-7, 2**31 - 1, 0, -(2**31)])
    gl.clearBufferfi(gl.DEPTH_STENCIL, 0, 0.5, 3)
    assert gl.getError() == gl.NO_ERROR
    got = gl.readPixels(0, 0, 2, 2, gl.RGBA_INTEGER, gl.INT)
    np.testing.assert_array_equal(got[1, 1], [-7, 2**31 - 1, 0, -(2**31)])
    with pytest.warns(softgl.GLWarning):
        gl.clearBufferfv(gl.COLOR, 0, [1, 1, 1, 1])
    assert gl.getError() == gl.INVALID_OPERATION
    assert gl.getParameter(gl.DEPTH_BITS) == 24 and gl.getParameter(gl.STENCIL_BITS) == 8


def test_copy_tex_image_2d_from_the_drawing_buffer(version):
    gl = softgl.Context(8, 8, version=version, antialias=False, alpha=True)
    draw_quad(gl, softgl.program(gl, VS, FS_UV))
    src = gl.readPixels(0, 0, 8, 8, gl.RGBA, gl.UNSIGNED_BYTE)
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    gl.copyTexImage2D(gl.TEXTURE_2D, 0, gl.RGBA, 2, 1, 4, 4, 0)
    gl.copyTexSubImage2D(gl.TEXTURE_2D, 0, 0, 0, 7, 7, 2, 2)   # partly outside: zeros there
    assert gl.getError() == gl.NO_ERROR
    gl.bindFramebuffer(gl.FRAMEBUFFER, gl.createFramebuffer())
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0)
    got = gl.readPixels(0, 0, 4, 4, gl.RGBA, gl.UNSIGNED_BYTE)
    expected = src[1:5, 2:6].copy()
    expected[0, 0] = src[7, 7]
    expected[0, 1] = expected[1, 0] = expected[1, 1] = 0
    np.testing.assert_array_equal(got, expected)


@pytest.mark.parametrize("filt", ["NEAREST", "LINEAR"])
def test_blit_with_scaling(filt):
    gl = softgl.Context(8, 8, antialias=False)
    src = np.random.default_rng(3).integers(0, 256, (4, 4, 4), dtype=np.uint8)
    a = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, a)
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, 4, 4, 0, gl.RGBA, gl.UNSIGNED_BYTE, src)
    read = gl.createFramebuffer()
    gl.bindFramebuffer(gl.READ_FRAMEBUFFER, read)
    gl.framebufferTexture2D(gl.READ_FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, a, 0)
    gl.bindFramebuffer(gl.DRAW_FRAMEBUFFER, None)
    gl.blitFramebuffer(0, 0, 4, 4, 0, 0, 8, 8, gl.COLOR_BUFFER_BIT, getattr(gl, filt))
    assert gl.getError() == gl.NO_ERROR
    gl.bindFramebuffer(gl.READ_FRAMEBUFFER, None)
    got = gl.readPixels(0, 0, 8, 8, gl.RGBA, gl.UNSIGNED_BYTE)
    if filt == "NEAREST":
        expected = np.repeat(np.repeat(src, 2, 0), 2, 1)
    else:
        # ES 3.0 §4.3.3: destination pixel centres map to source (x + 0.5) / 2; bilinear, clamped.
        c = (np.arange(8) + 0.5) / 2 - 0.5
        i0 = np.floor(c).astype(int)
        f = c - i0
        i0c, i1c = np.clip(i0, 0, 3), np.clip(i0 + 1, 0, 3)
        s = src.astype(np.float64) / 255
        rows = (1 - f)[:, None, None] * s[i0c] + f[:, None, None] * s[i1c]
        full = (1 - f)[None, :, None] * rows[:, i0c] + f[None, :, None] * rows[:, i1c]
        expected = np.floor(full * 255 + 0.5)
    np.testing.assert_allclose(got, expected, atol=1 if filt == "LINEAR" else 0)


def test_multisample_renderbuffer_resolves_by_blit():
    gl = softgl.Context(8, 8, antialias=False)
    rb = gl.createRenderbuffer()
    gl.bindRenderbuffer(gl.RENDERBUFFER, rb)
    gl.renderbufferStorageMultisample(gl.RENDERBUFFER, 4, gl.RGBA8, 8, 8)
    assert gl.getRenderbufferParameter(gl.RENDERBUFFER, gl.RENDERBUFFER_SAMPLES) == 4
    ms = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, ms)
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.RENDERBUFFER, rb)
    assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == gl.FRAMEBUFFER_COMPLETE
    # A triangle covering half the target: edge pixels get partial coverage.
    prog = softgl.program(gl, "attribute vec2 pos; void main() { gl_Position = vec4(pos, 0.0, 1.0); }",
                          "precision mediump float; void main() { gl_FragColor = vec4(1.0); }")
    gl.useProgram(prog)
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.bufferData(gl.ARRAY_BUFFER, np.array([-1, -1, 1, -1, -1, 1], np.float32), gl.STATIC_DRAW)
    gl.enableVertexAttribArray(0)
    gl.vertexAttribPointer(0, 2, gl.FLOAT, False, 0, 0)
    gl.drawArrays(gl.TRIANGLES, 0, 3)
    gl.bindFramebuffer(gl.READ_FRAMEBUFFER, ms)
    gl.bindFramebuffer(gl.DRAW_FRAMEBUFFER, None)
    gl.blitFramebuffer(0, 0, 8, 8, 0, 0, 8, 8, gl.COLOR_BUFFER_BIT, gl.NEAREST)
    assert gl.getError() == gl.NO_ERROR
    gl.bindFramebuffer(gl.READ_FRAMEBUFFER, None)
    got = gl.readPixels(0, 0, 8, 8, gl.RGBA, gl.UNSIGNED_BYTE)[..., 0]
    assert got[0, 0] == 255 and got[7, 7] == 0
    assert len(set(np.diag(got[::-1]).tolist()) - {0, 255}) > 0   # resolved partial coverage on the edge


def test_feedback_loop_is_an_error(version, quiet):
    gl = softgl.Context(4, 4, version=version, antialias=False)
    tex = color_texture(gl, 4, 4)
    gl.bindFramebuffer(gl.FRAMEBUFFER, gl.createFramebuffer())
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0)
    draw_quad(gl, softgl.program(gl, VS, FS_TEX))
    assert gl.getError() == gl.INVALID_OPERATION
