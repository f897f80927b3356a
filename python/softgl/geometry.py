"""Meshes for WebGL scenes: quad, cube, sphere, cone, cylinder, torus and a plane grid.

Every function returns a :class:`Mesh` of NumPy arrays ready for ``bufferData``:
positions and normals (N, 3) float32, uvs (N, 2) float32 in [0, 1], colors (N, 4) float32
or None, and triangle indices (M,) for ``drawElements(gl.TRIANGLES, mesh.count,
mesh.index_type, 0)``.

Conventions (WebGL's defaults, so nothing needs changing on the context):

- right-handed, y up; solids are centred on the origin;
- front faces are counter-clockwise seen from outside (``frontFace(CCW)``, ``cullFace(BACK)``
  culls the inside);
- normals are unit length and point outward;
- textures are not mirrored: seen from outside, u grows to the right and v grows upward
  (WebGL's texture v = 0 is the first row uploaded).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# WebGL's index types (values as in the WebGL IDL).
UNSIGNED_SHORT = 0x1403
UNSIGNED_INT = 0x1405

# Six RGBA colors with alpha 0.5, one per face in the order +x, -x, +y, -y, +z, -z, from the
# palette of the course notes' alpha cube: cube(face_colors=ALPHA_CUBE_FACE_COLORS).
ALPHA_CUBE_FACE_COLORS = np.array([
    [1.0, 1.0, 0.0, 0.5],   # +x yellow
    [1.0, 0.0, 1.0, 0.5],   # -x magenta
    [1.0, 1.0, 1.0, 0.5],   # +y white
    [0.0, 1.0, 0.0, 0.5],   # -y green
    [1.0, 0.0, 0.0, 0.5],   # +z red
    [0.0, 0.0, 1.0, 0.5],   # -z blue
], np.float32)


@dataclass
class Mesh:
    """Triangles with per-vertex attributes; see the module docstring for conventions."""
    positions: np.ndarray
    normals: np.ndarray
    uvs: np.ndarray
    indices: np.ndarray
    colors: np.ndarray | None = None

    def __post_init__(self):
        self.positions = np.ascontiguousarray(self.positions, np.float32).reshape(-1, 3)
        n = len(self.positions)
        self.normals = np.ascontiguousarray(self.normals, np.float32).reshape(n, 3)
        self.uvs = np.ascontiguousarray(self.uvs, np.float32).reshape(n, 2)
        if self.colors is not None:
            self.colors = np.ascontiguousarray(self.colors, np.float32).reshape(n, 4)
        indices = np.asarray(self.indices).reshape(-1)
        if len(indices) % 3:
            raise ValueError(f"Mesh: {len(indices)} indices is not a whole number of triangles")
        if len(indices) and (indices.min() < 0 or indices.max() >= n):
            raise ValueError("Mesh: an index is out of range")
        self.indices = np.ascontiguousarray(indices, _index_dtype(n))

    @property
    def count(self) -> int:
        """Number of indices (the `count` argument of drawElements)."""
        return len(self.indices)

    @property
    def index_type(self) -> int:
        """gl.UNSIGNED_SHORT or gl.UNSIGNED_INT, matching the dtype of `indices`."""
        return UNSIGNED_SHORT if self.indices.dtype == np.uint16 else UNSIGNED_INT

    @property
    def triangles(self) -> np.ndarray:
        """Indices as (M/3, 3)."""
        return self.indices.reshape(-1, 3)

    def unindexed(self) -> "Mesh":
        """The same triangles with vertices repeated, for drawArrays(gl.TRIANGLES, 0, count)."""
        i = self.indices
        return Mesh(self.positions[i], self.normals[i], self.uvs[i], np.arange(len(i)),
                    None if self.colors is None else self.colors[i])


def _index_dtype(vertex_count: int):
    # WebGL 2 always enables primitive restart with the fixed index 0xFFFF for UNSIGNED_SHORT
    # (WebGL 2 spec §5.18), so 16-bit indices may only reach 65534.
    return np.uint16 if vertex_count <= 0xFFFF else np.uint32


def _concat(parts: list[Mesh]) -> Mesh:
    offsets = np.cumsum([0] + [len(p.positions) for p in parts[:-1]])
    colored = [p.colors is not None for p in parts]
    if any(colored) and not all(colored):
        raise ValueError("_concat: either every part has colors or none has")
    return Mesh(np.concatenate([p.positions for p in parts]),
                np.concatenate([p.normals for p in parts]),
                np.concatenate([p.uvs for p in parts]),
                np.concatenate([p.indices.astype(np.int64) + o for p, o in zip(parts, offsets)]),
                np.concatenate([p.colors for p in parts]) if all(colored) else None)


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _surface(fn, nu: int, nv: int, *, collapse_v0=False, collapse_v1=False) -> Mesh:
    """Triangulate a parametric patch fn(u, v) -> (points, normals) over [0, 1]^2.

    fn must be oriented so that dP/du x dP/dv points outward: then the cell corners
    (u,v), (u+1,v), (u+1,v+1), (u,v+1) are counter-clockwise seen from outside.
    A collapsed row (a sphere pole, a cone apex) gets one vertex per cell, placed at the cell's
    middle u, and one triangle per cell instead of two, so no triangle is degenerate.
    """
    rows = []   # (first vertex index, collapsed)
    pts, nrm, uvs = [], [], []
    count = 0
    for i in range(nv + 1):
        collapsed = (i == 0 and collapse_v0) or (i == nv and collapse_v1)
        u = (np.arange(nu) + 0.5) / nu if collapsed else np.arange(nu + 1) / nu
        v = np.full_like(u, i / nv)
        p, n = fn(u, v)
        pts.append(p)
        nrm.append(_unit(n))
        uvs.append(np.stack([u, v], axis=1))
        rows.append((count, collapsed))
        count += len(u)
    j = np.arange(nu)
    tris = []
    for i in range(nv):
        (lo, lo_collapsed), (hi, hi_collapsed) = rows[i], rows[i + 1]
        a, b, c, d = lo + j, lo + j + 1, hi + j + 1, hi + j
        if lo_collapsed:          # a is this cell's pole vertex
            tris.append(np.stack([a, c, d], axis=1))
        elif hi_collapsed:        # d is this cell's pole vertex
            tris.append(np.stack([a, b, d], axis=1))
        else:
            tris.append(np.stack([a, b, c, a, c, d], axis=1).reshape(-1, 3))
    return Mesh(np.concatenate(pts), np.concatenate(nrm), np.concatenate(uvs),
                np.concatenate(tris).reshape(-1))


def _ring(phi: np.ndarray) -> np.ndarray:
    """Unit vectors in the xz plane; phi = 0 points to -z (the back), so a texture's seam is at
    the back and its middle (u = 0.5) faces +z, towards the default camera."""
    return np.stack([-np.sin(phi), np.zeros_like(phi), -np.cos(phi)], axis=1)


def _disc(radius: float, y: float, up: bool, segments: int) -> Mesh:
    """A flat cap at height y facing +y (up) or -y, with planar uvs seen from outside."""
    phi = 2 * np.pi * np.arange(segments) / segments
    ring = radius * _ring(phi)
    pts = np.concatenate([[[0.0, 0.0, 0.0]], ring]) + [0.0, y, 0.0]
    normal = [0.0, 1.0 if up else -1.0, 0.0]
    # Looking down on the top cap, +x is right and -z is up; looking up at the bottom, +z is up.
    s = pts[:, [0, 2]] / (2 * radius)
    uvs = 0.5 + s * ([1.0, -1.0] if up else [1.0, 1.0])
    j = np.arange(segments)
    k = (j + 1) % segments
    order = (j + 1, k + 1) if up else (k + 1, j + 1)   # counter-clockwise seen from outside
    tris = np.stack([np.zeros_like(j), *order], axis=1)
    return Mesh(pts, np.tile(normal, (segments + 1, 1)), uvs, tris.reshape(-1))


def _check_segments(**counts):
    for name, (value, least) in counts.items():
        if int(value) != value or value < least:
            raise ValueError(f"{name} must be an integer >= {least}, got {value}")


def quad(width: float = 1.0, height: float = 1.0) -> Mesh:
    """A width x height rectangle in the z = 0 plane facing +z (quad(2, 2) covers clip space)."""
    def fn(u, v):
        p = np.stack([(u - 0.5) * width, (v - 0.5) * height, np.zeros_like(u)], axis=1)
        return p, np.tile([0.0, 0.0, 1.0], (len(u), 1))
    return _surface(fn, 1, 1)


def plane(width: float = 1.0, depth: float = 1.0, x_segments: int = 1,
          z_segments: int = 1) -> Mesh:
    """A width (x) by depth (z) grid in the y = 0 plane facing +y: a floor.

    u grows along +x and v along -z, so the texture reads upright from a camera in front of it.
    """
    _check_segments(x_segments=(x_segments, 1), z_segments=(z_segments, 1))

    def fn(u, v):
        p = np.stack([(u - 0.5) * width, np.zeros_like(u), (0.5 - v) * depth], axis=1)
        return p, np.tile([0.0, 1.0, 0.0], (len(u), 1))
    return _surface(fn, x_segments, z_segments)


def cube(size: float = 1.0, face_colors=None) -> Mesh:
    """An axis-aligned cube of edge `size`: 24 vertices (4 per face, flat normals), 36 indices.

    Faces come in the order +x, -x, +y, -y, +z, -z. `face_colors` gives one RGB or RGBA color per
    face, e.g. ALPHA_CUBE_FACE_COLORS for the course notes' alpha cube; colors is None otherwise.
    """
    # (outward normal, u axis, v axis) with u x v = normal, so each face is CCW from outside.
    frames = [((1, 0, 0), (0, 0, -1), (0, 1, 0)), ((-1, 0, 0), (0, 0, 1), (0, 1, 0)),
              ((0, 1, 0), (1, 0, 0), (0, 0, -1)), ((0, -1, 0), (1, 0, 0), (0, 0, 1)),
              ((0, 0, 1), (1, 0, 0), (0, 1, 0)), ((0, 0, -1), (-1, 0, 0), (0, 1, 0))]
    faces = []
    for n, du, dv in frames:
        n, du, dv = (np.array(a, np.float64) for a in (n, du, dv))

        def fn(u, v, n=n, du=du, dv=dv):
            p = (n + np.outer(2 * u - 1, du) + np.outer(2 * v - 1, dv)) * (size / 2)
            return p, np.tile(n, (len(u), 1))
        faces.append(_surface(fn, 1, 1))
    mesh = _concat(faces)
    if face_colors is not None:
        c = np.asarray(face_colors, np.float32)
        if c.shape not in ((6, 3), (6, 4)):
            raise ValueError(f"cube: face_colors must be 6 RGB or RGBA colors, got shape {c.shape}")
        if c.shape[1] == 3:
            c = np.concatenate([c, np.ones((6, 1), np.float32)], axis=1)
        mesh.colors = np.repeat(c, 4, axis=0)
    return mesh


def sphere(radius: float = 1.0, segments: int = 32, rings: int = 16) -> Mesh:
    """A UV sphere: `segments` around the y axis, `rings` from pole to pole (u = longitude,
    v = latitude from the south pole, 0, to the north pole, 1)."""
    _check_segments(segments=(segments, 3), rings=(rings, 2))

    def fn(u, v):
        theta = np.pi * (1 - v)                      # angle from +y
        n = np.sin(theta)[:, None] * _ring(2 * np.pi * u)
        n[:, 1] = np.cos(theta)
        return radius * n, n
    return _surface(fn, segments, rings, collapse_v0=True, collapse_v1=True)


def cylinder(radius: float = 0.5, height: float = 1.0, segments: int = 32,
             capped: bool = True) -> Mesh:
    """A cylinder along y from -height/2 to height/2; smooth sides, flat caps when `capped`."""
    _check_segments(segments=(segments, 3))

    def fn(u, v):
        n = _ring(2 * np.pi * u)
        return radius * n + np.outer(v - 0.5, [0, height, 0]), n
    parts = [_surface(fn, segments, 1)]
    if capped:
        parts += [_disc(radius, height / 2, True, segments), _disc(radius, -height / 2, False, segments)]
    return _concat(parts)


def cone(radius: float = 0.5, height: float = 1.0, segments: int = 32,
         capped: bool = True) -> Mesh:
    """A cone along y: base of `radius` at -height/2, apex at +height/2; smooth sides (the apex
    has one vertex per segment so each keeps its own normal), a flat base when `capped`."""
    _check_segments(segments=(segments, 3))

    def fn(u, v):
        r = _ring(2 * np.pi * u)
        # The side's normal leans up by the slope: perpendicular to the line base -> apex.
        n = height * r + [0.0, radius, 0.0]
        return radius * (1 - v)[:, None] * r + np.outer(v - 0.5, [0, height, 0]), n
    parts = [_surface(fn, segments, 1, collapse_v1=True)]
    if capped:
        parts.append(_disc(radius, -height / 2, False, segments))
    return _concat(parts)


def torus(major_radius: float = 0.75, minor_radius: float = 0.25, segments: int = 48,
          sides: int = 16) -> Mesh:
    """A torus around the y axis: `segments` around the ring, `sides` around the tube
    (v = 0 on the outer equator)."""
    _check_segments(segments=(segments, 3), sides=(sides, 3))

    def fn(u, v):
        r = _ring(2 * np.pi * u)
        psi = 2 * np.pi * v
        n = np.cos(psi)[:, None] * r
        n[:, 1] = np.sin(psi)
        return major_radius * r + minor_radius * n, n
    return _surface(fn, segments, sides)
