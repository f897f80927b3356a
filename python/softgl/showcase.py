"""The showcase: renders a gallery of every topic softgl draws today into a folder (PNG files
and an index.html contact sheet) and prints where it is.

    python -m softgl.showcase [folder]        (default: ./showcase)

Each picture is drawn with the WebGL API, through softgl.scene, softgl.programs and
softgl.experiments; see the notebooks for the same topics explained step by step.
"""
from __future__ import annotations

import html
import math
import sys
import time
from pathlib import Path

import numpy as np

import softgl
from softgl import display, experiments, geometry, io, programs, scene
from softgl import transforms as T


def _context(width, height, **attrs):
    attrs.setdefault("antialias", False)
    return softgl.Context(width, height, preserveDrawingBuffer=True, **attrs)


def _row(images, gap=6):
    """Images (contexts or arrays) side by side on a white strip."""
    pictures = [display.canvas_image(i, present=False) if hasattr(i, "drawingBufferWidth") else i
                for i in images]
    h = max(p.shape[0] for p in pictures)
    spacer = np.full((h, gap, 3), 255, np.uint8)
    parts = []
    for p in pictures:
        pad = np.full((h - p.shape[0], p.shape[1], 3), 255, np.uint8)
        parts += [np.concatenate([p, pad]), spacer]
    return np.concatenate(parts[:-1], axis=1)


# -- The gallery ------------------------------------------------------------------------------------

def color_models():
    palette = geometry.ALPHA_CUBE_FACE_COLORS.copy()
    palette[:, 3] = 1
    cube = geometry.cube(1.4, face_colors=palette)
    images = []
    for shading in ("constant", "vertex", "random"):
        s = scene.Scene(camera=scene.Camera(eye=(0, 2.2, 5), target=(0, 0.3, 0), fovy=40),
                        background=(0.15, 0.15, 0.2, 1))
        s.add(cube, shading=shading, color=(0.9, 0.5, 0.1),
              model=T.rotate(0.6, (0, 1, 0)) @ T.rotate(0.4, (1, 0, 0)))
        images.append(s.render(_context(200, 160)))
    return _row(images)


def lambert_and_phong():
    sphere = geometry.sphere(1.0, 48, 24)
    view = T.look_at((0, 0, 3.2), (0, 0, 0), (0, 1, 0))
    images = []
    for name, shininess in (("lambert", 1.0), ("phong", 4.0), ("phong", 32.0)):
        gl = _context(160, 160)
        gl.clearColor(0.1, 0.1, 0.12, 1)
        gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
        gl.enable(gl.DEPTH_TEST)
        scene.draw_mesh(gl, getattr(programs, name)(gl), sphere, uView=view,
                        uProjection=T.perspective(0.8, 1, 0.1, 10),
                        uNormalMatrix=T.normal_matrix(view), uMaterialDiffuse=(0.2, 0.5, 0.9, 1),
                        uLightDirection=(1, -1, -1), uShininess=shininess,
                        uMaterialSpecular=(0.8, 0.8, 0.8, 1))
        images.append(gl)
    return _row(images)


def three_spotlights():
    s = scene.Scene(camera=scene.Camera(eye=(0, 7, 9), target=(0, 0, 0), fovy=45),
                    ambient=(0.08, 0.08, 0.08))
    s.add(geometry.plane(14, 14), color=(1, 1, 1))
    s.add(geometry.sphere(0.8, 32, 16), color=(1, 1, 1), model=T.translate(0, 0.8, 0))
    s.lights = [scene.Light((0, 4, 2), (1, 0.2, 0.2), direction=(0, -1, -0.2), cutoff=0.75),
                scene.Light((2.5, 4, -1), (0.2, 1, 0.2), direction=(-0.2, -1, 0), cutoff=0.75),
                scene.Light((-2.5, 4, -1), (0.3, 0.3, 1), direction=(0.2, -1, 0), cutoff=0.75)]
    return s.render(_context(480, 320))


def depth_functions():
    return experiments.depth_functions()


def points_lesson():
    return experiments.points_lesson()


def blend_modes():
    images = []
    for mode in [m for m in scene.BLEND_MODES if m != "opaque"]:
        s = scene.Scene(camera=scene.Camera(eye=(0, 0, 5), ortho_height=2.4),
                        background=(0.5, 0.5, 0.5, 1))
        disc = geometry.cylinder(0.6, 0.01, 48)
        for i, rgb in enumerate([(1, 0.2, 0.2), (0.2, 1, 0.2), (0.2, 0.2, 1)]):
            a = 2 * math.pi * i / 3 + math.pi / 2
            s.add(disc, shading="constant", color=rgb, alpha=0.6, blend=mode,
                  model=T.translate(0.35 * math.cos(a), 0.35 * math.sin(a), 0.1 * i)
                  @ T.rotate(math.pi / 2, (1, 0, 0)))
        images.append(s.render(_context(110, 110, alpha=False)))
    return _row(images, gap=4)


