"""Depth-only draws (draw plan `depth_only`: docs/architecture.md, "Fast paths"): when no colour
buffer receives the shader's colour (colour mask all false, a framebuffer object without a colour
attachment, drawBuffers all NONE) and the tests run before shading, the fragment shader does not
run (a fragment shader has no other effect: GLSL ES 3.00 §3.8 ... no side effects), and the depth
buffer holds the same words as when the shader runs and colour is written."""
import numpy as np
import pytest

from softgl import _core
from test_draw_plan import DISCARD_FS, SHADED_FS, SIZE, context, draw


def depth_draw(fs=SHADED_FS, setup=None, antialias=False):
    """4 random overlapping triangles with the LESS depth test; returns (gl, plan, stats)."""
    gl, _ = context(fs, n=12, antialias=antialias)
    gl.enable(gl.DEPTH_TEST)
    gl.depthFunc(gl.LESS)
    if setup:
        setup(gl)
    gl.clear(gl.DEPTH_BUFFER_BIT | gl.COLOR_BUFFER_BIT)
    gl.stats(reset=True)
    plan = draw(gl)
    return gl, plan, gl.stats()


@pytest.mark.parametrize("antialias", [False, True])
def test_colour_mask_off_takes_depth_only_and_keeps_the_depth(antialias):
    gl, plan, stats = depth_draw(antialias=antialias)
    assert plan["writes_color"] and not plan["depth_only"] and plan["depth_only_why_not"] == "writes_color"
    assert stats["fragments_shaded"] > 0
    shaded = _core.testing.read_depth(gl)
    assert len(np.unique(shaded)) > 3   # several triangles' depths

    gl2, plan2, stats2 = depth_draw(setup=lambda gl: gl.colorMask(False, False, False, False), antialias=antialias)
    assert not plan2["writes_color"] and plan2["depth_only"] and plan2["depth_only_why_not"] is None
    assert stats2["fragments_shaded"] == 0 and stats2["quads"] > 0
    np.testing.assert_array_equal(_core.testing.read_depth(gl2), shaded)


def test_discard_or_late_tests_shade():
    # The shader may discard: its fragments must run to know which survive.
    gl, plan, stats = depth_draw(DISCARD_FS, setup=lambda gl: gl.colorMask(False, False, False, False))
    assert not plan["writes_color"] and not plan["depth_only"] and plan["depth_only_why_not"] == "discard"
    assert stats["fragments_shaded"] > 0


def framebuffer_without_colour(gl, with_colour_texture=False):
    depth = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, depth)
    gl.texStorage2D(gl.TEXTURE_2D, 1, gl.DEPTH24_STENCIL8, SIZE, SIZE)
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.DEPTH_STENCIL_ATTACHMENT, gl.TEXTURE_2D, depth, 0)
    if with_colour_texture:
        color = gl.createTexture()
        gl.bindTexture(gl.TEXTURE_2D, color)
        gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA8, SIZE, SIZE)
        gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, color, 0)
        gl.drawBuffers([gl.NONE])
    assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == gl.FRAMEBUFFER_COMPLETE
    return fb


def test_framebuffer_without_colour_buffer_takes_depth_only():
    # A shadow map's pass: a depth texture only (or a colour attachment drawBuffers leaves out).
    # Its depth, blitted to the canvas, equals the canvas's own depth drawn with colour.
    reference = _core.testing.read_depth(depth_draw()[0])
    for with_colour_texture in (False, True):
        fb_holder = {}

        def setup(gl):
            fb_holder["fb"] = framebuffer_without_colour(gl, with_colour_texture)

        gl, plan, stats = depth_draw(setup=setup)
        assert plan["target"] == "framebuffer_object"
        assert not plan["writes_color"] and plan["depth_only"], plan["text"]
        assert stats["fragments_shaded"] == 0 and stats["samples_written"] == 0
        gl.bindFramebuffer(gl.READ_FRAMEBUFFER, fb_holder["fb"])
        gl.bindFramebuffer(gl.DRAW_FRAMEBUFFER, None)
        gl.blitFramebuffer(0, 0, SIZE, SIZE, 0, 0, SIZE, SIZE, gl.DEPTH_BUFFER_BIT, gl.NEAREST)
        assert gl.getError() == gl.NO_ERROR
        np.testing.assert_array_equal(_core.testing.read_depth(gl), reference)
