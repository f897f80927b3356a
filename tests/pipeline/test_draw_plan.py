"""The draw plan (pipeline/draw_plan.h, gl.last_draw_plan()): which kernels and fast paths a draw
takes and, for each one it does not, the first reason why. Each case here is a draw whose paths
follow from the spec's rules and softgl's documented limits (docs/architecture.md, "Fast paths"),
so a plan that took a path it must not (or left one it could take without a reason) fails; the
draw-kind counters of gl.stats() agree with the plans, and equal draws give equal plans."""
import numpy as np
import pytest

import softgl
from softgl import _core

SIZE = 32
VS = """#version 300 es
in vec4 aPos;
in vec4 aColor;
out vec4 vColor;
void main() { gl_Position = aPos; gl_PointSize = 3.0; vColor = aColor; }
"""
COPY_FS = """#version 300 es
precision highp float;
in vec4 vColor;
out vec4 fragColor;
void main() { fragColor = vColor; }
"""
SHADED_FS = """#version 300 es
precision highp float;
in vec4 vColor;
out vec4 fragColor;
void main() { fragColor = vColor * vColor; }
"""
UNIFORM_FS = """#version 300 es
precision highp float;
uniform vec4 uColor;
out vec4 fragColor;
void main() { fragColor = uColor; }
"""
DISCARD_FS = """#version 300 es
precision highp float;
in vec4 vColor;
out vec4 fragColor;
void main() { if (vColor.a < 0.5) discard; fragColor = vColor; }
"""
FLAT_FS = """#version 300 es
precision highp float;
flat in vec4 vColor;
out vec4 fragColor;
void main() { fragColor = vColor; }
"""


def context(fs=COPY_FS, vs=VS, n=12, **kw):
    """A SIZE x SIZE context drawing n random vertices with `fs`; returns (gl, program)."""
    kw.setdefault("antialias", False)
    gl = softgl.Context(SIZE, SIZE, preserveDrawingBuffer=True, **kw)
    prog = softgl.program(gl, vs, fs, {"aPos": 0, "aColor": 1})
    gl.useProgram(prog)
    rng = np.random.default_rng(n)
    pos = np.column_stack([rng.uniform(-1, 1, (n, 2)), rng.uniform(-0.5, 0.5, n), np.ones(n)])
    for loc, data in ((0, pos), (1, rng.uniform(0, 1, (n, 4)))):
        gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
        gl.bufferData(gl.ARRAY_BUFFER, np.ascontiguousarray(data, np.float32), gl.STATIC_DRAW)
        gl.enableVertexAttribArray(loc)
        gl.vertexAttribPointer(loc, 4, gl.FLOAT, False, 0, 0)
    return gl, prog


def draw(gl, mode="TRIANGLES", count=12):
    gl.drawArrays(getattr(gl, mode), 0, count)
    assert gl.getError() == gl.NO_ERROR
    return gl.last_draw_plan()


def taken(plan, *paths):
    return {p: plan[p] for p in paths}


def why_not(plan, *paths):
    return {p: plan[p + "_why_not"] for p in paths}


def test_none_before_the_first_draw():
    gl, _ = context()
    assert gl.last_draw_plan() is None


def test_opaque_depth_tested_mesh_takes_every_depth_path():
    gl, _ = context()
    gl.enable(gl.DEPTH_TEST)
    plan = draw(gl)
    assert plan["primitives"] == "triangles" and plan["skip"] == "no" and plan["target"] == "drawing_buffer"
    assert all(taken(plan, "tests_before_shading", "quad_depth", "depth_bounds", "hidden_surface_removal",
                     "fragment_copies", "fused_copy", "color_kernels").values()), plan["text"]
    assert plan["kernel"] == "plain" and plan["plain_write"] and plan["copied_word"] == 0
    assert why_not(plan, "constant_color", "blend_table") == {"constant_color": "not_uniform_only",
                                                              "blend_table": "not_uniform_only"}
    assert plan["simd"] == _core.testing.tuning(gl)["simd"]


def test_blended_per_vertex_colour_reads_the_destination():
    gl, _ = context()
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)
    plan = draw(gl)
    assert plan["kernel"] == "alpha_over" and not plan["plain_write"]
    assert why_not(plan, "hidden_surface_removal", "quad_depth") == {"hidden_surface_removal": "reads_destination",
                                                                     "quad_depth": "no_depth_test"}
    assert plan["fused_copy"] and plan["color_kernels"]
    assert gl.stats()["draws_plain_write"] == 0


