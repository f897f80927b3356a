"""SOFTGL_introspection: gl.fragments(x, y) on hand-built scenes lists exactly the fragments
expected, with the tests they passed or failed and their blend inputs and outputs."""
import numpy as np
import pytest

import softgl

VS = "attribute vec4 aPos; void main() { gl_Position = aPos; }"
FS = "precision highp float; uniform vec4 uColor; void main() { gl_FragColor = uColor; }"
FS_DISCARD = """precision highp float; uniform vec4 uColor;
void main() { if (gl_FragCoord.x < 2.0) discard; gl_FragColor = uColor; }"""


def setup(gl, fs=FS):
    prog = softgl.program(gl, VS, fs)
    gl.useProgram(prog)
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.enableVertexAttribArray(0)
    gl.vertexAttribPointer(0, 4, gl.FLOAT, False, 0, 0)
    return gl.getUniformLocation(prog, "uColor")


def quad(gl, loc, x0, x1, z, color):
    """A quad over window columns [x0, x1) of an 8x8 buffer, two triangles, at NDC depth z."""
    a, b = x0 / 4 - 1, x1 / 4 - 1
    pos = np.array([[a, -1, z, 1], [b, -1, z, 1], [a, 1, z, 1], [b, 1, z, 1]], np.float32)
    gl.bufferData(gl.ARRAY_BUFFER, pos, gl.STATIC_DRAW)
    gl.uniform4f(loc, *color)
    gl.drawArrays(gl.TRIANGLE_STRIP, 0, 4)


def test_two_overlapping_quads_one_failing_the_depth_test():
    gl = softgl.Context(8, 8, antialias=False, alpha=False, strict=True)
    ext = gl.getExtension("SOFTGL_introspection")
    gl.enable(ext.INTROSPECTION_SOFTGL)
    loc = setup(gl)
    gl.clearColor(0, 0, 0, 1)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    gl.enable(gl.DEPTH_TEST)
    quad(gl, loc, 0, 6, 0.0, (1, 0, 0, 1))          # draw 0: opaque red, window z 0.5
    quad(gl, loc, 2, 8, 0.5, (0, 1, 0, 1))          # draw 1: behind red where they overlap
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)
    quad(gl, loc, 4, 8, -0.5, (0, 0, 1, 0.5))       # draw 2: blue, in front, blended

    # Pixel (1, 5): red only.
    f = gl.fragments(1, 5)
    assert [(r["draw"], r["fate"]) for r in f] == [(0, "written")]
    # Pixel (3, 5): red written, green fails the (early) depth test, never shaded.
    f = gl.fragments(3, 5)
    assert [(r["draw"], r["fate"]) for r in f] == [(0, "written"), (1, "failed the depth test (early)")]
    red, green = f
    assert red["tests"]["depth"] is True and red["shader_color"] == (1.0, 0.0, 0.0, 1.0)
    assert red["blend"]["out"] == (1.0, 0.0, 0.0, 1.0) and red["blend"]["enabled"] is False
    assert red["blend"]["out_bytes"] == (255, 0, 0, 255)
    assert green["tests"]["depth"] is False and green["shader_color"] is None and green["blend"] is None
    assert green["depth"] == pytest.approx(0.75, abs=1e-7) and red["depth"] == pytest.approx(0.5, abs=1e-7)
    assert green["early_tests"] and green["tests"]["stencil"] is None and green["tests"]["scissor"] is None
    # Pixel (5, 5): red, green hidden, blue blended over red: inputs, factors and output.
    f = gl.fragments(5, 5)
    assert [(r["draw"], r["fate"]) for r in f] == [(0, "written"), (1, "failed the depth test (early)"),
                                                    (2, "blended")]
    b = f[2]["blend"]
    assert b["src"] == (0.0, 0.0, 1.0, 0.5) and b["dst"] == (1.0, 0.0, 0.0, 1.0)
    assert b["factors"] == ("SRC_ALPHA", "ONE_MINUS_SRC_ALPHA", "SRC_ALPHA", "ONE_MINUS_SRC_ALPHA")
    assert b["src_factor"] == (0.5,) * 4 and b["dst_factor"] == (0.5,) * 4
    assert b["out_bytes"][:3] == (128, 0, 128) and b["out"][:3] == (128 / 255, 0.0, 128 / 255)
    assert tuple(gl.readPixels(5, 5, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE)[0, 0]) == b["out_bytes"]
    # Every colour of the report is one kind of number: floats as the blend equation sees them.
    for key in ("src", "dst", "src_factor", "dst_factor", "out"):
        assert all(type(v) is float for v in b[key]), key
    # Pixel (7, 5): green written (nothing in front), then blue over green.
    assert [(r["draw"], r["fate"]) for r in gl.fragments(7, 5)] == [(1, "written"), (2, "blended")]
    # One fragment per pixel per draw: each pixel lies in exactly one triangle of a strip.
    assert all(len({(r["draw"]) for r in gl.fragments(x, 3)}) == len(gl.fragments(x, 3)) for x in range(8))
    # A clear forgets everything; draw numbers start again.
    gl.clear(gl.COLOR_BUFFER_BIT)
    assert gl.fragments(5, 5) == []
    quad(gl, loc, 0, 8, -0.9, (1, 1, 1, 1))
    assert [r["draw"] for r in gl.fragments(5, 5)] == [0]


