"""NaN and +-Inf everywhere a float enters softgl, with the behaviour docs/reliability.md defines:

- positions: a primitive with a non-finite clip coordinate (x, y, z or w) is dropped whole
  (counted in stats()["primitives_invalid"]); its neighbours in a strip or fan are unaffected.
- attributes/uniforms that become colors: float -> unorm clamps, NaN -> 0, +Inf -> 1, -Inf -> 0.
- blend color: stored as given (getParameter returns it), clamped at blend time (NaN -> 0).
- clear values: clearColor like colors; clearDepth and depthRange clamp to [0, 1] with NaN -> 0.
- lineWidth NaN: INVALID_VALUE (WebGL); polygonOffset NaN: no offset (the comparison fails
  neither way: documented below); sampleCoverage NaN -> 0.
- viewport/scissor take GLint: a Python float (NaN or not) is a TypeError, as every GLint.
"""
import math

import numpy as np
import pytest

from stress_helpers import Painter, context, pixels, quiet

NAN, INF = math.nan, math.inf
TRI = np.array([[-1, -1, 0, 1], [1, -1, 0, 1], [-1, 1, 0, 1]], np.float32)
FULL = np.array([[-1, -1, 0, 1], [3, -1, 0, 1], [-1, 3, 0, 1]], np.float32)   # covers the canvas


def one_triangle(value, component, vertex=2, **kw):
    gl = context(16, 16, **kw)
    p = Painter(gl, uniform_color=True)
    tri = TRI.copy()
    tri[vertex, component] = value
    p.draw(gl.TRIANGLES, tri, color=(1, 1, 1, 1))
    return gl, pixels(gl)


@pytest.mark.parametrize("value", [NAN, INF, -INF])
@pytest.mark.parametrize("component", [0, 1, 2, 3])
def test_non_finite_position_drops_the_primitive(value, component):
    gl, img = one_triangle(value, component)
    assert img.sum() == 0
    s = gl.stats()
    assert s["primitives_invalid"] == 1 and s["primitives_rasterized"] == 0


@pytest.mark.parametrize("mode", ["TRIANGLE_STRIP", "TRIANGLE_FAN", "LINE_STRIP", "POINTS"])
def test_a_nan_vertex_drops_only_its_primitives(mode):
    gl = context(32, 8)
    p = Painter(gl, uniform_color=True)
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.ONE, gl.ONE)
    xs = np.linspace(-0.95, 0.95, 9)
    strip = np.array([[x, -0.9 if k % 2 == 0 else 0.9, 0, 1] for k, x in enumerate(xs)], np.float32)
    if mode == "TRIANGLE_FAN":
        strip = np.vstack([[[-0.95, 0, 0, 1]], strip])
    clean = strip.copy()
    bad = strip.copy()
    bad[4, 1] = np.nan
    p.draw(getattr(gl, mode), clean, color=(3 / 255,) * 4)
    ref = pixels(gl)[..., 0] // 3
    prims_clean = gl.stats(reset=True)["primitives"]
    gl.clear(gl.COLOR_BUFFER_BIT)
    p.draw(getattr(gl, mode), bad, color=(3 / 255,) * 4)
    got = pixels(gl)[..., 0] // 3
    s = gl.stats()
    per_vertex = {"TRIANGLE_STRIP": 3, "TRIANGLE_FAN": 2, "LINE_STRIP": 2, "POINTS": 1}[mode]
    assert s["primitives_invalid"] == per_vertex
    assert s["primitives"] == prims_clean
    assert (got <= ref).all() and got.sum() > 0 and got.sum() < ref.sum()


@pytest.mark.parametrize("rgba,expected", [
    ((NAN, NAN, NAN, NAN), (0, 0, 0, 0)),
    ((INF, -INF, NAN, INF), (255, 0, 0, 255)),
    ((1e38, -1e38, 0.5, 2.0), (255, 0, 128, 255)),
])
@pytest.mark.parametrize("source", ["attribute", "uniform"])
def test_non_finite_colors_clamp(rgba, expected, source):
    gl = context(8, 8)
    p = Painter(gl, uniform_color=source == "uniform")
    p.draw(gl.TRIANGLES, FULL, color=rgba)
    assert pixels(gl)[4, 4].tolist() == list(expected)


