"""Each lesson page, run as JavaScript through softgl.page, gives the same bytes as the same
scene written with softgl's Python API (its twin): the bridge must pass every call, array and
object through unchanged."""
import math

import numpy as np
import pytest

import softgl
import softgl.page
from softgl import geometry, programs, scene, transforms as T


def spotlights_twin(width=320, height=240):
    """tests/pages/lessons/spotlights.html in Python: softgl.programs.lights(3), geometry.plane and
    geometry.cube, softgl.scene.draw_mesh."""
    gl = softgl.Context(width, height, version=2, antialias=False)
    gl.clearColor(0.1, 0.1, 0.12, 1.0)
    gl.enable(gl.DEPTH_TEST)
    gl.viewport(0, 0, width, height)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    prog = programs.lights(gl, 3)
    view = T.look_at((0, 5, 12), (0, 0, 0), (0, 1, 0))
    projection = T.perspective(np.pi / 4, width / height, 0.1, 100)
    lights = dict(uLightPositions=[[-4, 6, 2], [0, 6, 2], [4, 6, 2]],
                  uLightDirections=[[0, -1, -0.3], [0, -1, 0.3], [0, -1, -0.3]],
                  uLightColors=[[1, 0.2, 0.2, 1], [0.2, 1, 0.2, 1], [0.2, 0.2, 1, 1]],
                  uLightCutoffs=[0.4, 0.4, 0.4], uLightAmbient=(0.1, 0.1, 0.1, 1))
    for mesh, model in ((geometry.plane(20, 20), T.identity()), (geometry.cube(2.0), T.translate(0, 1, 0))):
        scene.draw_mesh(gl, prog, mesh, model=model, uView=view, uProjection=projection,
                        uNormalMatrix=T.normal_matrix(view @ model), **lights)
    return gl.readPixels(0, 0, width, height, gl.RGBA, gl.UNSIGNED_BYTE)


def test_spotlights_page_equals_its_python_twin(lessons):
    result = softgl.page.run(lessons / "spotlights.html", frames=2)
    assert result.errors == []
    assert result.console == [("log", "spotlights: ready")]
    twin = spotlights_twin()
    assert len(result.frames) == 2
    for frame in result.frames:   # drawn again on each animation frame, the same bytes
        assert frame.shape == (240, 320, 4) and frame.dtype == np.uint8
        assert np.array_equal(frame, twin)
    # The scene is lit: the three lights' colours all reach the floor.
    assert len(np.unique(twin.reshape(-1, 4), axis=0)) > 400
    assert twin[..., 0].max() > 200 and twin[..., 1].max() > 200 and twin[..., 2].max() > 200


def test_page_frame_helper_against_the_twin(lessons, tmp_path):
    result = softgl.page.run(lessons / "spotlights.html", frames=1)
    softgl.testing.assert_page_frame(result, spotlights_twin())
    different = spotlights_twin().copy()
    different[100:110, 100:110, 0] ^= 0x40
    with pytest.raises(AssertionError, match="100 pixels beyond atol"):
        softgl.testing.assert_page_frame(result, different, out_dir=tmp_path)


def fog_blend_twin(width=240, height=180):
    """tests/pages/lessons/fog_blend.html in Python: softgl.programs.fogged (EXP2 on the eye
    depth), geometry.cube, scene.draw_mesh; blending with plain softgl calls."""
    gl = softgl.Context(width, height, version=1, antialias=False)
    gl.clearColor(0.6, 0.6, 0.7, 1.0)
    gl.enable(gl.DEPTH_TEST)
    gl.viewport(0, 0, width, height)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    prog = programs.fogged(gl, "EXP2", density=0.05, color=(0.6, 0.6, 0.7, 1.0))
    view = T.look_at((0, 2, 8), (0, 0, -6), (0, 1, 0))
    projection = T.perspective(np.pi / 4, width / height, 0.5, 60)
    cube = geometry.cube(2.0)
    common = dict(uView=view, uProjection=projection, uLightDirection=(0, -1, -1),
                  uLightAmbient=(0.1, 0.1, 0.1, 1))

    def draw(model, color):
        scene.draw_mesh(gl, prog, cube, model=model, uNormalMatrix=T.normal_matrix(view @ model),
                        uMaterialDiffuse=color, **common)
    gl.disable(gl.BLEND)
    gl.depthMask(True)
    for i in range(5):
        draw(T.translate(-3 + 1.5 * i, 0, -3 * i), (0.9, 0.5, 0.2, 1))
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)
    gl.depthMask(False)
    draw(T.translate(2, -0.5, 2.5), (0.2, 0.4, 1, 0.5))
    gl.depthMask(True)
    return gl.readPixels(0, 0, width, height, gl.RGBA, gl.UNSIGNED_BYTE)


