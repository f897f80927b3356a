"""Transparency, exactly and approximately: one scene, every usual method, each with its error::

    from softgl import transparency as tr
    scene = tr.Scene(objects=[tr.Object(geometry.sphere(), color=(1, 0, 0, 0.5)), ...],
                     view=..., projection=...)
    exact = tr.render(scene, "exact", width=256, height=256)
    table = tr.compare(scene, width=256, height=256)     # {method: Result with .error}

Methods (``METHODS``):

- ``exact``: the reference. softgl's A-buffer (SOFTGL_exact_transparency) keeps every blended
  fragment of every sample, sorts by depth (ties in submission order) and composites with the
  blend state in float64, rounding once.
- ``unsorted``: the transparent objects blended in the order given.
- ``sorted_objects``: objects sorted back to front by the eye depth of their centroid.
- ``sorted_triangles``: all transparent triangles sorted back to front by centroid eye depth,
  drawn as one mesh.
- ``two_pass``: objects sorted back to front, each drawn twice: back faces (cullFace FRONT), then
  front faces (cullFace BACK).
- ``peeling``: depth peeling with ``layers`` layers. This is the *arithmetic* of depth peeling,
  computed from the A-buffer's per-sample lists (composite only the ``layers`` nearest fragments
  over the background), not a multi-pass implementation with depth textures (softgl has the
  framebuffer objects and depth textures that needs; the arithmetic is computed from the lists
  so that it is compared with the exact image without a pass's own rounding). Real peeling
  with a strict depth comparison would also lose co-planar fragments, which this does not.
- ``wboit``: weighted blended order-independent transparency (McGuire & Bavoil, JCGT 2013),
  ``weight`` selecting their equation 7, 8, 9 (eye distance) or 10 (window depth), also computed
  from the A-buffer lists in float64 (the paper accumulates in 16-bit float targets).

Opaque objects are drawn first (depth writes on, blending off); transparent ones with the depth
test on and depth writes off, blending with ``blend`` (default SRC_ALPHA, ONE_MINUS_SRC_ALPHA).
Errors are measured on RGB in [0, 1] units against the exact image: RMSE, max and PSNR (dB, peak 1).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from . import geometry
from .context import Context
from .errors import GLError
from .programs import program
from .transforms import column_major

METHODS = ("exact", "unsorted", "sorted_objects", "sorted_triangles", "two_pass", "peeling", "wboit")

_VS = """
attribute vec3 aPos;
attribute vec4 aColor;
uniform mat4 uMVP;
varying vec4 vColor;
void main() { vColor = aColor; gl_Position = uMVP * vec4(aPos, 1.0); }
"""
_FS = """
precision highp float;
varying vec4 vColor;
void main() { gl_FragColor = vColor; }
"""


@dataclass
class Object:
    """A mesh with a model matrix and an RGBA color (constant, or None for the mesh's colors).

    With `light` (a world-space direction), RGB is shaded per vertex by 0.3 + 0.7·max(n·l, 0), so
    front and back faces differ and the order of an object's own layers matters (layers of one
    constant color commute under "over", which would hide ordering errors)."""
    mesh: geometry.Mesh
    color: tuple | None = (1.0, 1.0, 1.0, 0.5)
    model: np.ndarray = field(default_factory=lambda: np.eye(4, dtype=np.float32))
    name: str = ""
    light: tuple | None = None

    def colors(self) -> np.ndarray:
        if self.color is None:
            if self.mesh.colors is None:
                raise ValueError(f"Object {self.name!r}: no color and the mesh has no colors")
            c = self.mesh.colors.astype(np.float64)
        else:
            c = np.tile(np.asarray(self.color, np.float64), (len(self.mesh.positions), 1))
        if self.light is not None:
            n = self.mesh.normals.astype(np.float64) @ np.linalg.inv(np.asarray(self.model, np.float64)[:3, :3])
            n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)
            l = np.asarray(self.light, np.float64) / np.linalg.norm(self.light)
            c[:, :3] *= (0.3 + 0.7 * np.maximum(n @ l, 0.0))[:, None]
        return c.astype(np.float32)


@dataclass
class Scene:
    """Transparent objects (drawn in this order when unsorted), opaque ones, a camera."""
    objects: list
    view: np.ndarray
    projection: np.ndarray
    opaque: list = field(default_factory=list)
    background: tuple = (0.0, 0.0, 0.0, 1.0)
    blend: tuple = ("SRC_ALPHA", "ONE_MINUS_SRC_ALPHA")


@dataclass
class Error:
    rmse: float
    max: float
    psnr: float


@dataclass
class Result:
    method: str
    image: np.ndarray          # (height, width, 4) uint8, top row first
    seconds: float            # drawing (and resolving) only; no context creation or readback
    error: Error | None = None
    exact_float: np.ndarray | None = None   # exact only: unrounded float64 image, top row first


def error(image: np.ndarray, reference: np.ndarray) -> Error:
    """RMSE, max and PSNR of image - reference over RGB, in [0, 1] units."""
    a = np.asarray(image, np.float64)[..., :3] / 255.0
    b = np.asarray(reference, np.float64)[..., :3] / 255.0
    d = a - b
    rmse = float(np.sqrt(np.mean(d * d)))
    return Error(rmse, float(np.abs(d).max()), math.inf if rmse == 0 else 20 * math.log10(1 / rmse))


def _eye_depths(obj: Object, view: np.ndarray) -> np.ndarray:
    """Eye-space z of each vertex (negative in front of the camera)."""
    p = np.c_[obj.mesh.positions.astype(np.float64), np.ones(len(obj.mesh.positions))]
    return (p @ (np.asarray(view, np.float64) @ np.asarray(obj.model, np.float64)).T)[:, 2]


def _world(obj: Object) -> np.ndarray:
    p = np.c_[obj.mesh.positions.astype(np.float64), np.ones(len(obj.mesh.positions))]
    return (p @ np.asarray(obj.model, np.float64).T)[:, :3].astype(np.float32)


class _Renderer:
    """One context drawing the scene's opaque and transparent objects."""

    def __init__(self, scene: Scene, width: int, height: int, samples: int, threads):
        self.scene = scene
        aa = samples > 1
        self.gl = gl = Context(width, height, antialias=aa, samples=samples if aa else None, alpha=False,
                               preserveDrawingBuffer=True, threads=threads, strict=True)
        self.prog = program(gl, _VS, _FS, {"aPos": 0, "aColor": 1})
        gl.useProgram(self.prog)
        self.mvp = gl.getUniformLocation(self.prog, "uMVP")
        self.vp = np.asarray(scene.projection, np.float64) @ np.asarray(scene.view, np.float64)
        self.pos_buf, self.col_buf, self.idx_buf = gl.createBuffer(), gl.createBuffer(), gl.createBuffer()
        for loc, buf, size in ((0, self.pos_buf, 3), (1, self.col_buf, 4)):
            gl.bindBuffer(gl.ARRAY_BUFFER, buf)
            gl.enableVertexAttribArray(loc)
            gl.vertexAttribPointer(loc, size, gl.FLOAT, False, 0, 0)
        gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, self.idx_buf)

    def draw(self, positions, colors, indices, mvp):
        gl = self.gl
        gl.uniformMatrix4fv(self.mvp, False, column_major(mvp))
        gl.bindBuffer(gl.ARRAY_BUFFER, self.pos_buf)
        gl.bufferData(gl.ARRAY_BUFFER, np.ascontiguousarray(positions, np.float32), gl.STREAM_DRAW)
        gl.bindBuffer(gl.ARRAY_BUFFER, self.col_buf)
        gl.bufferData(gl.ARRAY_BUFFER, np.ascontiguousarray(colors, np.float32), gl.STREAM_DRAW)
        idx = np.ascontiguousarray(indices, np.uint32)
        gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, idx, gl.STREAM_DRAW)
        gl.drawElements(gl.TRIANGLES, len(idx), gl.UNSIGNED_INT, 0)

    def draw_object(self, obj: Object):
        self.draw(obj.mesh.positions, obj.colors(), obj.mesh.indices,
                  self.vp @ np.asarray(obj.model, np.float64))

    def begin(self):
        gl, s = self.gl, self.scene
        gl.clearColor(*s.background)
        gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
        gl.enable(gl.DEPTH_TEST)
        gl.depthMask(True)
        gl.disable(gl.BLEND)
        for obj in s.opaque:
            self.draw_object(obj)
        gl.depthMask(False)
        gl.enable(gl.BLEND)
        gl.blendFunc(*(getattr(gl, f) if isinstance(f, str) else f for f in s.blend))

    def image(self) -> np.ndarray:
        gl = self.gl
        return gl.readPixels(0, 0, gl.drawingBufferWidth, gl.drawingBufferHeight, gl.RGBA,
                             gl.UNSIGNED_BYTE)[::-1].copy()