def test_nan_varying_interpolates_to_nan_and_clamps_to_zero():
    gl = context(8, 8)
    p = Painter(gl)
    col = np.array([[NAN, 1, 0, 1], [0, 1, INF, 1], [0, 1, 0, 1]], np.float32)
    p.draw(gl.TRIANGLES, FULL, colors=col)
    img = pixels(gl)
    assert (img[..., 0] == 0).all() and (img[..., 1] == 255).all()
    assert set(np.unique(img[..., 2])) <= {0, 255}      # Inf * 0 weight = NaN -> 0, else +Inf -> 255


@pytest.mark.parametrize("constant,expected_r", [((NAN,) * 4, 0), ((INF,) * 4, 255), ((-INF,) * 4, 0),
                                                 ((0.5, NAN, NAN, NAN), 128)])
def test_non_finite_blend_color_is_clamped_at_blend_time(constant, expected_r):
    gl = context(8, 8)
    gl.blendColor(*constant)
    stored = gl.getParameter(gl.BLEND_COLOR)
    np.testing.assert_array_equal(stored, np.array(constant, np.float32))   # stored as given
    p = Painter(gl, uniform_color=True)
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.CONSTANT_COLOR, gl.ZERO)
    p.draw(gl.TRIANGLES, FULL, color=(1, 1, 1, 1))
    assert pixels(gl)[4, 4, 0] == expected_r


def test_non_finite_clear_values():
    gl = context(4, 4, stencil=True)
    gl.clearColor(NAN, INF, -INF, NAN)
    gl.clear(gl.COLOR_BUFFER_BIT)
    assert pixels(gl)[0, 0].tolist() == [0, 255, 0, 0]
    for value, stored in [(NAN, 0.0), (INF, 1.0), (-INF, 0.0), (2.0, 1.0)]:
        gl.clearDepth(value)
        assert gl.getParameter(gl.DEPTH_CLEAR_VALUE) == stored
    # The cleared depth really is that value: a quad at window depth 0.5 passes LESS only
    # against depth 1.
    gl.enable(gl.DEPTH_TEST)
    p = Painter(gl, uniform_color=True)
    for value, passes in [(NAN, False), (INF, True)]:
        gl.clearDepth(value)
        gl.clearColor(0, 0, 0, 0)
        gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
        p.draw(gl.TRIANGLES, FULL, color=(1, 1, 1, 1))
        assert (pixels(gl)[2, 2, 0] == 255) == passes


@pytest.mark.parametrize("near,far,expected", [(NAN, NAN, (0, 0)), (-INF, INF, (0, 1)), (INF, NAN, (1, 0)),
                                               (NAN, 0.5, (0, 0.5))])
def test_non_finite_depth_range_clamps(near, far, expected):
    gl = context(4, 4)
    gl.depthRange(near, far)
    assert gl.getError() == gl.NO_ERROR
    assert gl.getParameter(gl.DEPTH_RANGE).tolist() == list(expected)


def test_non_finite_line_width_and_sample_coverage():
    gl = context(4, 4)
    with quiet():
        gl.lineWidth(NAN)
    assert gl.getError() == gl.INVALID_VALUE and gl.getParameter(gl.LINE_WIDTH) == 1.0
    gl.lineWidth(INF)       # accepted (WebGL: only NaN and <= 0 are errors), clamped when drawing
    assert gl.getError() == gl.NO_ERROR
    gl.sampleCoverage(NAN, False)
    assert gl.getParameter(gl.SAMPLE_COVERAGE_VALUE) == 0.0


