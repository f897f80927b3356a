"""softgl.geometry checked against closed-form volumes and areas, and against properties that
any correct mesh has (orientation, closedness, unit normals), computed here independently."""
import math

import numpy as np
import pytest

from softgl import geometry as G, transforms as T

SOLIDS = {  # closed meshes, convex ones marked
    "cube": (lambda: G.cube(1.3), True),
    "sphere": (lambda: G.sphere(0.8, 24, 12), True),
    "cylinder": (lambda: G.cylinder(0.6, 1.5, 20), True),
    "cone": (lambda: G.cone(0.7, 1.2, 20), True),
    "torus": (lambda: G.torus(1.0, 0.3, 24, 12), False),
}
OPEN = {
    "quad": lambda: G.quad(2.0, 1.0),
    "plane": lambda: G.plane(3.0, 2.0, 4, 3),
    "open_cylinder": lambda: G.cylinder(capped=False),
    "open_cone": lambda: G.cone(capped=False),
}
ALL = {**{k: f for k, (f, _) in SOLIDS.items()}, **OPEN}


def triangles(mesh):
    return mesh.positions.astype(np.float64)[mesh.triangles]


def face_cross(mesh):
    """Per triangle (b - a) x (c - a): twice the area, along the CCW normal."""
    t = triangles(mesh)
    return np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])


def signed_volume(mesh):
    """Divergence theorem: sum of signed tetrahedra (origin, a, b, c); positive when every
    triangle is CCW seen from outside."""
    t = triangles(mesh)
    return np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum() / 6


def area(mesh):
    return np.linalg.norm(face_cross(mesh), axis=1).sum() / 2


@pytest.mark.parametrize("name", ALL)
def test_arrays_have_webgl_ready_shapes_and_dtypes(name):
    m = ALL[name]()
    n = len(m.positions)
    assert m.positions.shape == (n, 3) and m.positions.dtype == np.float32
    assert m.normals.shape == (n, 3) and m.normals.dtype == np.float32
    assert m.uvs.shape == (n, 2) and m.uvs.dtype == np.float32
    assert m.indices.ndim == 1 and m.indices.dtype == np.uint16 and m.index_type == 0x1403
    assert m.count == len(m.indices) and m.count % 3 == 0
    for a in (m.positions, m.normals, m.uvs, m.indices):
        assert a.flags.c_contiguous
    assert m.indices.max() < n
    assert np.unique(m.indices).size == n, "every vertex is used by some triangle"


@pytest.mark.parametrize("name", ALL)
def test_normals_unit_uvs_in_range_no_degenerate_triangles(name):
    m = ALL[name]()
    np.testing.assert_allclose(np.linalg.norm(m.normals, axis=1), 1.0, atol=1e-6)
    assert m.uvs.min() >= 0.0 and m.uvs.max() <= 1.0
    doubled_areas = np.linalg.norm(face_cross(m), axis=1)
    assert doubled_areas.min() > 1e-4 * doubled_areas.mean()


@pytest.mark.parametrize("name", ALL)
def test_winding_agrees_with_vertex_normals(name):
    # A CCW triangle's geometric normal must point the same way as its shading normals.
    m = ALL[name]()
    shading = m.normals.astype(np.float64)[m.triangles].sum(axis=1)
    assert (np.einsum("ij,ij->i", face_cross(m), shading) > 0).all()


@pytest.mark.parametrize("name", [k for k, (_, convex) in SOLIDS.items() if convex])
def test_convex_solids_wind_ccw_from_outside(name):
    m = SOLIDS[name][0]()
    centroids = triangles(m).mean(axis=1)
    assert (np.einsum("ij,ij->i", face_cross(m), centroids) > 0).all()   # centre is the origin


def test_torus_winds_ccw_from_outside():
    major = 1.0
    m = G.torus(major, 0.3, 24, 12)
    c = triangles(m).mean(axis=1)
    radial = c * [1, 0, 1]
    core = major * radial / np.linalg.norm(radial, axis=1, keepdims=True)   # nearest ring point
    assert (np.einsum("ij,ij->i", face_cross(m), c - core) > 0).all()


@pytest.mark.parametrize("name", SOLIDS)
def test_solids_are_closed_and_consistently_oriented(name):
    # Weld the seam duplicates by position; in a closed, consistently wound surface every
    # directed edge appears once and its reverse once.
    m = SOLIDS[name][0]()
    _, weld = np.unique(np.round(m.positions, 5), axis=0, return_inverse=True)
    t = weld.reshape(-1)[m.triangles]
    edges = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    directed = set(map(tuple, edges))
    assert len(directed) == len(edges), "a directed edge is used twice: inconsistent winding"
    assert all((b, a) in directed for a, b in directed), "a boundary edge: the mesh is open"