def blend_matrix():
    return experiments.blend_matrix(size=48)


def transparency_modes():
    images = []
    for mode in ("depth_write", "unsorted", "sorted", "two_pass"):
        s = scene.Scene(camera=scene.Camera(eye=(0, 2.5, 6), target=(0, 0.6, 0), fovy=40),
                        transparency=mode, background=(0.12, 0.12, 0.15, 1))
        s.lights = [scene.Light((3, 6, 4)), scene.Light((-4, 3, 2), (0.4, 0.4, 0.5))]
        s.add(geometry.plane(8, 8), color=(0.7, 0.7, 0.7))
        for x, z, rgb in [(0.0, 1.2, (1, 0.2, 0.2)), (-0.8, 0.0, (0.2, 1, 0.2)),
                          (0.8, -0.6, (0.2, 0.4, 1))]:
            s.add(geometry.sphere(0.6, 32, 16), color=rgb, alpha=0.5, model=T.translate(x, 0.7, z))
        images.append(s.render(_context(200, 150)))
    return _row(images)


def alpha_cube():
    images = []
    for mode in ("sorted", "two_pass"):
        s = scene.Scene(camera=scene.Camera(eye=(0, 1.6, 3.6), fovy=40), transparency=mode,
                        background=(1, 1, 1, 1))
        s.add(geometry.cube(1.3, face_colors=geometry.ALPHA_CUBE_FACE_COLORS), shading="vertex",
              blend="interpolative", model=T.rotate(0.4, (0, 1, 0)) @ T.rotate(0.3, (1, 0, 0)))
        images.append(s.render(_context(200, 200)))
    return _row(images)


def projection_shadows():
    """The course's exercise: a ground quad, objects above it and a light circling at y = 2,
    shadows flattened onto the ground, semi-transparent, clipped to the ground by the depth test."""
    frames = []
    for angle in (0.0, 2.1, 4.2):
        light = (2 * math.cos(angle), 3.0, -1 + 2 * math.sin(angle))
        s = scene.Scene(camera=scene.Camera(eye=(0, 2.4, 2.6), target=(0, -0.8, -1), fovy=50))
        s.add(geometry.plane(4, 4), color=(0.85, 0.85, 0.8), model=T.translate(0, -1, -1),
              receives_shadow=True)
        s.add(geometry.cube(0.8), color=(0.9, 0.25, 0.2), model=T.translate(-0.7, -0.2, -1.2))
        s.add(geometry.torus(0.5, 0.15), color=(0.2, 0.5, 0.9),
              model=T.translate(0.8, 0.0, -0.6) @ T.rotate(1.0, (1, 0, 0)))
        s.lights = [scene.Light(light)]
        s.shadows = scene.ProjectedShadows(light=0, plane_y=-1.0, alpha=0.5)
        frames.append(s.render(_context(220, 165, stencil=True)))
    return _row(frames)


def multisampling():
    """The same edges without and with antialias: true (4x MSAA), enlarged 4x."""
    images = []
    for antialias in (False, True):
        s = scene.Scene(camera=scene.Camera(eye=(0, 0, 5), ortho_height=2.0),
                        background=(1, 1, 1, 1))
        s.add(geometry.quad(1.2, 1.2), shading="constant", color=(0.1, 0.2, 0.6),
              model=T.rotate(0.35))
        gl = s.render(_context(48, 48, antialias=antialias))
        images.append(np.repeat(np.repeat(display.canvas_image(gl, present=False), 4, 0), 4, 1))
    return _row(images)