@pytest.mark.parametrize("factor,units,drawn", [(NAN, 0, True), (0, NAN, True), (INF, 0, False),
                                                (0, INF, False), (-INF, 0, True), (0, -INF, True)])
def test_non_finite_polygon_offset(factor, units, drawn):
    """+Inf pushes the depth to 1 (fails LESS against the cleared 1), -Inf to 0; NaN leaves a
    NaN offset that softgl's depth conversion turns into depth 0 (drawn)."""
    gl = context(16, 16)
    gl.enable(gl.DEPTH_TEST)
    gl.enable(gl.POLYGON_OFFSET_FILL)
    gl.polygonOffset(factor, units)
    p = Painter(gl, uniform_color=True)
    tri = np.array([[-1, -1, 0, 1], [3, -1, 0.5, 1], [-1, 3, -0.3, 1]], np.float32)
    p.draw(gl.TRIANGLES, tri, color=(1, 1, 1, 1))
    assert (pixels(gl)[..., 0] == 255).all() == drawn


@pytest.mark.parametrize("call", ["viewport", "scissor"])
@pytest.mark.parametrize("value", [NAN, INF, 1.5])
def test_float_arguments_to_glint_are_type_errors(call, value):
    gl = context(4, 4)
    with pytest.raises(TypeError):
        getattr(gl, call)(0, 0, value, 4)
    assert gl.getError() == gl.NO_ERROR
    assert gl.getParameter(gl.VIEWPORT).tolist() == [0, 0, 4, 4]


@pytest.mark.parametrize("vp", [(-2**31, -2**31, 16384, 16384), (2**31 - 1, 2**31 - 1, 16384, 16384),
                                (2**31 - 20000, 0, 16384, 16), (-16380, 0, 16384, 16)])
def test_extreme_viewports_draw_only_what_they_cover(vp):
    gl = context(16, 16)
    p = Painter(gl, uniform_color=True)
    gl.viewport(*vp)
    p.draw(gl.TRIANGLE_STRIP, np.array([[-1, -1, 0, 1], [1, -1, 0, 1], [-1, 1, 0, 1], [1, 1, 0, 1]], np.float32),
           color=(1, 1, 1, 1))
    x, y, w, h = vp
    cols = max(0, min(16, x + w) - max(0, x))
    rows = max(0, min(16, y + h) - max(0, y))
    assert (pixels(gl)[..., 0] > 0).sum() == cols * rows


@pytest.mark.parametrize("value", [NAN, INF, -INF])
def test_non_finite_point_size_and_fragment_outputs(value):
    """gl_PointSize NaN/Inf: clamped to the point size range ([1, 1024]; NaN -> 1). A shader
    writing NaN/Inf colors: clamped like any color."""
    import softgl
    gl = context(16, 16)
    vs = f"""attribute vec4 aPos; uniform float uSize;
void main() {{ gl_Position = aPos; gl_PointSize = uSize; }}"""
    fs = "precision highp float; uniform float uV; void main() { gl_FragColor = vec4(uV, 1.0, 0.0, 1.0); }"
    prog = softgl.program(gl, vs, fs, {"aPos": 0})
    gl.useProgram(prog)
    gl.uniform1f(gl.getUniformLocation(prog, "uSize"), value)
    gl.uniform1f(gl.getUniformLocation(prog, "uV"), value)
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.bufferData(gl.ARRAY_BUFFER, np.array([0, 0, 0, 1], np.float32), gl.STATIC_DRAW)
    gl.enableVertexAttribArray(0)
    gl.vertexAttribPointer(0, 4, gl.FLOAT, False, 0, 0)
    gl.drawArrays(gl.POINTS, 0, 1)
    img = pixels(gl)
    covered = img[..., 1] == 255
    expected_r = 255 if value == INF else 0
    # +Inf -> 1024 covers the canvas; NaN and -Inf -> size 1: the one pixel whose square holds the centre.
    assert covered.sum() == (256 if value == INF else 1)
    assert (img[covered, 0] == expected_r).all()
