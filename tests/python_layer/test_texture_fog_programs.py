"""Stock textured, multitextured and fogged programs, the GLSL fog snippets, and the scene layer's
textures and fog, against float64 formulas computed here."""
import math

import numpy as np
import pytest

import softgl
from softgl import geometry, programs, scene
from softgl import transforms as T
from layer_util import read, unorm

W, H = 16, 8


def upload(gl, unit, image, filt=None):
    gl.activeTexture(gl.TEXTURE0 + unit)
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    h, w, n = image.shape
    fmt = gl.RGBA if n == 4 else gl.RGB
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1)
    gl.texImage2D(gl.TEXTURE_2D, 0, fmt, w, h, 0, fmt, gl.UNSIGNED_BYTE, np.ascontiguousarray(image))
    for p in (gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER):
        gl.texParameteri(gl.TEXTURE_2D, p, filt or gl.NEAREST)
    for p in (gl.TEXTURE_WRAP_S, gl.TEXTURE_WRAP_T):
        gl.texParameteri(gl.TEXTURE_2D, p, gl.REPEAT)
    return tex


def textures(seed=3):
    rng = np.random.default_rng(seed)
    return (rng.integers(0, 256, (H, W, 4), dtype=np.uint8),
            rng.integers(0, 256, (H, W, 4), dtype=np.uint8))


@pytest.mark.parametrize("name", ["textured", "multitextured", "fogged"])
def test_new_stock_programs_link_in_both_versions(name, version):
    gl = softgl.Context(4, 4, antialias=False, version=version)
    prog = getattr(programs, name)(gl)
    assert gl.getProgramParameter(prog.handle, gl.LINK_STATUS)
    assert gl.getError() == gl.NO_ERROR


def test_textured_maps_one_texel_per_pixel():
    gl = softgl.Context(W, H, antialias=False)
    t0, _ = textures()
    upload(gl, 0, t0)
    prog = programs.textured(gl)
    scene.draw_mesh(gl, prog, geometry.quad(2, 2))        # uvs 0..1 over the whole viewport
    assert (read(gl) == t0).all()                           # row 0 of the texture at the bottom
    # uMaterialDiffuse tints, uTexScale0 repeats.
    prog.set(uMaterialDiffuse=(0.5, 1, 0.25, 1), uTexScale0=(2, 1))
    scene.draw_mesh(gl, prog, geometry.quad(2, 2))
    x = (np.arange(W) * 2 + 1) % W            # u = 2 (x + 0.5) / W: texel 2x + 1
    want = unorm(t0[:, x] / 255.0 * (0.5, 1, 0.25, 1))
    assert np.abs(read(gl) - want).max() <= 1


@pytest.mark.parametrize("combine", sorted(programs.MULTITEXTURE_COMBINE))
def test_multitextured_combines_two_units(combine):
    gl = softgl.Context(W, H, antialias=False)
    t0, t1 = textures()
    upload(gl, 0, t0)
    upload(gl, 1, t1)
    prog = programs.multitextured(gl, combine).set(uMix=0.3)
    scene.draw_mesh(gl, prog, geometry.quad(2, 2))
    a, b = t0 / 255.0, t1 / 255.0
    want = {"modulate": a * b, "add": np.minimum(a + b, 1), "interpolate": a * 0.7 + b * 0.3,
            "decal": np.concatenate([a[..., :3] * (1 - b[..., 3:]) + b[..., :3] * b[..., 3:],
                                     a[..., 3:]], -1)}[combine]
    assert np.abs(read(gl) - unorm(want)).max() <= 1


def test_multitexture_exercise_red_texel_and_checkerboard():
    """The course exercise: one shader, a checkerboard on unit 0 and a 1x1 red RGB texture made
    of the bytes [255, 0, 0] on unit 1; which one a draw shows is one uniform."""
    gl = softgl.Context(W, H, antialias=False)
    checker = np.zeros((8, 8, 4), np.uint8)
    checker[(np.add.outer(np.arange(8), np.arange(8)) % 2) == 0] = 255
    checker[..., 3] = 255
    upload(gl, 0, checker)
    upload(gl, 1, np.array([[[255, 0, 0]]], np.uint8))
    prog = programs.textured(gl)
    scene.draw_mesh(gl, prog, geometry.quad(2, 2))
    img = read(gl)
    assert (img[0, 0] == [255, 255, 255, 255]).all() and (img[0, 2] == [0, 0, 0, 255]).all()
    prog.set(uTexture0=1)
    scene.draw_mesh(gl, prog, geometry.quad(2, 2))
    assert (read(gl) == [255, 0, 0, 255]).all()


# -- Fog in the shader ----------------------------------------------------------------------------

NEAR_W, FAR_W = 1.0, 9.0
# clip = (X, Y, 0, -Z): the fog coordinate -z is clip w, which grows from left to right.
PROJECTION = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0, 0], [0, 0, -1, 0]], np.float64)


