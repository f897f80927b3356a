"""softgl.scene against hand-computed pixels: blend modes byte by byte, the transparency passes
and the projected shadows (depth-test clipping, stencil against double darkening)."""
import warnings

import numpy as np
import pytest

import softgl
from softgl import geometry, scene
from softgl import transforms as T
from layer_util import read, unorm

BLACK = (0.0, 0.0, 0.0, 1.0)


def front_view(size=16, version=2, **attrs):
    """A context and a scene looking down -z with an orthographic camera: the square
    x, y in [-1, 1] fills the drawing buffer."""
    gl = softgl.Context(size, size, antialias=False, version=version, **attrs)
    s = scene.Scene(camera=scene.Camera(eye=(0, 0, 5), ortho_height=2.0, near=0.1, far=10),
                    background=BLACK)
    return gl, s


def f32(x):
    """Values as the shaders see them (float32 uniforms), in float64 for the references."""
    return np.asarray(x, np.float32).astype(np.float64)


def blend_reference(mode, src, dst_bytes):
    """float64 blend of a float source over 8-bit destination bytes, stored as bytes."""
    s, d = f32(src), np.asarray(dst_bytes, np.float64) / 255
    sa = s[3]
    rgb = {"additive": s[:3] + d[:3],
           "subtractive": s[:3] - d[:3],
           "reverse_subtractive": d[:3] - s[:3],
           "multiplicative": s[:3] * d[:3],
           "interpolative": s[:3] * sa + d[:3] * (1 - sa),
           "premultiplied": s[:3] * sa + d[:3] * (1 - sa),   # the shader premultiplies
           "min": np.minimum(s[:3], d[:3]),
           "max": np.maximum(s[:3], d[:3])}[mode]
    a = {"additive": sa + d[3], "subtractive": sa - d[3], "reverse_subtractive": d[3] - sa,
         "multiplicative": sa * d[3], "interpolative": sa + d[3] * (1 - sa),
         "premultiplied": sa + d[3] * (1 - sa), "min": min(sa, d[3]), "max": max(sa, d[3])}[mode]
    return unorm(np.append(rgb, a))


def test_additive_quad_over_quad_exact_bytes():
    gl, s = front_view()
    s.add(geometry.quad(2, 2), shading="constant", color=(0.2, 0.3, 0.4))
    s.add(geometry.quad(1, 1), shading="constant", color=(0.25, 0.52, 0.12), blend="additive",
          model=T.translate(0, 0, 0.5))
    img = read(s.render(gl))
    a = unorm(f32([0.2, 0.3, 0.4, 1.0]))                  # 51, 77, 102, 255
    both = unorm(a / 255 + f32([0.25, 0.52, 0.12, 1.0]))  # 51 + 63.75, 77 + 132.6, 102 + 30.6
    assert (img[:4] == a).all() and (img[:, :4] == a).all()
    assert (img[4:12, 4:12] == both).all()
    assert both.tolist() == [115, 210, 133, 255]


MODES = ["additive", "subtractive", "reverse_subtractive", "multiplicative", "interpolative",
         "premultiplied", "min", "max"]


@pytest.mark.parametrize("mode", MODES)
def test_blend_modes_by_name(mode, version):
    gl, s = front_view(8, version)
    dst, src = (0.6, 0.3, 0.9, 1.0), (0.3, 0.8, 0.45, 0.6)
    s.add(geometry.quad(2, 2), shading="constant", color=dst)
    s.add(geometry.quad(2, 2), shading="constant", color=src, blend=mode,
          model=T.translate(0, 0, 0.5))
    img = read(s.render(gl))
    want = blend_reference(mode, src, unorm(dst))
    assert (np.abs(img - want) <= 1).all(), (img[0, 0], want)
    assert (img == img[0, 0]).all()
    assert gl.getError() == gl.NO_ERROR


def test_explicit_blend_factors_and_blend_color():
    gl, s = front_view(8)
    s.add(geometry.quad(2, 2), shading="constant", color=(0.6, 0.3, 0.9, 1.0))
    s.add(geometry.quad(2, 2), shading="constant", color=(0.3, 0.8, 0.45, 0.6),
          blend=scene.Blend("CONSTANT_COLOR", "ONE_MINUS_CONSTANT_COLOR", color=(0.2, 0.4, 0.8, 1.0)),
          model=T.translate(0, 0, 0.5))
    img = read(s.render(gl))
    c = f32([0.2, 0.4, 0.8, 1.0])
    d = unorm([0.6, 0.3, 0.9, 1.0]) / 255
    want = unorm(f32([0.3, 0.8, 0.45, 0.6]) * c + d * (1 - c))
    assert (np.abs(img - want) <= 1).all()
    # A tuple (src, dst, equation) works too.
    assert scene.blend_mode(("ONE", "ONE", "FUNC_SUBTRACT")) == scene.BLEND_MODES["subtractive"]


