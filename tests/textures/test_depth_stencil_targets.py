"""Depth and stencil between the drawing buffer and framebuffer objects: blitFramebuffer of
DEPTH/STENCIL_BUFFER_BIT both ways when the formats match (ES 3.0 §4.3.3), and WebGL's
front/back stencil consistency rule checked against the bound framebuffer's stencil bits
(WebGL 1.0 §6.11)."""
import numpy as np
import pytest

import softgl

VS = "attribute vec2 pos; uniform float z; void main() { gl_Position = vec4(pos, z, 1.0); }"
FS = "precision mediump float; uniform vec4 color; void main() { gl_FragColor = color; }"
TRI = np.array([-1, -1, 3, -1, -1, 3], np.float32)


def setup_program(gl):
    prog = softgl.program(gl, VS, FS)
    gl.useProgram(prog)
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.bufferData(gl.ARRAY_BUFFER, TRI, gl.STATIC_DRAW)
    gl.enableVertexAttribArray(0)
    gl.vertexAttribPointer(0, 2, gl.FLOAT, False, 0, 0)
    return prog


def draw(gl, prog, z, color):
    gl.uniform1f(gl.getUniformLocation(prog, "z"), z)
    gl.uniform4f(gl.getUniformLocation(prog, "color"), *color)
    gl.drawArrays(gl.TRIANGLES, 0, 3)


def fbo(gl, w, h, depth_format):
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    color = gl.createRenderbuffer()
    gl.bindRenderbuffer(gl.RENDERBUFFER, color)
    gl.renderbufferStorage(gl.RENDERBUFFER, gl.RGBA8, w, h)
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.RENDERBUFFER, color)
    ds = gl.createRenderbuffer()
    gl.bindRenderbuffer(gl.RENDERBUFFER, ds)
    gl.renderbufferStorage(gl.RENDERBUFFER, depth_format, w, h)
    point = gl.DEPTH_STENCIL_ATTACHMENT if depth_format == gl.DEPTH24_STENCIL8 else gl.DEPTH_ATTACHMENT
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, point, gl.RENDERBUFFER, ds)
    assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == gl.FRAMEBUFFER_COMPLETE
    return fb


def test_blit_depth_from_drawing_buffer_to_fbo_and_back():
    """Depth cleared to 0.25 in the drawing buffer, blitted into an FBO: a triangle at window
    z 0.5 then fails LESS there, one at z 0.125 passes (z_window = (z_ndc + 1) / 2)."""
    gl = softgl.Context(4, 4, antialias=False, preserveDrawingBuffer=True)
    prog = setup_program(gl)
    gl.clearDepth(0.25)
    gl.clear(gl.DEPTH_BUFFER_BIT)
    fb = fbo(gl, 4, 4, gl.DEPTH_COMPONENT24)
    gl.clearDepth(1.0)
    gl.clearColor(0, 0, 0, 1)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    gl.bindFramebuffer(gl.READ_FRAMEBUFFER, None)
    gl.blitFramebuffer(0, 0, 4, 4, 0, 0, 4, 4, gl.DEPTH_BUFFER_BIT, gl.NEAREST)
    assert gl.getError() == gl.NO_ERROR
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    gl.enable(gl.DEPTH_TEST)
    draw(gl, prog, 0.0, (1, 0, 0, 1))           # window z 0.5 > 0.25: fails
    assert np.all(gl.readPixels(0, 0, 4, 4, gl.RGBA, gl.UNSIGNED_BYTE) == (0, 0, 0, 255))
    draw(gl, prog, -0.75, (0, 1, 0, 1))         # window z 0.125 < 0.25: passes, writes 0.125
    assert np.all(gl.readPixels(0, 0, 4, 4, gl.RGBA, gl.UNSIGNED_BYTE) == (0, 255, 0, 255))
    # Back into the drawing buffer (which holds 0.25): the FBO's 0.125 arrives.
    gl.bindFramebuffer(gl.DRAW_FRAMEBUFFER, None)
    gl.bindFramebuffer(gl.READ_FRAMEBUFFER, fb)
    gl.blitFramebuffer(0, 0, 4, 4, 0, 0, 4, 4, gl.DEPTH_BUFFER_BIT, gl.NEAREST)
    assert gl.getError() == gl.NO_ERROR
    gl.bindFramebuffer(gl.FRAMEBUFFER, None)
    gl.clearColor(0, 0, 0, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    draw(gl, prog, -0.6, (0, 0, 1, 1))          # window z 0.2: fails against 0.125 (passed against 0.25)
    assert np.all(gl.readPixels(0, 0, 4, 4, gl.RGBA, gl.UNSIGNED_BYTE) == (0, 0, 0, 255))
    draw(gl, prog, -0.8, (0, 0, 1, 1))          # window z 0.1 passes
    assert np.all(gl.readPixels(0, 0, 4, 4, gl.RGBA, gl.UNSIGNED_BYTE) == (0, 0, 255, 255))


def test_blit_stencil_with_scaling_from_drawing_buffer():
    gl = softgl.Context(4, 4, antialias=False, stencil=True, preserveDrawingBuffer=True)
    prog = setup_program(gl)
    # Stencil of the drawing buffer: left half 1, right half 2.
    gl.enable(gl.SCISSOR_TEST)
    for x, value in ((0, 1), (2, 2)):
        gl.scissor(x, 0, 2, 4)
        gl.clearStencil(value)
        gl.clear(gl.STENCIL_BUFFER_BIT)
    gl.disable(gl.SCISSOR_TEST)
    fb = fbo(gl, 2, 2, gl.DEPTH24_STENCIL8)
    gl.clearColor(0, 0, 0, 1)
    gl.clearStencil(0)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.STENCIL_BUFFER_BIT)
    gl.bindFramebuffer(gl.READ_FRAMEBUFFER, None)
    gl.blitFramebuffer(0, 0, 4, 4, 0, 0, 2, 2, gl.STENCIL_BUFFER_BIT, gl.NEAREST)   # 2:1 down
    assert gl.getError() == gl.NO_ERROR
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    gl.viewport(0, 0, 2, 2)
    gl.enable(gl.STENCIL_TEST)
    gl.stencilFunc(gl.EQUAL, 2, 0xFF)
    draw(gl, prog, 0.0, (1, 1, 1, 1))
    px = gl.readPixels(0, 0, 2, 2, gl.RGBA, gl.UNSIGNED_BYTE)
    # Destination x = 0 samples source x = 1 (stencil 1); x = 1 samples x = 3 (stencil 2).
    assert np.all(px[:, 0] == (0, 0, 0, 255)) and np.all(px[:, 1] == (255, 255, 255, 255))


