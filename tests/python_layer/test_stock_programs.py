"""softgl.programs: every stock program compiles and links in WebGL 1 and 2, and draws the
pixels its lighting formula gives when computed in float64 here."""
import numpy as np
import pytest

import softgl
from softgl import programs
from softgl import transforms as T
from layer_util import draw_triangles, fullscreen, pixel_centers_ndc, read, unorm

STOCK = ["constant_color", "vertex_color", "random_color", "lambert", "phong", "lights"]


def normalize(v):
    v = np.asarray(v, np.float64)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


@pytest.mark.parametrize("name", STOCK)
def test_stock_program_links_in_both_versions(name, version):
    gl = softgl.Context(8, 8, antialias=False, version=version)
    prog = getattr(programs, name)(gl)
    assert gl.getProgramParameter(prog.handle, gl.LINK_STATUS)
    assert "aPosition" in prog.attributes
    assert gl.getError() == gl.NO_ERROR


def test_constant_color(gl):
    prog = programs.constant_color(gl).set(uMaterialDiffuse=(0.2, 0.45, 0.71, 0.6))
    draw_triangles(gl, prog, fullscreen())
    img = read(gl)
    assert (img == unorm([0.2, 0.45, 0.71, 0.6])).all()


def test_vertex_color_interpolates(gl):
    prog = programs.vertex_color(gl)
    pos = np.array([[-1, -1, 0], [3, -1, 0], [-1, 3, 0]], np.float32)   # covers the screen
    col = np.array([[1, 0, 0, 1], [0, 1, 0, 1], [0, 0, 1, 1]], np.float32)
    draw_triangles(gl, prog, pos, colors=col)
    x, y = pixel_centers_ndc(32, 24)
    # Barycentrics of the big triangle: (x + 1) / 4 for vertex 1, (y + 1) / 4 for vertex 2.
    l1, l2 = (x + 1) / 4, (y + 1) / 4
    want = unorm(np.stack([1 - l1 - l2, l1, l2, np.ones_like(x)], -1))
    assert np.abs(read(gl) - want).max() <= 1


def test_random_color_matches_reference(gl):
    prog = programs.random_color(gl, seed=17).set(uMaterialDiffuse=(1, 1, 1, 0.5))
    draw_triangles(gl, prog, fullscreen())
    img = read(gl)
    ys, xs = np.mgrid[0:24, 0:32]
    want = unorm(programs.random_color_reference(xs, ys, 17))
    assert np.abs(img[..., :3] - want).max() <= 1
    assert (img[..., 3] == 128).all()
    assert len(np.unique(img[..., :3].reshape(-1, 3), axis=0)) > 500   # it does look random
    other = programs.random_color(gl, seed=18)
    draw_triangles(gl, other, fullscreen())
    assert (read(gl)[..., :3] != img[..., :3]).any()


def lambert_reference(normal, light_direction, view, diffuse, light_diffuse, ambient):
    n = normalize(normal)
    l = normalize((np.asarray(view, np.float64) @ np.append(light_direction, 0.0))[:3])
    lam = max(float(n @ -l), 0.0)
    return np.asarray(ambient) + np.asarray(light_diffuse) * np.asarray(diffuse) * lam


def test_lambert_with_view_and_normal_matrix(gl):
    view = T.rotate(0.4, (0, 1, 0))
    model = T.rotate(-0.3, (1, 0, 0))
    nm = T.normal_matrix(view @ model)
    normal = np.array([0.2, 0.3, 1.0])
    eye_normal = (np.asarray(nm, np.float64) @ np.append(normal, 0.0))[:3]
    diffuse, light, ambient = (0.9, 0.6, 0.3, 0.8), (1.0, 0.9, 0.7, 1.0), (0.1, 0.1, 0.1, 1.0)
    direction = (-0.3, -0.5, -1.0)
    prog = programs.lambert(gl).set(uMaterialDiffuse=diffuse, uLightDiffuse=light,
                                    uLightAmbient=ambient, uMaterialAmbient=(1, 1, 1, 1),
                                    uLightDirection=direction, uNormalMatrix=nm, uView=view, uModel=model,
                                    uProjection=np.linalg.inv(np.asarray(view, np.float64) @ model))
    # uProjection undoes view*model, so the full-screen quad stays full-screen.
    draw_triangles(gl, prog, fullscreen(), normals=np.tile(normal, (6, 1)))
    want = lambert_reference(eye_normal, direction, view, diffuse, light, np.multiply(ambient, 1))
    want[3] = diffuse[3]
    assert np.abs(read(gl) - unorm(want)).max() <= 1


def test_phong_per_pixel(gl):
    normal = normalize([0.1, -0.2, 1.0])
    direction = normalize([0.3, 0.2, -1.0])
    diffuse, ambient, spec, shininess = (0.5, 0.4, 0.3, 1.0), (0.05, 0.05, 0.05, 1.0), (0.6, 0.6, 0.6, 1.0), 8.0
    prog = programs.phong(gl).set(uMaterialDiffuse=diffuse, uLightAmbient=ambient,
                                  uLightDirection=direction, uMaterialSpecular=spec,
                                  uShininess=shininess)
    # Eye space = clip space here (identity matrices), with the quad pushed back to z = -0.5.
    draw_triangles(gl, prog, fullscreen(-0.5), normals=np.tile(normal, (6, 1)))
    x, y = pixel_centers_ndc(32, 24)
    p = np.stack([x, y, np.full_like(x, -0.5)], -1)
    lam = max(float(normal @ -direction), 0.0)
    r = direction - 2 * (normal @ direction) * normal        # reflect(L, N)
    e = normalize(-p)
    s = np.maximum(e @ r, 0.0) ** shininess
    want = np.asarray(ambient)[:3] + np.asarray(diffuse)[:3] * lam + np.asarray(spec)[:3] * s[..., None]
    img = read(gl)
    assert np.abs(img[..., :3] - unorm(want)).max() <= 1
    assert np.ptp(img[..., 0]) > 10   # the highlight varies over the quad