def over(src, dst_bytes):
    return blend_reference("interpolative", src, dst_bytes)


NEAR = (1.0, 0.0, 0.0, 0.5)
FAR = (0.0, 0.0, 1.0, 0.75)


@pytest.mark.parametrize("mode", scene.TRANSPARENCY_MODES)
def test_transparency_order(mode):
    gl, s = front_view(8)
    s.transparency = mode
    # Added nearest first: only sorting puts the far quad first.
    s.add(geometry.quad(2, 2), shading="constant", color=NEAR, model=T.translate(0, 0, 1))
    s.add(geometry.quad(2, 2), shading="constant", color=FAR, model=T.translate(0, 0, -1))
    img = read(s.render(gl))
    bg = unorm(BLACK)
    want = {"sorted": over(NEAR, over(FAR, bg)),        # the right answer
            "two_pass": over(NEAR, over(FAR, bg)),
            "unsorted": over(FAR, over(NEAR, bg)),      # far blended on top of near
            "depth_write": over(NEAR, bg),              # far rejected by near's depth
            "exact": over(NEAR, over(FAR, bg))}[mode]   # the A-buffer: composited in float64
    tolerance = 1 if mode == "exact" else 0             # one rounding instead of two
    assert (np.abs(img - want) <= tolerance).all(), (mode, img[0, 0], want)


def test_two_pass_draws_back_faces_first():
    """An alpha cube seen face on: back face (-z, blue) first, then the front face (+z, red)."""
    gl, s = front_view(16)
    s.transparency = "two_pass"
    mesh = geometry.cube(1.0, face_colors=geometry.ALPHA_CUBE_FACE_COLORS)
    s.add(mesh, shading="vertex", blend="interpolative")
    gl.stats(reset=True)
    img = read(s.render(gl))
    red, blue = geometry.ALPHA_CUBE_FACE_COLORS[4], geometry.ALPHA_CUBE_FACE_COLORS[5]
    want = over(red, over(blue, unorm(BLACK)))
    assert (img[4:12, 4:12] == want).all()
    # Each pass culls one of the two faces the camera sees; the side faces are edge-on.
    stats = gl.stats()
    assert stats["draws"] == 2 and stats["primitives_culled"] == 4
    assert stats["primitives_zero_area"] == 16
    # In one pass the face order of the mesh decides: +z (red) comes before -z (blue).
    s.transparency = "sorted"
    img = read(s.render(gl))
    assert (img[4:12, 4:12] == over(blue, over(red, unorm(BLACK)))).all()


def test_opaque_first_hides_transparent_behind_it():
    gl, s = front_view(8)
    s.add(geometry.quad(2, 2), shading="constant", color=(0.0, 1.0, 0.0, 0.5),
          model=T.translate(0, 0, -1))                            # transparent, behind
    s.add(geometry.quad(2, 2), shading="constant", color=(0.2, 0.2, 0.2))   # opaque, added last
    img = read(s.render(gl))
    assert (img == unorm([0.2, 0.2, 0.2, 1.0])).all()


def test_material_defaults():
    assert scene.Material(alpha=0.5).blending == scene.BLEND_MODES["interpolative"]
    assert scene.Material(color=(1, 0, 0, 0.5)).blending == scene.BLEND_MODES["interpolative"]
    assert scene.Material().blending is None
    assert scene.Material(alpha=0.5, blend="opaque").blending is None
    with pytest.raises(ValueError, match="unknown blend mode"):
        scene.Material(blend="screen")
    with pytest.raises(ValueError, match="unknown shading"):
        scene.Material(shading="toon")
    gl, s = front_view(8)
    s.transparency = "perfect"
    with pytest.raises(ValueError, match="transparency mode"):
        s.render(gl)


# -- Projected shadows ----------------------------------------------------------------------------

LIGHT = np.array([0.2, 2.0, -0.1])
GROUND_HALF = 0.8
# (centre, half size) of horizontal square casters, and their colors.
CASTERS = [((0.3, 1.0, 0.1), 0.35), ((-0.2, 0.6, 0.0), 0.25)]
CASTER_COLORS = [(0.9, 0.2, 0.1), (0.1, 0.3, 0.9)]
GROUND = (0.6, 0.7, 0.8)
GREY = (0.3, 0.3, 0.3, 1.0)


def shadow_scene(n=64, alpha=0.5, stencil=True):
    gl = softgl.Context(n, n, antialias=False, stencil=True)
    s = scene.Scene(camera=scene.Camera(eye=(0, 5, 0), up=(0, 0, -1), ortho_height=2.0,
                                        near=0.1, far=10), background=GREY)
    s.add(geometry.plane(2 * GROUND_HALF, 2 * GROUND_HALF), shading="constant", color=GROUND,
          receives_shadow=True)
    for (center, half), color in zip(CASTERS, CASTER_COLORS):
        s.add(geometry.plane(2 * half, 2 * half), shading="constant", color=color,
              model=T.translate(*center))
    s.lights.append(scene.Light(position=tuple(LIGHT)))
    s.shadows = scene.ProjectedShadows(light=0, alpha=alpha, stencil=stencil)
    return gl, s


