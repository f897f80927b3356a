"""softgl.transforms against GLM (the C++ math library) and against hand-derived properties."""
import math

import numpy as np
import pytest

from softgl import _core, transforms as T

glm = _core.testing


def close(a, b, tol=2e-6):
    np.testing.assert_allclose(a, b, rtol=tol, atol=tol)


@pytest.mark.parametrize("args", [(math.radians(45), 4 / 3, 0.1, 100.0), (1.0, 1.0, 1.0, 2.0),
                                  (math.radians(90), 0.5, 0.01, 1e4)])
def test_perspective_equals_glm(args):
    close(T.perspective(*args), glm.glm_perspective(*args))


def test_ortho_look_at_translate_scale_rotate_equal_glm():
    close(T.ortho(-2, 3, -1, 4, 0.5, 20), glm.glm_ortho(-2, 3, -1, 4, 0.5, 20))
    close(T.look_at((1, 2, 3), (0, 0.5, -1), (0, 1, 0)), glm.glm_look_at((1, 2, 3), (0, 0.5, -1), (0, 1, 0)))
    close(T.translate(1, -2, 3.5), glm.glm_translate((1, -2, 3.5)))
    close(T.scale(2, 3, 0.5), glm.glm_scale((2, 3, 0.5)))
    for axis in [(0, 0, 1), (1, 1, 0), (-0.3, 0.2, 0.9)]:
        close(T.rotate(0.7, axis), glm.glm_rotate(0.7, axis))


def test_normal_matrix_equals_glm_inverse_transpose():
    mv = T.look_at((3, 1, 2), (0, 0, 0), (0, 1, 0)) @ T.rotate(0.4, (1, 2, 3)) @ T.scale(2, 1, 0.5)
    close(T.normal_matrix(mv), glm.glm_inverse_transpose(mv), tol=1e-5)


def test_column_major_is_what_uniform_matrix_wants():
    m = T.translate(1, 2, 3)
    assert T.column_major(m)[12:15].tolist() == [1, 2, 3]   # translation in the last column


def test_perspective_maps_near_and_far_to_clip_depth_bounds():
    p = T.perspective(1.0, 1.0, 2.0, 50.0).astype(np.float64)
    for z, ndc in ((-2.0, -1.0), (-50.0, 1.0)):
        clip = p @ [0, 0, z, 1]
        assert math.isclose(clip[2] / clip[3], ndc, abs_tol=1e-6)


def test_shadow_matrix_projects_onto_the_plane_along_light_rays():
    light = np.array([2.0, 5.0, -1.0])
    ms = T.shadow_matrix(light, plane_y=0.0).astype(np.float64)
    rng = np.random.default_rng(3)
    for p in rng.uniform(-2, 2, (20, 3)) + [0, 2.5, 0]:   # points between the light and the plane
        q = ms @ [*p, 1]
        q = q[:3] / q[3]
        assert abs(q[1]) < 1e-9                                    # on the plane y = 0
        # On the ray from the light through p: (q - light) parallel to (p - light).
        assert np.linalg.norm(np.cross(q - light, p - light)) < 1e-6
    lifted = T.shadow_matrix(light, plane_y=0.0, epsilon=0.01).astype(np.float64) @ [0.5, 1, 0.5, 1]
    assert math.isclose(lifted[1] / lifted[3], 0.01, abs_tol=1e-6)


def test_bad_arguments():
    with pytest.raises(ValueError):
        T.perspective(1.0, 1.0, 0.0, 1.0)
    with pytest.raises(ValueError):
        T.look_at((0, 0, 0), (0, 0, 0), (0, 1, 0))
    with pytest.raises(ValueError):
        T.rotate(1.0, (0, 0, 0))
    with pytest.raises(ValueError):
        T.shadow_matrix((0, 0, 0), plane_y=0.0)
