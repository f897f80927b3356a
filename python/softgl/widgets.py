"""An ipywidgets explorer of blending, depth, masks, culling, fog, antialiasing and transparency.

    from softgl import widgets
    widgets.blend_explorer()                      # in Jupyter: controls and the picture

Every change of a control re-renders the explorer's scene (an opaque ground and cube, then
three transparent objects drawn with the chosen state) with the WebGL API and shows the canvas,
with the WebGL calls the state amounts to. The rendering is ``render(settings)``, a plain
function of a settings dict, so it runs (and is tested) without a browser.
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from . import display, geometry, scene
from . import transforms as T
from .context import Context
from .errors import GLWarning
from .experiments import BLEND_COLOR, BLEND_EQUATIONS, BLEND_FACTORS, DEPTH_FUNCTIONS

CULL = ["none", "BACK", "FRONT", "FRONT_AND_BACK"]
FOG = ["off", "LINEAR", "EXP", "EXP2"]
ANTIALIAS = {"off": 0, "MSAA 2x": 2, "MSAA 4x": 4, "MSAA 16x": 16}

DEFAULTS = dict(src="SRC_ALPHA", dst="ONE_MINUS_SRC_ALPHA", equation="FUNC_ADD",
                depth_func="LESS", depth_mask=False, red=True, green=True, blue=True, alpha=True,
                cull="none", fog="off", fog_density=0.15, antialias="off",
                transparency="sorted", opacity=0.5)

CHOICES = dict(src=BLEND_FACTORS, dst=BLEND_FACTORS[:-1], equation=BLEND_EQUATIONS,
               depth_func=DEPTH_FUNCTIONS, cull=CULL, fog=FOG, antialias=list(ANTIALIAS),
               transparency=list(scene.TRANSPARENCY_MODES))


def check(settings: dict) -> dict:
    """`settings` completed with DEFAULTS; ValueError on an unknown name or choice."""
    unknown = set(settings) - set(DEFAULTS)
    if unknown:
        raise ValueError(f"unknown explorer settings {sorted(unknown)}; known: {sorted(DEFAULTS)}")
    s = {**DEFAULTS, **settings}
    for name, choices in CHOICES.items():
        if s[name] not in choices:
            raise ValueError(f"{name}={s[name]!r}: choose one of {choices}")
    return s


def build_scene(settings: dict) -> scene.Scene:
    """The explorer's scene for `settings` (see the module docstring)."""
    s = check(settings)
    blend = scene.Blend(s["src"], s["dst"], s["equation"], src_alpha="ONE",
                        dst_alpha="ONE_MINUS_SRC_ALPHA", color=BLEND_COLOR)
    sc = scene.Scene(camera=scene.Camera(eye=(0, 2.2, 5.5), target=(0, 0.3, 0), fovy=42),
                     background=(0.93, 0.93, 0.95, 1.0), transparency=s["transparency"])
    sc.lights = [scene.Light((3, 5, 4), (0.9, 0.9, 0.9))]
    sc.add(geometry.plane(6, 6), color=(0.55, 0.6, 0.55), name="ground")
    sc.add(geometry.cube(0.9), color=(0.85, 0.2, 0.15), name="opaque cube",
           model=T.translate(0.9, 0.45, -1.2) @ T.rotate(0.5, (0, 1, 0)))
    a = float(s["opacity"])
    for name, color, model in (
            # nearest first, so that "unsorted" shows the classic ordering error
            ("green torus", (0.1, 0.9, 0.3), T.translate(0.5, 1.0, 0.9) @ T.rotate(1.2, (1, 0, 0))),
            ("yellow cube", (1.0, 0.85, 0.1), T.translate(0.0, 0.8, 0.1) @ T.rotate(0.7, (1, 1, 0))),
            ("blue sphere", (0.1, 0.3, 1.0), T.translate(-0.6, 0.8, -0.7))):
        mesh = (geometry.sphere(0.7, 32, 16) if "sphere" in name else
                geometry.cube(1.0) if "cube" in name else geometry.torus(0.6, 0.2, 48, 16))
        sc.add(mesh, color=color, alpha=a, blend=blend, name=name, model=model)
    sc.transparent_pass = scene.PassState(
        depth_func=s["depth_func"], depth_mask=bool(s["depth_mask"]),
        color_mask=(s["red"], s["green"], s["blue"], s["alpha"]),
        cull=None if s["cull"] == "none" else s["cull"])
    if s["fog"] != "off":
        sc.fog = scene.Fog(s["fog"], density=float(s["fog_density"]), start=2.0, end=12.0,
                           color=(0.93, 0.93, 0.95))
    return sc


@dataclass
class Rendered:
    image: np.ndarray          # (h, w, 3) uint8, top row first, composited over a white page
    calls: str                 # the transparent pass's state as WebGL calls
    error: str | None          # what WebGL said about an invalid state, like a browser console
    stats: dict