def test_smooth_lines_with_the_blend_lab_go_lane_by_lane():
    gl, _ = context()
    gl.enable(gl.getExtension("SOFTGL_smooth").LINE_SMOOTH)
    gl.enable(gl.getExtension("SOFTGL_introspection").INTROSPECTION_SOFTGL)
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)
    plan = draw(gl, "LINES")
    assert plan["primitives"] == "lines" and plan["blend_lab"] and plan["area_coverage"]
    assert why_not(plan, "color_kernels", "fused_copy", "hidden_surface_removal") == {
        "color_kernels": "blend_lab", "fused_copy": "blend_lab", "hidden_surface_removal": "reads_destination"}
    assert gl.stats()["draws_per_lane_color"] == 1
    # Without the blend lab the smoothing alone keeps the lanes (coverage scales alpha).
    gl.disable(gl.getExtension("SOFTGL_introspection").INTROSPECTION_SOFTGL)
    assert why_not(draw(gl, "LINES"), "color_kernels")["color_kernels"] == "smoothing"


def test_each_reason_for_the_depth_paths():
    gl, _ = context(stencil=True)
    gl.enable(gl.DEPTH_TEST)
    gl.enable(gl.STENCIL_TEST)
    plan = draw(gl)
    assert why_not(plan, "quad_depth", "depth_bounds", "hidden_surface_removal") == {
        "quad_depth": "stencil_test", "depth_bounds": "stencil_test", "hidden_surface_removal": "stencil_test"}
    gl.disable(gl.STENCIL_TEST)
    gl.depthFunc(gl.EQUAL)
    assert why_not(draw(gl), "depth_bounds")["depth_bounds"] == "depth_func"
    gl.depthFunc(gl.LESS)
    gl.enable(gl.getExtension("SOFTGL_smooth").POLYGON_SMOOTH)
    assert why_not(draw(gl), "depth_bounds")["depth_bounds"] == "smoothing"

    gl, _ = context(antialias=True)
    gl.enable(gl.DEPTH_TEST)
    plan = draw(gl)
    assert plan["samples"] == 4 and plan["quad_depth"]
    assert why_not(plan, "depth_bounds", "hidden_surface_removal", "fused_copy") == {
        "depth_bounds": "multisampled", "hidden_surface_removal": "multisampled", "fused_copy": "multisampled"}


def test_discard_tests_late():
    gl, _ = context(DISCARD_FS)
    gl.enable(gl.DEPTH_TEST)
    plan = draw(gl)
    assert why_not(plan, "tests_before_shading", "quad_depth", "color_kernels", "fragment_copies") == {
        "tests_before_shading": "discard", "quad_depth": "late_tests", "color_kernels": "late_tests",
        "fragment_copies": "not_copy"}
    stats = gl.stats()
    assert stats["draws_late_tests"] == 1 and stats["draws_early_depth"] == 0 and stats["draws_per_lane_color"] == 1


def test_copies_and_shaders():
    gl, _ = context(SHADED_FS)
    assert why_not(draw(gl), "fragment_copies", "fused_copy") == {"fragment_copies": "not_copy",
                                                                  "fused_copy": "not_copy"}
    gl, _ = context(FLAT_FS, vs=VS.replace("out vec4 vColor", "flat out vec4 vColor"))
    plan = draw(gl)
    assert plan["fragment_copies"] and plan["copied_word"] == 0 and plan["copied_index"] == -1
    assert why_not(plan, "fused_copy")["fused_copy"] == "not_interpolated"
    gl, _ = context()
    assert why_not(draw(gl, "POINTS"), "fused_copy")["fused_copy"] == "not_interpolated"
    assert gl.stats()["draws_copied_varying"] == 1


def test_uniform_only_colour_by_table_and_whole_blocks():
    gl, prog = context(UNIFORM_FS)
    gl.uniform4f(gl.getUniformLocation(prog, "uColor"), 0.2, 0.4, 0.6, 0.5)
    plan = draw(gl)
    assert plan["shaded"] and plan["uniform_only"] and plan["constant_color"]
    assert why_not(plan, "blend_table")["blend_table"] == "no_blending"
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)
    plan = draw(gl)
    assert plan["blend_table"] and plan["whole_rect_blend"]
    gl.enable(gl.DEPTH_TEST)
    assert why_not(draw(gl), "whole_rect_blend")["whole_rect_blend"] == "depth_stencil_tests"
    stats = gl.stats()
    assert stats["draws_constant_color"] == 3 and stats["draws_blend_table"] == 2