@pytest.mark.parametrize("name", ALL)
def test_front_faces_are_ccw_on_screen(name):
    # Through WebGL's own transforms: faces turned to the eye must land counter-clockwise in
    # NDC (front under frontFace(CCW)), faces turned away clockwise.
    m = ALL[name]()
    eye = np.array([1.7, 2.3, 3.1])
    mvp = T.perspective(math.radians(50), 1.0, 0.1, 50) @ T.look_at(eye, (0, 0, 0), (0, 1, 0))
    t = triangles(m)
    clip = np.concatenate([t, np.ones(t.shape[:2] + (1,))], axis=2) @ mvp.T.astype(np.float64)
    ndc = clip[..., :2] / clip[..., 3:]
    e1, e2 = ndc[:, 1] - ndc[:, 0], ndc[:, 2] - ndc[:, 0]
    screen_area = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    facing = np.einsum("ij,ij->i", face_cross(m), eye - t.mean(axis=1))
    keep = np.abs(facing) > 1e-6   # skip faces seen exactly edge-on
    assert (np.sign(screen_area[keep]) == np.sign(facing[keep])).all()


@pytest.mark.parametrize("name", ALL)
def test_textures_are_not_mirrored(name):
    # dP/du x dP/dv = (e1 x e2) / det(uv edges): it points outward iff each triangle is CCW in
    # uv space too.
    m = ALL[name]()
    uv = m.uvs.astype(np.float64)[m.triangles]
    d1, d2 = uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]
    assert (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0] > 0).all()


def test_cube_volume_area_and_layout():
    s = 1.3
    m = G.cube(s)
    assert len(m.positions) == 24 and m.count == 36 and m.colors is None
    assert signed_volume(m) == pytest.approx(s ** 3, rel=1e-6)
    assert area(m) == pytest.approx(6 * s ** 2, rel=1e-6)
    np.testing.assert_allclose(np.abs(m.positions), s / 2, rtol=1e-6)
    # Flat faces: each group of 4 vertices shares the normal that its points lie along.
    normals = m.normals.reshape(6, 4, 3)
    assert (normals == normals[:, :1]).all()
    np.testing.assert_allclose(np.einsum("fvi,fvi->fv", m.positions.reshape(6, 4, 3), normals), s / 2,
                               rtol=1e-6)
    np.testing.assert_array_equal(normals[:, 0], [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0],
                                                  [0, 0, 1], [0, 0, -1]])


def test_cube_face_colors():
    m = G.cube(face_colors=G.ALPHA_CUBE_FACE_COLORS)
    assert m.colors.shape == (24, 4) and m.colors.dtype == np.float32
    per_face = m.colors.reshape(6, 4, 4)
    np.testing.assert_array_equal(per_face, np.repeat(G.ALPHA_CUBE_FACE_COLORS[:, None], 4, axis=1))
    assert len({tuple(c) for c in G.ALPHA_CUBE_FACE_COLORS}) == 6 and (per_face[..., 3] == 0.5).all()
    # Every triangle takes its color from one face only (flat faces, as the alpha cube draws).
    assert (m.colors[m.triangles] == m.colors[m.triangles][:, :1]).all()
    rgb = G.cube(face_colors=np.eye(3).repeat(2, axis=0))
    assert (rgb.colors[:, 3] == 1).all()
    with pytest.raises(ValueError):
        G.cube(face_colors=[[1, 0, 0, 1]] * 5)


def test_sphere_points_and_normals_are_radial():
    r = 0.8
    m = G.sphere(r, 24, 12)
    np.testing.assert_allclose(np.linalg.norm(m.positions, axis=1), r, rtol=1e-6)
    np.testing.assert_allclose(m.normals, m.positions / r, atol=1e-6)
    # One vertex per cell at each pole (no degenerate fans), rows of segments + 1 between.
    assert len(m.positions) == 2 * 24 + 11 * 25
    assert m.count == 3 * (2 * 24 + 10 * 2 * 24)


def volume_area_errors(make, volume, surface, sizes):
    return [(abs(signed_volume(make(*n)) - volume) / volume, abs(area(make(*n)) - surface) / surface)
            for n in sizes]


def test_sphere_volume_and_area_converge_quadratically():
    r = 0.8
    errors = volume_area_errors(lambda s, k: G.sphere(r, s, k), 4 / 3 * math.pi * r ** 3,
                                4 * math.pi * r ** 2, [(16, 8), (32, 16), (64, 32), (128, 64)])
    for (v0, a0), (v1, a1) in zip(errors, errors[1:]):
        assert 3.5 < v0 / v1 < 4.5 and 3.5 < a0 / a1 < 4.5   # halving the step quarters the error
    # Vertices lie on the sphere and no face spans more than the angular step d, so the
    # polyhedron sits between the spheres of radius r cos(d) and r: bounds on both errors.
    d = 2 * math.pi / 128
    assert errors[-1][0] < 1 - math.cos(d) ** 3 and errors[-1][1] < 1 - math.cos(d) ** 2
    assert signed_volume(G.sphere(r, 64, 32)) < 4 / 3 * math.pi * r ** 3   # inscribed