def webgl_calls(settings: dict) -> str:
    """The transparent pass's state as the JavaScript a reader would write."""
    s = check(settings)
    mask = ", ".join("true" if s[c] else "false" for c in ("red", "green", "blue", "alpha"))
    lines = [f"gl.enable(gl.BLEND); gl.blendFuncSeparate(gl.{s['src']}, gl.{s['dst']}, gl.ONE, "
             "gl.ONE_MINUS_SRC_ALPHA);",
             f"gl.blendEquation(gl.{s['equation']});",
             f"gl.depthFunc(gl.{s['depth_func']}); gl.depthMask({str(bool(s['depth_mask'])).lower()});",
             f"gl.colorMask({mask});",
             "gl.disable(gl.CULL_FACE);" if s["cull"] == "none"
             else f"gl.enable(gl.CULL_FACE); gl.cullFace(gl.{s['cull']});"]
    if s["fog"] != "off":
        lines.append(f"fog = gl.getExtension('SOFTGL_fog'); gl.enable(fog.FOG); "
                     f"fog.fogi(fog.FOG_MODE, fog.{s['fog']});")
    samples = ANTIALIAS[s["antialias"]]
    lines.append(f"// context: samples={samples}" if samples else "// context: antialias: false")
    lines.append(f"// transparency: {s['transparency']}")
    return "\n".join(lines)


def render(settings: dict | None = None, width: int = 320, height: int = 240) -> Rendered:
    """Render the explorer's scene with `settings` (DEFAULTS for what is missing)."""
    s = check(settings or {})
    samples = ANTIALIAS[s["antialias"]]
    attrs = dict(samples=samples) if samples else dict(antialias=False)
    gl = Context(width, height, preserveDrawingBuffer=True, **attrs)
    error = None
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", GLWarning)
        build_scene(s).render(gl)
    messages = [str(w.message) for w in caught if issubclass(w.category, GLWarning)]
    if messages:
        error = messages[0]
    return Rendered(display.canvas_image(gl, present=False), webgl_calls(s), error,
                    gl.stats())


class BlendExplorer:
    """The controls (``.controls``: name -> widget), the picture (``.image``, an ipywidgets
    Image) and the WebGL calls (``.calls``); ``.settings`` is the current settings dict and
    ``.last`` the last Rendered. Changing a control calls ``update``."""

    def __init__(self, width: int = 320, height: int = 240, **settings):
        import ipywidgets as W
        self.width, self.height = width, height
        s = check(settings)
        self.controls = {}
        for name in ("src", "dst", "equation", "depth_func", "cull", "fog", "antialias",
                     "transparency"):
            self.controls[name] = W.Dropdown(options=CHOICES[name], value=s[name],
                                             description=name.replace("_", " "))
        self.controls["depth_mask"] = W.Checkbox(value=s["depth_mask"], description="depth mask")
        for c in ("red", "green", "blue", "alpha"):
            self.controls[c] = W.Checkbox(value=s[c], description=f"write {c}")
        self.controls["fog_density"] = W.FloatSlider(value=s["fog_density"], min=0.0, max=0.6,
                                                     step=0.01, description="fog density")
        self.controls["opacity"] = W.FloatSlider(value=s["opacity"], min=0.0, max=1.0, step=0.05,
                                                 description="opacity")
        self.image = W.Image(format="png")
        self.calls = W.HTML()
        self.renders = 0
        for widget in self.controls.values():
            widget.observe(self.update, names="value")
        left = W.VBox([self.controls[n] for n in ("src", "dst", "equation", "opacity",
                                                  "depth_func", "depth_mask")])
        right = W.VBox([self.controls[n] for n in ("cull", "fog", "fog_density", "antialias",
                                                   "transparency")] +
                       [W.HBox([self.controls[c] for c in ("red", "green")]),
                        W.HBox([self.controls[c] for c in ("blue", "alpha")])])
        self.widget = W.VBox([W.HBox([left, right]), W.HBox([self.image, self.calls])])
        self.update()

    @property
    def settings(self) -> dict:
        return {name: w.value for name, w in self.controls.items()}

    def update(self, change=None):
        """Re-render with the controls' values and show the picture and the calls."""
        import html
        self.last = render(self.settings, self.width, self.height)
        self.renders += 1
        self.image.value = display.encode_png(self.last.image)
        note = (f"<p style='color:#b00'>{html.escape(self.last.error)}</p>"
                if self.last.error else "")
        self.calls.value = f"<pre style='font-size:11px'>{html.escape(self.last.calls)}</pre>{note}"

    def _ipython_display_(self):
        # The live widget, with the current picture as the PNG a page without a kernel or widget
        # state shows instead (a static HTML export, the docs site, GitHub's viewer).
        import base64
        from IPython.display import publish_display_data
        bundle = dict(self.widget._repr_mimebundle_())
        bundle["image/png"] = base64.b64encode(display.encode_png(self.last.image)).decode("ascii")
        publish_display_data(bundle)

    def _repr_png_(self):   # for viewers without widgets (e.g. an HTML export)
        return display.encode_png(self.last.image)


def blend_explorer(width: int = 320, height: int = 240, **settings) -> BlendExplorer:
    """An ipywidgets explorer: blend funcs/equations, depth func, masks, cull, fog, antialiasing
    and transparency mode; the picture updates as the controls change (see BlendExplorer)."""
    return BlendExplorer(width, height, **settings)