def test_skipped_draws_decide_nothing_for_the_tile_pass():
    gl, _ = context()
    gl.colorMask(False, False, False, False)
    plan = draw(gl)
    assert plan["skip"] == "no_output" and not plan["shaded"]
    assert set(why_not(plan, "quad_depth", "color_kernels", "constant_color", "blend_table").values()) == {"not_rasterized"}
    gl.colorMask(True, True, True, True)
    gl.enable(gl.RASTERIZER_DISCARD)
    assert draw(gl)["skip"] == "rasterizer_discard"


def test_framebuffer_objects_of_one_rgba8_image_take_the_byte_paths():
    # An RGBA8 image stores the drawing buffer's bytes (surface/texture.h): the colour kernels
    # write it. Other formats, or a second colour buffer, go through the render target.
    gl, _ = context()
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    textures = []
    for internal, fmt, type_ in ((gl.RGBA8, gl.RGBA, gl.UNSIGNED_BYTE), (gl.RGBA4, gl.RGBA, gl.UNSIGNED_BYTE),
                                 (gl.RGB8, gl.RGB, gl.UNSIGNED_BYTE)):
        tex = gl.createTexture()
        gl.bindTexture(gl.TEXTURE_2D, tex)
        gl.texImage2D(gl.TEXTURE_2D, 0, internal, SIZE, SIZE, 0, fmt, type_, None)
        textures.append(tex)
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, textures[0], 0)
    plan = draw(gl)
    assert plan["target"] == "framebuffer_object"
    assert plan["color_kernels"] and plan["fused_copy"], plan["text"]
    for other in textures[1:]:
        gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, other, 0)
        assert why_not(draw(gl), "color_kernels", "fused_copy") == {"color_kernels": "framebuffer_object",
                                                                    "fused_copy": "framebuffer_object"}
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, textures[0], 0)
    second = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, second)
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, SIZE, SIZE, 0, gl.RGBA, gl.UNSIGNED_BYTE, None)
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT1, gl.TEXTURE_2D, second, 0)
    gl.drawBuffers([gl.COLOR_ATTACHMENT0, gl.COLOR_ATTACHMENT1])
    assert why_not(draw(gl), "color_kernels")["color_kernels"] == "framebuffer_object"


def test_the_tuning_switches_paths_off():
    gl, _ = context()
    gl.enable(gl.DEPTH_TEST)
    _core.testing.set_tuning(gl, hidden_surface_removal="off", depth_bounds="off", fragment_copies=False,
                             simd="scalar", batch_primitives=5)
    plan = draw(gl)
    assert set(why_not(plan, "hidden_surface_removal", "depth_bounds", "fragment_copies").values()) == {"tuning_off"}
    assert plan["simd"] == "scalar" and plan["batch_primitives"] == 5
    _core.testing.set_tuning(gl, hidden_surface_removal="in_every_tile", depth_bounds="sabotaged_for_tests")
    plan = draw(gl)
    assert plan["hidden_surface_in_every_tile"] and plan["depth_bounds_sabotaged"]


def test_equal_draws_equal_plans_and_the_text_shows_every_field():
    gl, _ = context()
    first, second = draw(gl), draw(gl)
    assert first == second
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.ONE, gl.ONE)
    third = draw(gl)
    assert third["hash"] != first["hash"] and third["kernel"] == "additive"
    lines = third["text"].splitlines()
    assert [line.split(":")[0] for line in lines] == ["draw", "tests", "shading", "color"]
    for field, value in third.items():
        if field in ("text", "hash") or field.endswith("_why_not"):
            continue
        shown = {True: "yes", False: "no"}.get(value, str(value)) if isinstance(value, bool) else str(value)
        if isinstance(value, bool) and f"{field}_why_not" in third and not value:
            shown = f"no({third[field + '_why_not']})"
        assert f" {field}={shown}" in third["text"], field


@pytest.mark.parametrize("threads", [1, 2])
def test_draw_kind_counters_follow_the_plans(threads):
    """Each draw adds 1 to each counter its plan says, whatever the batch size."""
    for batch in (0, 2):
        gl, prog = context(DISCARD_FS, threads=threads)
        _core.testing.set_tuning(gl, batch_primitives=batch)
        gl.enable(gl.DEPTH_TEST)
        draw(gl)
        gl.useProgram(softgl.program(gl, VS, UNIFORM_FS, {"aPos": 0, "aColor": 1}))
        draw(gl)
        draw(gl)
        stats = gl.stats()
        assert (stats["draws_late_tests"], stats["draws_early_depth"], stats["draws_constant_color"],
                stats["draws_per_lane_color"]) == (1, 2, 2, 1), batch