def test_torus_volume_and_area_converge_quadratically():
    R, r = 1.0, 0.3
    errors = volume_area_errors(lambda s, k: G.torus(R, r, s, k), 2 * math.pi ** 2 * R * r ** 2,
                                4 * math.pi ** 2 * R * r, [(24, 12), (48, 24), (96, 48)])
    for (v0, a0), (v1, a1) in zip(errors, errors[1:]):
        assert 3.5 < v0 / v1 < 4.5 and 3.5 < a0 / a1 < 4.5
    d = 2 * math.pi / 48   # the coarser angular step of the finest torus
    assert errors[-1][0] < d ** 2 and errors[-1][1] < d ** 2
    ring = np.linalg.norm(G.torus(R, r).positions[:, [0, 2]], axis=1)
    tube = np.hypot(ring - R, G.torus(R, r).positions[:, 1])
    np.testing.assert_allclose(tube, r, rtol=1e-5)


@pytest.mark.parametrize("n", [3, 7, 20])
def test_cylinder_is_the_inscribed_prism(n):
    r, h = 0.6, 1.5
    m = G.cylinder(r, h, n)
    polygon = n / 2 * r ** 2 * math.sin(2 * math.pi / n)   # regular n-gon inscribed in r
    chord = 2 * r * math.sin(math.pi / n)
    assert signed_volume(m) == pytest.approx(polygon * h, rel=1e-6)
    assert area(m) == pytest.approx(n * chord * h + 2 * polygon, rel=1e-6)
    side = np.abs(m.normals[:, 1]) < 0.5
    np.testing.assert_allclose(m.normals[side], m.positions[side] * [1, 0, 1] / r, atol=1e-6)


@pytest.mark.parametrize("n", [3, 7, 20])
def test_cone_is_the_inscribed_pyramid(n):
    r, h = 0.7, 1.2
    m = G.cone(r, h, n)
    polygon = n / 2 * r ** 2 * math.sin(2 * math.pi / n)
    chord = 2 * r * math.sin(math.pi / n)
    slant = math.hypot(h, r * math.cos(math.pi / n))   # height of each side triangle
    assert signed_volume(m) == pytest.approx(polygon * h / 3, rel=1e-6)
    assert area(m) == pytest.approx(n * chord * slant / 2 + polygon, rel=1e-6)


def test_cone_side_normals_are_perpendicular_to_the_slant():
    r, h = 0.7, 1.2
    m = G.cone(r, h, 16, capped=False)
    apex = np.array([0, h / 2, 0])
    base = m.positions[m.positions[:, 1] < 0]
    slant = apex - base
    np.testing.assert_allclose(np.einsum("ij,ij->i", slant, m.normals[m.positions[:, 1] < 0]), 0,
                               atol=1e-6)
    assert (m.normals[:, 1] > 0).all()   # the side leans up


def test_quad_and_plane():
    q = G.quad(2.0, 1.0)
    assert len(q.positions) == 4 and q.count == 6
    assert area(q) == pytest.approx(2.0)
    assert (q.positions[:, 2] == 0).all() and (q.normals == [0, 0, 1]).all()
    assert sorted(map(tuple, q.uvs.tolist())) == [(0, 0), (0, 1), (1, 0), (1, 1)]
    p = G.plane(3.0, 2.0, 4, 3)
    assert len(p.positions) == 5 * 4 and p.count == 4 * 3 * 6
    assert area(p) == pytest.approx(6.0)
    assert (p.positions[:, 1] == 0).all() and (p.normals == [0, 1, 0]).all()
    assert np.ptp(p.positions[:, 0]) == pytest.approx(3.0) and np.ptp(p.positions[:, 2]) == pytest.approx(2.0)


def test_index_type_widens_past_65534():
    # 0xFFFF is WebGL 2's primitive-restart index for UNSIGNED_SHORT, so it must never be a vertex.
    def mesh(n):
        return G.Mesh(np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 2)), [0, 1, n - 1])
    assert mesh(0xFFFF).indices.dtype == np.uint16
    assert mesh(0x10000).indices.dtype == np.uint32 and mesh(0x10000).index_type == 0x1405
    big = G.sphere(1.0, 400, 200)
    assert big.indices.dtype == np.uint32 and big.indices.max() == len(big.positions) - 1 > 0xFFFF
    assert big.index_type == 0x1405


def test_unindexed_mesh_draws_the_same_triangles():
    m = G.cube(face_colors=G.ALPHA_CUBE_FACE_COLORS)
    flat = m.unindexed()
    assert len(flat.positions) == flat.count == 36
    np.testing.assert_array_equal(flat.positions, m.positions[m.indices])
    np.testing.assert_array_equal(flat.colors, m.colors[m.indices])
    np.testing.assert_array_equal(flat.indices, np.arange(36))


def test_bad_arguments_raise():
    with pytest.raises(ValueError):
        G.sphere(segments=2)
    with pytest.raises(ValueError):
        G.torus(sides=2.5)
    with pytest.raises(ValueError):
        G.plane(x_segments=0)
    with pytest.raises(ValueError):
        G.Mesh(np.zeros((3, 3)), np.zeros((3, 3)), np.zeros((3, 2)), [0, 1, 3])
    with pytest.raises(ValueError):
        G.Mesh(np.zeros((3, 3)), np.zeros((3, 3)), np.zeros((3, 2)), [0, 1])