def _by_depth_back_to_front(objects, view):
    # Farthest first: the most negative eye z of the centroid (stable for ties).
    keys = [float(np.mean(_eye_depths(o, view))) for o in objects]
    return [objects[i] for i in sorted(range(len(objects)), key=lambda i: keys[i])]


def _draw_method(r: _Renderer, method: str, layers: int, weight: int):
    gl, scene = r.gl, r.scene
    if method in ("exact", "peeling", "wboit"):
        ext = gl.getExtension("SOFTGL_exact_transparency")
        gl.enable(ext.EXACT_TRANSPARENCY_SOFTGL)
        for obj in scene.objects:
            r.draw_object(obj)
        gl.disable(ext.EXACT_TRANSPARENCY_SOFTGL)
        mode = {"exact": ext.TRANSPARENCY_EXACT_SOFTGL, "peeling": ext.DEPTH_PEELING_SOFTGL,
                "wboit": ext.WEIGHTED_BLENDED_SOFTGL}[method]
        return ext.resolve(mode, layers=layers, weight=weight)
    if method == "unsorted":
        for obj in scene.objects:
            r.draw_object(obj)
    elif method == "sorted_objects":
        for obj in _by_depth_back_to_front(scene.objects, scene.view):
            r.draw_object(obj)
    elif method == "two_pass":
        gl.enable(gl.CULL_FACE)
        for obj in _by_depth_back_to_front(scene.objects, scene.view):
            for face in (gl.FRONT, gl.BACK):   # cull front faces first: back faces are drawn first
                gl.cullFace(face)
                r.draw_object(obj)
        gl.disable(gl.CULL_FACE)
    elif method == "sorted_triangles":
        positions, colors, tris, keys, base = [], [], [], [], 0
        for obj in scene.objects:
            positions.append(_world(obj))
            colors.append(obj.colors())
            t = obj.mesh.triangles.astype(np.int64)
            keys.append(_eye_depths(obj, scene.view)[t].mean(axis=1))
            tris.append(t + base)
            base += len(obj.mesh.positions)
        if tris:
            t, k = np.concatenate(tris), np.concatenate(keys)
            order = np.argsort(k, kind="stable")   # most negative eye z (farthest) first
            r.draw(np.concatenate(positions), np.concatenate(colors), t[order].reshape(-1), r.vp)
    else:
        raise ValueError(f"unknown method {method!r}; one of {', '.join(METHODS)}")
    return None