def shadow_reference(n, alpha, stencil):
    """Expected bytes (rows bottom-up) and a mask of pixels too close to an edge to call."""
    c = (np.arange(n) + 0.5) / n * 2 - 1
    x, ny = np.meshgrid(c, c)
    z = -ny                         # the camera looks down with -z up the screen
    sure = np.ones_like(x, bool)
    margin = 4.0 / n / 16           # well over the rasterizer's sub-pixel snapping

    def inside(px, pz, cx, cz, half):
        d = np.maximum(np.abs(px - cx), np.abs(pz - cz)) - half
        return d < 0, np.abs(d) > margin

    img = np.zeros(x.shape + (4,), np.int64)
    img[:] = unorm(f32(GREY))     # shadows off the ground would darken it
    on_ground, ok = inside(x, z, 0, 0, GROUND_HALF)
    sure &= ok
    count = np.zeros(x.shape, int)
    for (cx, cy, cz), half in CASTERS:
        t = (LIGHT[1] - cy) / LIGHT[1]          # where the ray light -> ground crosses y = cy
        qx, qz = LIGHT[0] + t * (x - LIGHT[0]), LIGHT[2] + t * (z - LIGHT[2])
        hit, ok = inside(qx, qz, cx, cz, half)
        count += hit
        sure &= ok
    ground = unorm(f32(GROUND + (1.0,)))
    shaded = [ground]
    for _ in range(len(CASTERS)):
        shaded.append(over((0, 0, 0, alpha), shaded[-1]) * [1, 1, 1, 0] + [0, 0, 0, 255])
    layers = np.minimum(count, 1) if stencil else count
    for k in range(len(shaded)):
        img[on_ground & (layers == k)] = shaded[k]
    for ((cx, cy, cz), half), color in reversed(list(zip(CASTERS, CASTER_COLORS))):
        hit, ok = inside(x, z, cx, cz, half)    # higher casters (drawn nearer) win: listed first
        img[hit] = unorm(f32(color + (1.0,)))
        sure &= ok
    return img, sure, count


@pytest.mark.parametrize("stencil", [True, False])
def test_projected_shadows_hand_computed(stencil):
    n, alpha = 64, 0.5
    gl, s = shadow_scene(n, alpha, stencil)
    img = read(s.render(gl))
    want, sure, count = shadow_reference(n, alpha, stencil)
    assert sure.mean() > 0.8
    bad = (img != want).any(-1) & sure
    assert not bad.any(), np.argwhere(bad)[:5]
    # The scene has every case: shadow off the ground's edge (clipped), overlapping shadows.
    on_ground = np.abs((np.arange(n) + 0.5) / n * 2 - 1) < GROUND_HALF
    assert ((count > 0) & ~(on_ground[None, :] & on_ground[:, None]) & sure).any()
    assert ((count == 2) & sure & (want[..., 0] != unorm(CASTER_COLORS[0][0]))).sum() > 10


def test_shadows_need_a_stencil_buffer():
    gl = softgl.Context(8, 8, antialias=False)          # WebGL's default: no stencil
    s = scene.Scene()
    s.add(geometry.cube())
    s.lights.append(scene.Light())
    s.shadows = scene.ProjectedShadows()
    with pytest.raises(ValueError, match="stencil=True"):
        s.render(gl)


def test_lit_scene_renders_with_spotlights_and_counts_draws():
    gl = softgl.Context(64, 48, antialias=False, stencil=True)
    s = scene.Scene()
    s.add(geometry.plane(6, 6), receives_shadow=True)
    s.add(geometry.sphere(0.6, 16, 8), color=(1, 0.2, 0.2), model=T.translate(0, 0.8, 0))
    s.add(geometry.cube(0.8), color=(0.2, 0.5, 1.0), alpha=0.5, model=T.translate(1.2, 0.4, 0))
    s.lights += [scene.Light(position=(0, 4, 0), direction=(0, -1, 0), cutoff=0.6),
                 scene.Light(position=(2, 3, 2), color=(0.4, 0.4, 0.4))]
    s.shadows = scene.ProjectedShadows()
    gl.stats(reset=True)
    with warnings.catch_warnings():
        warnings.simplefilter("error", softgl.GLWarning)
        img = read(s.render(gl))
    # ground + 2 shadows + sphere + cube
    assert gl.stats()["draws"] == 5
    assert gl.getError() == gl.NO_ERROR
    assert len(np.unique(img.reshape(-1, 4), axis=0)) > 50   # lit, not flat