def test_fog_blend_page_equals_its_python_twin(lessons):
    result = softgl.page.run(lessons / "fog_blend.html", frames=2)
    assert result.errors == [] and result.console == []
    twin = fog_blend_twin()
    for frame in result.frames:
        assert np.array_equal(frame, twin)
    # Fog: the far cubes fade towards the fog colour; the translucent cube mixes blue in.
    assert len(np.unique(twin.reshape(-1, 4), axis=0)) > 40


def shadows_twin(time_ms, width=200, height=150):
    """tests/pages/lessons/shadows.html at one animation frame, in Python: the same shaders,
    geometry.plane and geometry.cube, transforms.shadow_matrix, plain softgl calls."""
    vertex, lit_fs, shadow_fs = shadow_shaders()
    gl = softgl.Context(width, height, version=1, antialias=False, stencil=True)
    gl.clearColor(0.95, 0.95, 1, 1)
    gl.enable(gl.DEPTH_TEST)
    lit = programs.Program(gl, vertex, lit_fs)
    shadow = programs.Program(gl, vertex, shadow_fs)
    angle = time_ms / 500
    light = (3 * math.cos(angle), 5, 3 * math.sin(angle))
    view = T.look_at((0, 4, 7), (0, 0, 0), (0, 1, 0))
    projection = T.perspective(np.pi / 4, width / height, 0.5, 50)
    floor, cube = geometry.plane(8, 8), geometry.cube(1.0)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT | gl.STENCIL_BUFFER_BIT)
    frame = dict(uView=view, uProjection=projection, uLightPosition=light, uLightColor=(1, 1, 0.9, 1),
                 uLightAmbient=(0.2, 0.2, 0.2, 1))
    scene.draw_mesh(gl, lit, floor, model=T.identity(), uNormalMatrix=T.normal_matrix(view @ T.identity()),
                    uMaterialDiffuse=(0.7, 0.75, 0.8, 1), **frame)
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)
    gl.enable(gl.STENCIL_TEST)
    gl.stencilFunc(gl.EQUAL, 0, 0xFF)
    gl.stencilOp(gl.KEEP, gl.KEEP, gl.INCR)
    shadow_model = T.shadow_matrix(light, 0.0, 0.01).astype(np.float64) @ T.translate(0, 0.5, 0).astype(np.float64)
    scene.draw_mesh(gl, shadow, cube, model=shadow_model, uView=view, uProjection=projection,
                    uShadowColor=(0, 0, 0, 0.5))
    gl.disable(gl.STENCIL_TEST)
    gl.disable(gl.BLEND)
    model = T.translate(0, 0.5, 0)
    scene.draw_mesh(gl, lit, cube, model=model, uNormalMatrix=T.normal_matrix(view @ model),
                    uMaterialDiffuse=(0.9, 0.3, 0.2, 1), **frame)
    return gl.readPixels(0, 0, width, height, gl.RGBA, gl.UNSIGNED_BYTE)


def shadow_shaders():
    """The page's three shaders, as the twin's own copies (GLSL is the same language on both)."""
    vertex = """attribute vec3 aPosition; attribute vec3 aNormal;
uniform mat4 uModel; uniform mat4 uView; uniform mat4 uProjection; uniform mat4 uNormalMatrix;
varying vec3 vEyePosition; varying vec3 vEyeNormal;
void main() {
  vec4 eye = uView * uModel * vec4(aPosition, 1.0);
  vEyePosition = eye.xyz;
  vEyeNormal = (uNormalMatrix * vec4(aNormal, 0.0)).xyz;
  gl_Position = uProjection * eye;
}"""
    lit = """precision highp float;
uniform mat4 uView; uniform vec3 uLightPosition; uniform vec4 uLightColor; uniform vec4 uLightAmbient;
uniform vec4 uMaterialDiffuse; varying vec3 vEyePosition; varying vec3 vEyeNormal;
void main() {
  vec3 N = normalize(vEyeNormal);
  vec3 light = (uView * vec4(uLightPosition, 1.0)).xyz;
  vec3 L = normalize(vEyePosition - light);
  float lambert = dot(N, -L);
  vec4 diffuse = vec4(0.0);
  if (lambert > 0.0) diffuse += uLightColor * uMaterialDiffuse * lambert;
  vec4 color = uLightAmbient * uMaterialDiffuse + diffuse;
  gl_FragColor = vec4(color.rgb, uMaterialDiffuse.a);
}"""
    shadow = "precision highp float; uniform vec4 uShadowColor; void main() { gl_FragColor = uShadowColor; }"
    return vertex, lit, shadow