def lights_reference(p, normal, lights, diffuse, ambient):
    """The course notes' N-light formula in float64 at eye positions p (..., 3); view = identity."""
    n = normalize(normal)
    total = np.zeros(p.shape[:-1] + (4,))
    for position, direction, color, cutoff in lights:
        d = np.asarray(direction, np.float64)
        spot = d @ d > 0
        nn = normalize(n - d) if spot else n   # D as given, as in the lesson
        l = normalize(p - np.asarray(position))
        lam = -(l @ nn)
        f = np.where(lam > cutoff, (np.maximum(lam, 0) ** (10 * cutoff)) if spot else lam, 0.0)
        total += np.asarray(color) * np.asarray(diffuse) * f[..., None]
        yield_mask = np.abs(lam - cutoff) < 1e-3   # too close to the cut to call
        total[yield_mask] = np.nan
    return np.asarray(ambient) + total


def test_lights_point_and_spots_with_cutoff():
    gl = softgl.Context(48, 40, antialias=False)
    lights = [((0.0, 0.0, 1.0), (0.0, 0.0, 0.0), (0.8, 0.2, 0.2, 1.0), 0.0),       # point
              ((-0.5, 0.3, 0.8), (0.3, -0.2, -1.0), (0.2, 0.9, 0.3, 1.0), 0.6),   # spot
              ((0.6, -0.4, 0.5), (-0.4, 0.5, -1.0), (0.3, 0.3, 1.0, 1.0), 0.85)]  # narrow spot
    diffuse, ambient = (0.9, 0.8, 0.7, 1.0), (0.05, 0.04, 0.03, 1.0)
    prog = programs.lights(gl, 3).set(
        uLightPositions=[l[0] for l in lights], uLightDirections=[l[1] for l in lights],
        uLightColors=[l[2] for l in lights], uLightCutoffs=[l[3] for l in lights],
        uMaterialDiffuse=diffuse, uLightAmbient=ambient)
    normal = (0.0, 0.0, 1.0)
    draw_triangles(gl, prog, fullscreen(), normals=np.tile(normal, (6, 1)))
    x, y = pixel_centers_ndc(48, 40)
    p = np.stack([x, y, np.zeros_like(x)], -1)
    want = lights_reference(p, np.array(normal), lights, diffuse, ambient)
    img = read(gl)
    ok = ~np.isnan(want[..., 0])
    assert ok.mean() > 0.9
    diff = np.abs(img[..., :3] - unorm(np.nan_to_num(want[..., :3])))
    assert diff[ok].max() <= 1
    # Each spotlight lights a patch and leaves other pixels dark: the cutoff acts.
    assert (img[..., 1] > 150).any() and (img[..., 1] < 80).any()


def test_visibility_zero_draws_black_shadow_keeping_alpha(gl):
    prog = programs.lambert(gl).set(uVisibility=0.0, uMaterialDiffuse=(1, 0.5, 0.2, 0.4))
    draw_triangles(gl, prog, fullscreen(), normals=np.tile((0, 0, 1), (6, 1)))
    assert (read(gl) == [0, 0, 0, 102]).all()


def test_premultiply(gl):
    prog = programs.constant_color(gl).set(uMaterialDiffuse=(1.0, 0.5, 0.2, 0.4), uPremultiply=True)
    draw_triangles(gl, prog, fullscreen())
    assert (read(gl) == unorm([0.4, 0.2, 0.08, 0.4])).all()


def test_program_set_matrix_layouts_and_errors(gl):
    prog = programs.constant_color(gl)
    m = T.translate(0.5, 0, 0) @ T.scale(0.5)
    prog.set(uModel=m)
    a = gl.getUniform(prog.handle, prog.uniforms["uModel"][0])
    prog.set(uModel=T.column_major(m))          # 16 floats: already column-major
    b = gl.getUniform(prog.handle, prog.uniforms["uModel"][0])
    np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(a, T.column_major(m))
    prog.set(uNotThere=1.0)                     # skipped, as WebGL skips a None location
    with pytest.raises(ValueError, match="uMaterialDiffuse"):
        prog.set(uMaterialDiffuse=(1, 0, 0))
    assert gl.getError() == gl.NO_ERROR


def test_uniform_arrays_take_all_elements():
    gl = softgl.Context(4, 4, antialias=False)
    prog = programs.lights(gl, 4)
    colors = np.arange(16, dtype=np.float32).reshape(4, 4) / 16
    prog.set(uLightColors=colors)
    for i in range(4):
        loc = gl.getUniformLocation(prog.handle, f"uLightColors[{i}]")
        np.testing.assert_array_equal(gl.getUniform(prog.handle, loc), colors[i])
    with pytest.raises(ValueError):
        prog.set(uLightColors=np.zeros((5, 4)))


def test_shader_error_has_log(gl):
    with pytest.raises(programs.ShaderError) as e:
        programs.Program(gl, "void main() { gl_Position = vec4(0.0); }", "void main() { oops; }")
    assert "oops" in str(e.value) or e.value.log
