"""4x4 transforms for WebGL scenes, computed in float64 and returned as float32.

Matrices are NumPy (4, 4) arrays in math layout (``m[row, col]``), so they compose with ``@``
and act on column vectors: ``clip = P @ V @ M @ [x, y, z, 1]``. softgl's
``uniformMatrix4fv(loc, False, m)`` takes such a 2-D matrix as it is (math layout); a flat
sequence is column-major, as in WebGL: ``column_major(m)`` gives those 16 floats.
Conventions are OpenGL's (right-handed eye space looking down -z, clip depth in [-1, 1]),
the same as GLM's defaults, which the C++ side uses; the tests compare with GLM.
"""
from __future__ import annotations

import math

import numpy as np


def _m(rows) -> np.ndarray:
    return np.asarray(rows, np.float64).astype(np.float32)


def column_major(m) -> np.ndarray:
    """The 16 floats WebGL's uniformMatrix*fv expects (column by column)."""
    return np.asarray(m, np.float32).T.reshape(-1).copy()


def identity() -> np.ndarray:
    return np.eye(4, dtype=np.float32)


def translate(x: float, y: float, z: float) -> np.ndarray:
    m = np.eye(4)
    m[:3, 3] = (x, y, z)
    return _m(m)


def scale(x: float, y: float | None = None, z: float | None = None) -> np.ndarray:
    y = x if y is None else y
    z = x if z is None else z
    return _m(np.diag([x, y, z, 1.0]))


def rotate(angle_radians: float, axis=(0.0, 0.0, 1.0)) -> np.ndarray:
    """Rotation by `angle_radians` about `axis` (right-hand rule), like glm::rotate."""
    a = np.asarray(axis, np.float64)
    n = np.linalg.norm(a)
    if not n > 0:
        raise ValueError("rotate: the axis must be a non-zero vector")
    x, y, z = a / n
    c, s = math.cos(angle_radians), math.sin(angle_radians)
    t = 1 - c
    return _m([[t * x * x + c, t * x * y - s * z, t * x * z + s * y, 0],
               [t * x * y + s * z, t * y * y + c, t * y * z - s * x, 0],
               [t * x * z - s * y, t * y * z + s * x, t * z * z + c, 0],
               [0, 0, 0, 1]])


def perspective(fovy_radians: float, aspect: float, near: float, far: float) -> np.ndarray:
    """OpenGL perspective projection (glm::perspective / gl-matrix mat4.perspective)."""
    if not (near > 0 and far > near and aspect > 0 and 0 < fovy_radians < math.pi):
        raise ValueError("perspective: need 0 < fovy < pi, aspect > 0 and 0 < near < far")
    f = 1.0 / math.tan(fovy_radians / 2)
    return _m([[f / aspect, 0, 0, 0],
               [0, f, 0, 0],
               [0, 0, (far + near) / (near - far), 2 * far * near / (near - far)],
               [0, 0, -1, 0]])


def ortho(left: float, right: float, bottom: float, top: float, near: float, far: float) -> np.ndarray:
    """OpenGL orthographic projection (glm::ortho)."""
    if right == left or top == bottom or far == near:
        raise ValueError("ortho: the box must have non-zero size")
    return _m([[2 / (right - left), 0, 0, -(right + left) / (right - left)],
               [0, 2 / (top - bottom), 0, -(top + bottom) / (top - bottom)],
               [0, 0, -2 / (far - near), -(far + near) / (far - near)],
               [0, 0, 0, 1]])


def look_at(eye, center, up) -> np.ndarray:
    """View matrix of a camera at `eye` looking at `center` (glm::lookAt)."""
    eye, center, up = (np.asarray(v, np.float64) for v in (eye, center, up))
    f = center - eye
    if not np.linalg.norm(f) > 0:
        raise ValueError("look_at: eye and center must differ")
    f /= np.linalg.norm(f)
    s = np.cross(f, up)
    if not np.linalg.norm(s) > 0:
        raise ValueError("look_at: up must not be parallel to the view direction")
    s /= np.linalg.norm(s)
    u = np.cross(s, f)
    return _m([[*s, -s @ eye], [*u, -u @ eye], [*(-f), f @ eye], [0, 0, 0, 1]])


lookAt = look_at   # the name course code uses


def normal_matrix(model_view) -> np.ndarray:
    """Inverse transpose of the model-view matrix: transforms normals (4x4, as the seed shaders use)."""
    return _m(np.linalg.inv(np.asarray(model_view, np.float64)).T)


def shadow_matrix(light_position, plane_y: float = 0.0, epsilon: float = 0.0) -> np.ndarray:
    """Projection-shadow matrix onto the plane y = plane_y from a point light.

    Ms = T(pl) · Mp · T(-pl): move the light to the origin, project with
    Mp: (x, y, z, 1) -> (x, y, z, y / h), where h is the plane's height relative to the light,
    then move back. `epsilon` lifts the shadow by that much above the plane so that it passes
    a depth test against the plane itself (the usual trick).
    Multiply by the object's model matrix on the right: ``shadow_matrix(pl) @ M``.
    """
    lx, ly, lz = (float(v) for v in light_position)
    height = (plane_y + epsilon) - ly          # plane height relative to the light
    if height == 0:
        raise ValueError("shadow_matrix: the light lies in the shadow plane")
    mp = np.eye(4)
    mp[3, 3] = 0
    mp[3, 1] = 1.0 / height
    return _m(np.asarray(translate(lx, ly, lz), np.float64) @ mp @
              np.asarray(translate(-lx, -ly, -lz), np.float64))