def scissor_mosaic():
    """Scissored clears and a red-only color mask band."""
    gl = _context(480, 320)
    w, h = gl.drawingBufferWidth, gl.drawingBufferHeight
    gl.clearColor(0.08, 0.09, 0.12, 1.0)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.enable(gl.SCISSOR_TEST)
    rng = np.random.default_rng(7)
    for _ in range(60):
        x, y = int(rng.integers(0, w)), int(rng.integers(0, h))
        gl.scissor(x, y, int(rng.integers(8, w // 3)), int(rng.integers(8, h // 3)))
        gl.clearColor(*(float(v) for v in rng.random(3)), 1.0)
        gl.clear(gl.COLOR_BUFFER_BIT)
    gl.colorMask(True, False, False, False)
    gl.scissor(0, h // 2 - 20, w, 40)
    gl.clearColor(1, 1, 1, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    return gl


def translucent_canvas():
    """A premultiplied drawing buffer with alpha from 0 to 1, composited over the white page."""
    gl = _context(480, 160)
    w, h = gl.drawingBufferWidth, gl.drawingBufferHeight
    gl.enable(gl.SCISSOR_TEST)
    for i, alpha in enumerate(np.linspace(0.0, 1.0, 8)):
        gl.scissor(i * w // 8, 0, w // 8 + 1, h)
        a = float(alpha)
        gl.clearColor(0.1 * a, 0.4 * a, 0.9 * a, a)
        gl.clear(gl.COLOR_BUFFER_BIT)
    return gl


def fog():
    """SOFTGL_fog: none, LINEAR, EXP, EXP2 on receding cubes."""
    return _row([experiments.render_fog(None, size=(200, 125)),
                 experiments.render_fog("LINEAR", start=1, end=20, size=(200, 125)),
                 experiments.render_fog("EXP", density=0.1, size=(200, 125)),
                 experiments.render_fog("EXP2", density=0.1, size=(200, 125))])


def antialiasing():
    """Zoomed crops and error maps: aliased, exact area (SOFTGL_smooth), sampled, MSAA 2/4/16."""
    fig, _ = experiments.antialiasing_methods(repeat=1)
    return fig


def _checkerboard(n=64, checks=8):
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    img = np.zeros((n, n, 4), np.uint8)
    img[((i // (n // checks)) + (j // (n // checks))) % 2 == 0] = 255
    img[..., 3] = 255
    return img


def multitexturing():
    """A mipmapped checkerboard on a plane with a red 1x1 texture on two quads, then two
    textures combined in one shader (modulate, interpolate)."""
    checker = _checkerboard()
    s = scene.Scene(camera=scene.Camera(eye=(0, 0, 0), target=(0, -0.2, -1), fovy=90),
                    background=(0.39, 0.58, 0.93, 1))
    s.add(geometry.plane(8, 8), texture=checker, texture_repeat=(4, 4), color=(1, 1, 1),
          model=T.translate(0, -1, -5))
    red = np.array([[[255, 0, 0]]], np.uint8)
    for m in (T.translate(0.5, -0.5, -1.5) @ T.rotate(-math.pi / 2, (1, 0, 0)),
              T.translate(-1.0, -0.5, -2.75) @ T.rotate(math.pi / 2, (0, 1, 0))):
        s.add(geometry.quad(0.5, 0.5), texture=red, texture_filter="nearest", color=(1, 1, 1), model=m)
    images = [s.render(_context(200, 150))]
    gradient = np.zeros((32, 32, 4), np.uint8)
    gradient[..., 0] = np.linspace(0, 255, 32)[None, :]
    gradient[..., 2] = np.linspace(255, 0, 32)[:, None]
    gradient[..., 3] = 255
    for combine in ("modulate", "interpolate"):
        gl = _context(150, 150)
        for unit, image in ((0, checker), (1, gradient)):
            gl.activeTexture(gl.TEXTURE0 + unit)
            gl.bindTexture(gl.TEXTURE_2D, gl.createTexture())
            gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, image.shape[1], image.shape[0], 0, gl.RGBA,
                          gl.UNSIGNED_BYTE, image)
            gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.LINEAR)
        scene.draw_mesh(gl, programs.multitextured(gl, combine), geometry.quad(2, 2))
        images.append(gl)
    return _row(images)


def exact_transparency():
    """Three interpenetrating transparent objects: unsorted, sorted by object, and exact
    (SOFTGL_exact_transparency: every fragment composited in depth order)."""
    images = []
    for mode in ("unsorted", "sorted", "exact"):
        s = scene.Scene(camera=scene.Camera(eye=(0, 1.2, 4), fovy=40), transparency=mode,
                        background=(1, 1, 1, 1))
        s.lights = [scene.Light((3, 5, 5))]
        s.add(geometry.torus(0.8, 0.25), color=(0.1, 0.8, 0.3), alpha=0.5,
              model=T.rotate(1.2, (1, 0, 0)))
        s.add(geometry.sphere(0.6), color=(0.2, 0.3, 1.0), alpha=0.5)
        s.add(geometry.cube(1.0), color=(1.0, 0.3, 0.1), alpha=0.4,
              model=T.translate(0.4, 0.1, -0.3) @ T.rotate(0.6, (1, 1, 0)))
        images.append(s.render(_context(200, 160)))
    return _row(images)


def circling_light():
    """Eight frames of a light circling at y = 2 around (0, 2, -2): semi-transparent shadows."""
    frames = []
    checker = _checkerboard()
    for angle in np.linspace(0, 2 * np.pi, 8, endpoint=False):
        s = scene.Scene(camera=scene.Camera(eye=(0, 1.6, 1.4), target=(0, -1, -2.2), fovy=55),
                        background=(0.39, 0.58, 0.93, 1))
        s.add(geometry.plane(4, 4), texture=checker, texture_repeat=(2, 2), color=(1, 1, 1),
              model=T.translate(0, -1, -2), receives_shadow=True)
        s.add(geometry.cube(0.5), color=(0.9, 0.2, 0.1), model=T.translate(0.3, -0.4, -2.0))
        s.add(geometry.quad(0.5, 0.5), shading="constant", color=(1, 0, 0),
              model=T.translate(-0.6, -0.3, -1.6) @ T.rotate(-math.pi / 2, (1, 0, 0)))
        s.lights = [scene.Light((2 * math.cos(angle), 2.0, -2 + 2 * math.sin(angle)))]
        s.shadows = scene.ProjectedShadows(light=0, plane_y=-1.0, alpha=0.5)
        frames.append(display.canvas_image(s.render(_context(160, 120, stencil=True)), present=False))
    from . import animation
    return animation.filmstrip(frames, columns=4)


GALLERY = [
    ("color_models", "Constant, per-vertex and per-fragment (random) color", color_models),
    ("lambert_and_phong", "Lambert, then Phong with shininess 4 and 32", lambert_and_phong),
    ("three_spotlights", "Three spotlights through uniform arrays, cutoff 0.75", three_spotlights),
    ("depth_functions", "The eight depth functions", depth_functions),
    ("points_lesson", "The points lesson: depth test, blending and masks", points_lesson),
    ("blend_modes", "Additive, subtractive, reverse subtractive, multiplicative, interpolative, "
                    "premultiplied, min, max", blend_modes),
    ("blend_matrix", "Source factor x blend equation", blend_matrix),
    ("transparency_modes", "Transparency: depth writes on, unsorted, sorted, two passes",
     transparency_modes),
    ("alpha_cube", "The alpha cube in one pass and with back faces first", alpha_cube),
    ("projection_shadows", "Projection shadows from a circling light: blended, stencilled, "
                           "clipped to the ground", projection_shadows),
    ("multisampling", "Edges without and with 4x multisampling (enlarged)", multisampling),
    ("fog", "SOFTGL_fog: none, LINEAR, EXP, EXP2", fog),
    ("antialiasing", "Antialiasing: zoomed crops and error against the exact area", antialiasing),
    ("multitexturing", "A checkerboard and a 1x1 red texture; two textures in one shader",
     multitexturing),
    ("circling_light", "Projection shadows from a light circling at y = 2 (8 frames)", circling_light),
    ("exact_transparency", "Transparency unsorted, sorted by object, and exact (A-buffer)",
     exact_transparency),
    ("scissor_mosaic", "Scissored clears and a red-only color mask", scissor_mosaic),
    ("translucent_canvas", "A premultiplied canvas over the white page", translucent_canvas),
]


def render(folder: Path, progress: bool = True) -> list[tuple[str, str, Path]]:
    """Render every gallery item into `folder` and write its index.html; returns
    (name, title, path) per picture."""
    from tqdm.auto import tqdm
    folder.mkdir(parents=True, exist_ok=True)
    items = []
    for name, title, make in tqdm(GALLERY, desc="softgl showcase", unit="picture",
                                  disable=not progress):
        picture = make()
        path = folder / f"{name}.png"
        if hasattr(picture, "savefig"):
            experiments.save_figure(picture, path)
        else:
            io.save(display.canvas_image(picture, present=False)
                    if hasattr(picture, "drawingBufferWidth") else picture, path)
        items.append((name, title, path))
    cards = "\n".join(
        f'<figure><a href="{p.name}"><img src="{p.name}"></a>'
        f"<figcaption>{html.escape(t)}</figcaption></figure>" for _, t, p in items)
    (folder / "index.html").write_text(
        "<!doctype html><meta charset=utf-8><title>softgl showcase</title>"
        "<style>body{font-family:sans-serif;margin:16px}figure{display:inline-block;margin:8px;"
        "vertical-align:top}img{max-width:560px;max-height:420px}figcaption{max-width:560px}"
        "</style><h1>softgl showcase</h1>\n"
        f"<p>softgl {softgl.__version__}: every picture is drawn by softgl's software WebGL.</p>\n"
        f"{cards}\n")
    return items


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    folder = Path(argv[0] if argv else "showcase").resolve()
    start = time.perf_counter()
    items = render(folder)
    print(f"softgl showcase: {len(items)} pictures in {folder} "
          f"({time.perf_counter() - start:.1f} s); open {folder / 'index.html'}")


if __name__ == "__main__":
    main()
