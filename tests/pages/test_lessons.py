"""Each lesson page, run as JavaScript through softgl.page, gives the same bytes as the same
scene written with softgl's Python API (its twin): the bridge must pass every call, array and
object through unchanged."""
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