def receding_quad():
    pos = []
    for x, y in ((-1, -1), (1, -1), (-1, 1), (1, 1)):
        w = NEAR_W if x < 0 else FAR_W
        pos.append([x * w, y * w, -w])
    return geometry.Mesh(pos, [[0, 0, 1]] * 4, [[0, 0]] * 4, [0, 1, 2, 2, 1, 3])


def eye_depth():
    t = (np.arange(W) + 0.5) / W             # 1/w is linear in window x
    return np.broadcast_to(1.0 / ((1 - t) / NEAR_W + t / FAR_W), (H, W))


PARAMS = dict(density=0.25, start=2.0, end=8.0)
COLOR, FOG = (0.9, 0.6, 0.3, 1.0), (0.2, 0.4, 0.8, 1.0)


def fogged_want(mode, c):
    f = programs.fog_factor(mode, c, **PARAMS)[..., None]
    rgb = f * np.array(COLOR[:3]) + (1 - f) * np.array(FOG[:3])
    return unorm(np.concatenate([rgb, np.ones_like(f)], -1))


@pytest.mark.parametrize("mode", ["LINEAR", "EXP", "EXP2"])
def test_fog_in_the_shader_matches_float64(mode):
    gl = softgl.Context(W, H, antialias=False)
    prog = programs.fogged(gl, mode, color=FOG, lit=False, **PARAMS)
    scene.draw_mesh(gl, prog, receding_quad(), uProjection=PROJECTION, uMaterialDiffuse=COLOR)
    img = read(gl)
    assert np.abs(img - fogged_want(mode, eye_depth())).max() <= 1
    assert len(np.unique(img[..., 0])) > 5            # the fog really varies across the quad


def test_radial_fog_uses_the_distance():
    gl = softgl.Context(W, H, antialias=False)
    prog = programs.fogged(gl, "EXP", color=FOG, lit=False, radial=True, **PARAMS)
    scene.draw_mesh(gl, prog, receding_quad(), uProjection=PROJECTION, uMaterialDiffuse=COLOR)
    x = ((np.arange(W) + 0.5) / W * 2 - 1)[None, :]
    y = ((np.arange(H) + 0.5) / H * 2 - 1)[:, None]
    c = eye_depth() * np.sqrt(x ** 2 + y ** 2 + 1)
    assert np.abs(read(gl) - fogged_want("EXP", c)).max() <= 1


@pytest.mark.parametrize("mode", ["LINEAR", "EXP", "EXP2"])
def test_shader_fog_equals_softgl_fog(mode):
    """Fog in GLSL with the eye depth and SOFTGL_fog (FRAGMENT_DEPTH: clip w) give the same bytes
    under a perspective projection."""
    images = []
    for in_shader in (True, False):
        gl = softgl.Context(W, H, antialias=False)
        if in_shader:
            prog = programs.fogged(gl, mode, color=FOG, lit=False, **PARAMS)
        else:
            prog = programs.constant_color(gl)
            scene.Fog(mode, color=FOG, **PARAMS).apply(gl)
        scene.draw_mesh(gl, prog, receding_quad(), uProjection=PROJECTION, uMaterialDiffuse=COLOR)
        images.append(read(gl))
    assert np.abs(images[0] - images[1]).max() <= 1


def test_fog_factor_formulas():
    assert programs.fog_factor("LINEAR", [1, 2, 5, 8, 9], start=2, end=8).tolist() == [1, 1, 0.5, 0, 0]
    assert programs.fog_factor("EXP", 2.0, density=0.5) == pytest.approx(math.exp(-1))
    assert programs.fog_factor("EXP2", 2.0, density=0.5) == pytest.approx(math.exp(-1))
    with pytest.raises(ValueError):
        programs.fog_factor("CUBIC", 1.0)


# -- The scene layer: textures and fog -------------------------------------------------------------

def test_scene_texture_on_a_quad():
    t0, _ = textures(5)
    s = scene.Scene(camera=scene.Camera(eye=(0, 0, 5), ortho_height=2.0), background=(0, 0, 0, 1))
    s.add(geometry.quad(W / H * 2, 2), texture=t0, texture_filter="nearest", color=(1, 1, 1))
    gl = s.render(softgl.Context(W, H, antialias=False))
    assert (read(gl) == t0).all()
    assert s.objects[0].material.shading == "textured"
    with pytest.raises(ValueError):
        scene.Material(shading="textured")


def test_scene_fog_fogs_by_eye_depth_and_is_left_off():
    s = scene.Scene(camera=scene.Camera(eye=(0, 0, 6), fovy=30), background=(0, 0, 0, 1),
                    fog=scene.Fog("LINEAR", start=2.0, end=10.0, color=(1, 1, 1)))
    s.add(geometry.quad(8, 8), shading="constant", color=(0, 0, 0))   # at eye depth 6
    gl = s.render(softgl.Context(W, H, antialias=False))
    f = programs.fog_factor("LINEAR", 6.0, start=2.0, end=10.0)
    assert np.abs(read(gl)[..., :3] - unorm(1 - f)).max() <= 1
    ext = gl.getExtension("SOFTGL_fog")
    assert not gl.isEnabled(ext.FOG)
    s.fog = None
    assert (read(s.render(gl))[..., :3] == 0).all()