def render(scene: Scene, method: str = "exact", *, width: int = 256, height: int = 256, layers: int = 4,
           weight: int = 7, samples: int = 1, threads: int | None = None, memory_limit: int | None = None,
           repeat: int = 1) -> Result:
    """Render `scene` with `method` (see the module doc); `seconds` is the best of `repeat` runs.

    Raises GLError (OUT_OF_MEMORY) when an A-buffer method would need more than `memory_limit`
    bytes of fragment records."""
    if method not in METHODS:
        raise ValueError(f"unknown method {method!r}; one of {', '.join(METHODS)}")
    r = _Renderer(scene, width, height, samples, threads)
    if memory_limit is not None:
        r.gl.getExtension("SOFTGL_exact_transparency").setMemoryLimit(int(memory_limit))
    best, exact_float = math.inf, None
    for _ in range(max(1, repeat)):
        t0 = time.perf_counter()
        r.begin()
        f = _draw_method(r, method, layers, weight)
        best = min(best, time.perf_counter() - t0)
        if f is not None:
            exact_float = f[::-1].copy()
    return Result(method if method not in ("peeling", "wboit") else
                  f"{method}({layers if method == 'peeling' else 'eq%d' % weight})",
                  r.image(), best, exact_float=exact_float if method == "exact" else None)