def test_discard_stencil_and_late_tests():
    gl = softgl.Context(8, 8, antialias=False, alpha=False, stencil=True, strict=True)
    ext = gl.getExtension("SOFTGL_introspection")
    gl.enable(ext.INTROSPECTION_SOFTGL)
    loc = setup(gl, FS_DISCARD)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT | gl.STENCIL_BUFFER_BIT)
    gl.enable(gl.STENCIL_TEST)
    gl.stencilFunc(gl.EQUAL, 1, 0xFF)                # the stencil is 0: every sample fails
    quad(gl, loc, 0, 8, 0.0, (1, 1, 1, 1))
    f0, f3 = gl.fragments(0, 0), gl.fragments(3, 0)
    assert [r["fate"] for r in f0] == ["discarded by the fragment shader"]
    assert f0[0]["tests"]["discard"] is False
    # The shader may discard, so the tests run late, after shading.
    assert [r["fate"] for r in f3] == ["failed the stencil test"]
    assert f3[0]["tests"]["stencil"] is False and f3[0]["tests"]["depth"] is None
    assert f3[0]["early_tests"] is False and f3[0]["shader_color"] == (1.0, 1.0, 1.0, 1.0)


def test_scissor_and_exact_transparency_capture_are_reported():
    gl = softgl.Context(8, 8, antialias=False, alpha=False, strict=True)
    intro = gl.getExtension("SOFTGL_introspection")
    exact = gl.getExtension("SOFTGL_exact_transparency")
    gl.enable(intro.INTROSPECTION_SOFTGL)
    gl.enable(exact.EXACT_TRANSPARENCY_SOFTGL)
    loc = setup(gl)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.enable(gl.SCISSOR_TEST)
    gl.scissor(0, 0, 4, 8)
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.ONE, gl.ONE)
    quad(gl, loc, 0, 8, 0.0, (0.25, 0.5, 0.75, 1))
    f = gl.fragments(1, 1)
    assert [r["fate"] for r in f] == ["kept in the A-buffer (exact transparency)"]
    assert f[0]["tests"]["scissor"] is True and f[0]["src"] == (0.25, 0.5, 0.75, 1.0)
    assert gl.fragments(6, 1) == []                    # outside the scissor box: never generated


def test_off_by_default_and_changes_no_pixel(quiet):
    gl = softgl.Context(8, 8)
    assert gl.fragments(0, 0) == [] and gl.getError() == gl.INVALID_OPERATION
    images = []
    for on in (False, True):
        gl = softgl.Context(8, 8, antialias=True, samples=4, strict=True)
        ext = gl.getExtension("SOFTGL_introspection")
        if on:
            gl.enable(ext.INTROSPECTION_SOFTGL)
        loc = setup(gl)
        gl.enable(gl.BLEND)
        gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)
        for k in range(3):
            quad(gl, loc, k, 8 - k, 0.1 * k, (0.3 * k, 0.5, 1 - 0.3 * k, 0.6))
        images.append(gl.readPixels(0, 0, 8, 8, gl.RGBA, gl.UNSIGNED_BYTE))
        if on:   # multisampled: one report per covered sample
            assert {r["sample"] for r in gl.fragments(4, 4)} == {0, 1, 2, 3}
            assert len(gl.fragments(4, 4)) == 12
    assert (images[0] == images[1]).all()


def test_log_memory_limit(quiet):
    gl = softgl.Context(8, 8, antialias=False)
    ext = gl.getExtension("SOFTGL_introspection")
    gl.enable(ext.INTROSPECTION_SOFTGL)
    ext.setMemoryLimit(1000)
    loc = setup(gl)
    quad(gl, loc, 0, 8, 0.0, (1, 1, 1, 1))
    assert gl.getError() == gl.OUT_OF_MEMORY and ext.memory()["overflowed"]
    assert gl.fragments(1, 1) == [] and gl.getError() == gl.OUT_OF_MEMORY   # refuses, not partial


@pytest.mark.parametrize("fmt", ["rgba16f", "rgba32f"])
@pytest.mark.parametrize("name", ["SOFTGL_exact_transparency", "SOFTGL_introspection"])
def test_float_contexts_refuse_the_blend_lab_with_a_reason(fmt, name):
    gl = softgl.Context(8, 8, color_format=fmt)
    names = gl.getSupportedExtensions()
    assert name not in names and "SOFTGL_smooth" in names and "SOFTGL_fog" in names
    with pytest.warns(UserWarning, match=rf"{name}.*color_format='{fmt}'.*color_format='rgba8'"):
        assert gl.getExtension(name) is None
    assert gl.getError() == gl.NO_ERROR
    assert softgl.Context(8, 8).getExtension(name) is not None     # RGBA8: offered