def test_shadows_page_equals_its_python_twin_frame_by_frame(lessons):
    result = softgl.page.run(lessons / "shadows.html", frames=3, time_step=250)
    assert result.errors == []
    twins = [shadows_twin(t) for t in result.times]
    for frame, twin in zip(result.frames, twins):
        assert np.array_equal(frame, twin)
    # The light moves: the shadow (and the lit faces) differ from frame to frame.
    assert not np.array_equal(twins[0], twins[1]) and not np.array_equal(twins[1], twins[2])


COLUMNS = [(False, False, True, "LESS", False), (True, False, True, "LESS", False),
           (False, True, True, "LESS", False), (True, True, True, "LESS", True),
           (False, True, True, "LESS", True), (True, True, True, "LEQUAL", True),
           (True, True, True, "GREATER", True), (True, True, False, "LESS", True)]


def columns_twin():
    """tests/pages/lessons/columns.html in Python: softgl.programs.vertex_color (points of
    uPointSize) and plain softgl calls, the same eight depth/blend settings."""
    gl = softgl.Context(320, 160, version=1, antialias=False)
    prog = programs.vertex_color(gl)
    prog.set(uPointSize=14.0)
    gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
    for name, loc in prog.attributes.items():
        if name == "aPosition":
            gl.enableVertexAttribArray(loc)
            gl.vertexAttribPointer(loc, 3, gl.FLOAT, False, 28, 0)
        elif name == "aColor":
            gl.enableVertexAttribArray(loc)
            gl.vertexAttribPointer(loc, 4, gl.FLOAT, False, 28, 12)
    gl.clearColor(0, 0, 0, 1)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    gl.enable(gl.SCISSOR_TEST)
    gl.scissor(0, 94, 320, 12)
    gl.clearColor(1, 1, 1, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.disable(gl.SCISSOR_TEST)
    d = 0.04
    for c, (depth, blend, mask, func, separate) in enumerate(COLUMNS):
        (gl.enable if depth else gl.disable)(gl.DEPTH_TEST)
        (gl.enable if blend else gl.disable)(gl.BLEND)
        if separate:
            gl.blendFuncSeparate(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA, gl.ZERO, gl.ONE)
        else:
            gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)
        gl.depthMask(mask)
        gl.depthFunc(getattr(gl, func))
        for r, alpha in enumerate([1, 0.75, 0.5, 0.25]):
            x, y = (c + 0.5) / 4 - 1, 1 - (r + 0.5) / 2
            data = np.array([[x - d, y + d, -0.5, 1, 0, 0, alpha], [x, y, 0, 1, 1, 0, alpha],
                             [x + d, y - d, 0.5, 0, 0, 1, alpha]], np.float32)
            gl.bufferData(gl.ARRAY_BUFFER, data, gl.DYNAMIC_DRAW)
            gl.drawArrays(gl.POINTS, 0, 3)
    return gl.readPixels(0, 0, 320, 160, gl.RGBA, gl.UNSIGNED_BYTE)


def test_columns_page_equals_its_python_twin(lessons):
    result = softgl.page.run(lessons / "columns.html", frames=1)
    assert result.errors == []
    # The lesson's getters, read from JavaScript after the last column.
    assert result.console == [("log", f"depth test true depth bits 24 depth range 0,1 write mask false func {0x0201}")]
    twin = columns_twin()
    assert np.array_equal(result.frames[0], twin)
    # Columns differ: e.g. column 1 (no depth test) shows blue on top, column 2 (depth) red.
    assert not np.array_equal(twin[:, :40], twin[:, 40:80])