def compare(scene: Scene, methods=None, *, peeling_layers=(1, 2, 4, 8), wboit_weights=(7, 10), **kwargs) -> dict:
    """Render every method on the same scene; each Result carries its error against ``exact``."""
    exact = render(scene, "exact", **kwargs)
    exact.error = error(exact.image, exact.image)
    results = {"exact": exact}
    for m in methods or METHODS[1:]:
        if m == "peeling":
            runs = [render(scene, m, layers=k, **kwargs) for k in peeling_layers]
        elif m == "wboit":
            runs = [render(scene, m, weight=w, **kwargs) for w in wboit_weights]
        else:
            runs = [render(scene, m, **kwargs)]
        for res in runs:
            res.error = error(res.image, exact.image)
            results[res.method] = res
    return results


def depth_complexity(scene: Scene, *, width: int = 256, height: int = 256, samples: int = 1) -> np.ndarray:
    """(height, width) top-down: the most transparent fragments any sample of a pixel keeps."""
    r = _Renderer(scene, width, height, samples, None)
    ext = r.gl.getExtension("SOFTGL_exact_transparency")
    r.begin()
    r.gl.enable(ext.EXACT_TRANSPARENCY_SOFTGL)
    for obj in scene.objects:
        r.draw_object(obj)
    return ext.depthComplexity()[::-1].copy()


def table(results: dict) -> str:
    """A Markdown table of the results: method, seconds, RMSE, max, PSNR."""
    lines = ["| method | time (ms) | RMSE | max | PSNR (dB) |", "|---|---:|---:|---:|---:|"]
    for name, res in results.items():
        e = res.error
        lines.append(f"| {name} | {res.seconds * 1e3:.2f} | {e.rmse:.5f} | {e.max:.4f} | "
                     f"{'inf' if math.isinf(e.psnr) else f'{e.psnr:.2f}'} |")
    return "\n".join(lines)


__all__ = ["METHODS", "Object", "Scene", "Result", "Error", "render", "compare", "error",
           "depth_complexity", "table", "GLError"]


def demo_scene(aspect: float = 1.0) -> Scene:
    """A fixed scene where every approximation shows its failure: four overlapping translucent
    spheres (each object overlaps itself: front and back faces), a torus, two interpenetrating
    quads (no triangle order is right), on an opaque ground. Transparent objects are listed
    front to back, the worst order for ``unsorted``."""
    from .transforms import look_at, perspective, rotate, scale, translate
    m = lambda *ms: np.linalg.multi_dot([np.asarray(x, np.float64) for x in ms] + [np.eye(4)]).astype(np.float32)
    L = (0.4, 1.0, 0.6)
    objects = [
        Object(geometry.sphere(0.55, 24, 12), (0.9, 0.2, 0.2, 0.45), m(translate(0.35, 0.55, 1.2)), "red sphere", L),
        Object(geometry.quad(1.6, 1.0), (0.2, 0.9, 0.3, 0.5),
               m(translate(-0.4, 0.6, 0.4), rotate(0.6, (0, 1, 0))), "green quad", L),
        Object(geometry.quad(1.6, 1.0), (0.95, 0.85, 0.1, 0.5),
               m(translate(-0.4, 0.6, 0.4), rotate(-0.6, (0, 1, 0))), "yellow quad", L),
        Object(geometry.torus(0.6, 0.18, 32, 12), (0.2, 0.8, 0.9, 0.4),
               m(translate(0.5, 0.5, -0.2), rotate(1.1, (1, 0, 0))), "cyan torus", L),
        Object(geometry.sphere(0.6, 24, 12), (0.3, 0.3, 1.0, 0.5), m(translate(-0.3, 0.7, -0.8)), "blue sphere", L),
        Object(geometry.sphere(0.7, 24, 12), (1.0, 0.5, 0.9, 0.35), m(translate(0.6, 0.8, -1.6)), "pink sphere", L),
    ]
    ground = Object(geometry.plane(6, 6, 8, 8), (0.55, 0.5, 0.45, 1.0), m(translate(0, -0.05, 0)), "ground")
    return Scene(objects=objects, opaque=[ground], view=look_at((0.3, 1.8, 3.6), (0, 0.5, 0), (0, 1, 0)),
                 projection=perspective(0.9, aspect, 0.5, 20.0), background=(0.08, 0.08, 0.1, 1.0))