def test_blit_depth_format_mismatch(quiet):
    gl = softgl.Context(4, 4, antialias=False)
    fbo(gl, 4, 4, gl.DEPTH_COMPONENT16)
    gl.bindFramebuffer(gl.READ_FRAMEBUFFER, None)
    gl.blitFramebuffer(0, 0, 4, 4, 0, 0, 4, 4, gl.DEPTH_BUFFER_BIT, gl.NEAREST)
    assert gl.getError() == gl.INVALID_OPERATION      # 24-bit drawing buffer vs DEPTH_COMPONENT16


def test_stencil_consistency_uses_the_bound_framebuffer(quiet):
    """Different front/back stencil masks are an error only when the draw framebuffer has
    stencil bits: a drawing buffer without stencil, an FBO with DEPTH24_STENCIL8."""
    for version in (1, 2):
        gl = softgl.Context(4, 4, version=version, antialias=False, stencil=False)
        prog = setup_program(gl)
        gl.stencilMaskSeparate(gl.BACK, 0x0F)
        draw(gl, prog, 0.0, (1, 0, 0, 1))
        assert gl.getError() == gl.NO_ERROR                # no stencil buffer: masks compare as 0
        fb = gl.createFramebuffer()
        gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
        tex = gl.createTexture()
        gl.bindTexture(gl.TEXTURE_2D, tex)
        gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, 4, 4, 0, gl.RGBA, gl.UNSIGNED_BYTE, None)
        gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0)
        draw(gl, prog, 0.0, (1, 0, 0, 1))
        assert gl.getError() == gl.NO_ERROR                # FBO without stencil
        rb = gl.createRenderbuffer()
        gl.bindRenderbuffer(gl.RENDERBUFFER, rb)
        gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH_STENCIL, 4, 4)
        gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_STENCIL_ATTACHMENT, gl.RENDERBUFFER, rb)
        assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == gl.FRAMEBUFFER_COMPLETE
        draw(gl, prog, 0.0, (1, 0, 0, 1))
        assert gl.getError() == gl.INVALID_OPERATION       # 8 stencil bits: 0xFF vs 0x0F differ
        gl.stencilMaskSeparate(gl.BACK, 0xFF)
        draw(gl, prog, 0.0, (1, 0, 0, 1))
        assert gl.getError() == gl.NO_ERROR
        # Back on a drawing buffer without stencil, differing masks are fine again.
        gl.stencilMaskSeparate(gl.BACK, 0x0F)
        gl.bindFramebuffer(gl.FRAMEBUFFER, None)
        draw(gl, prog, 0.0, (1, 0, 0, 1))
        assert gl.getError() == gl.NO_ERROR
