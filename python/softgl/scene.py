"""A small scene layer over the WebGL API: meshes with materials, lights, a camera, transparency
passes and projection shadows.

    from softgl import geometry, scene
    from softgl.transforms import translate
    s = scene.Scene(camera=scene.Camera(eye=(0, 2, 5)))
    s.add(geometry.plane(6, 6), color=(0.8, 0.8, 0.8), receives_shadow=True)
    s.add(geometry.cube(), color=(1, 0, 0), alpha=0.5, model=translate(0, 1, 0))
    s.lights.append(scene.Light(position=(2, 4, 2)))
    s.shadows = scene.ProjectedShadows(light=0, alpha=0.5)
    s.render(gl)                        # gl = softgl.Context(w, h, stencil=True)

``render`` only calls the WebGL API (so ``gl.stats()`` counts what it did) and draws in this
order:

1. clear color, depth (and stencil when shadows are on);
2. opaque objects that receive shadows (the ground);
3. projected shadows of the shadow casters: each caster is drawn flattened onto the plane
   y = plane_y by the shadow matrix Ms = T(pl)·Mp·T(-pl)·M, in black with the shadow's alpha,
   blended over the ground. The flattened copy lies ε beyond the plane as seen from the camera and
   is drawn with ``depthFunc(GREATER)`` and no depth writes, so it shows only where the ground is
   in front of it: shadows never hang over the ground's edge. A stencil test (EQUAL 0, INCR)
   lets each pixel darken once where shadows overlap (needs ``Context(stencil=True)``);
4. the other opaque objects (``depthFunc(LESS)``), which hide any shadow behind them;
5. transparent objects (any material whose blend mode is not "opaque") with
   ``depthMask(false)``, in the order of the scene's transparency mode:

   ``"sorted"`` (default)  whole objects back to front by the eye depth of their centres;
   ``"unsorted"``          in the order they were added;
   ``"two_pass"``          sorted, and each object's back faces before its front faces;
   ``"depth_write"``       in the order added with depth writes on (the classic mistake);
   ``"exact"``             through SOFTGL_exact_transparency: every blended fragment is kept
                           and composited per pixel in depth order (the A-buffer reference).

Blend modes by name, as in the course notes: "opaque" (blending off), "additive" (ONE, ONE),
"subtractive" (ONE, ONE, FUNC_SUBTRACT: S - D), "reverse_subtractive" (D - S),
"multiplicative" (DST_COLOR, ZERO), "interpolative" (SRC_ALPHA, ONE_MINUS_SRC_ALPHA; the
canvas alpha follows ONE, ONE_MINUS_SRC_ALPHA so an opaque canvas stays opaque),
"premultiplied" (ONE, ONE_MINUS_SRC_ALPHA with the shader's rgb multiplied by alpha), "min" and
"max" (MIN/MAX equations; EXT_blend_minmax in WebGL 1), or a ``Blend`` of explicit factors.
A scene's ``fog`` (a Fog) turns on SOFTGL_fog for the whole render; a material's ``texture``
draws the object with the stock textured program.
The render leaves depth test on, blending, culling, stencil and fog off, and depth writes on.
Programs and mesh buffers are made once per context and reused: a mesh's arrays are uploaded on
its first render, so give a changed mesh as a new Mesh.
"""
from __future__ import annotations

import math
import weakref
from dataclasses import dataclass, field

import numpy as np

from . import _core, programs
from . import transforms as T

E = {name: value for name, value, _version in _core.ENUMS}   # WebGL enum values by name
E.update(MIN=0x8007, MAX=0x8008)


def _enum(v) -> int:
    return E[v] if isinstance(v, str) else int(v)


@dataclass(frozen=True)
class Blend:
    """Explicit blending state: factors and equations (names like "SRC_ALPHA" or enum values).

    The alpha factors and equation default to the color ones; ``color`` sets blendColor;
    ``premultiply`` makes the stock shaders output rgb * alpha."""
    src: int | str
    dst: int | str
    equation: int | str = "FUNC_ADD"
    src_alpha: int | str | None = None
    dst_alpha: int | str | None = None
    equation_alpha: int | str | None = None
    color: tuple | None = None
    premultiply: bool = False

    def apply(self, gl):
        eqs = [_enum(self.equation), _enum(self.equation if self.equation_alpha is None
                                           else self.equation_alpha)]
        if gl.version == 1 and any(e in (E["MIN"], E["MAX"]) for e in eqs):
            if gl.getExtension("EXT_blend_minmax") is None:
                raise RuntimeError("MIN/MAX blending needs EXT_blend_minmax")
        gl.enable(gl.BLEND)
        gl.blendFuncSeparate(_enum(self.src), _enum(self.dst),
                             _enum(self.src if self.src_alpha is None else self.src_alpha),
                             _enum(self.dst if self.dst_alpha is None else self.dst_alpha))
        gl.blendEquationSeparate(*eqs)
        if self.color is not None:
            gl.blendColor(*self.color)


BLEND_MODES = {
    "opaque": None,
    "additive": Blend("ONE", "ONE"),
    "subtractive": Blend("ONE", "ONE", "FUNC_SUBTRACT"),
    "reverse_subtractive": Blend("ONE", "ONE", "FUNC_REVERSE_SUBTRACT"),
    "multiplicative": Blend("DST_COLOR", "ZERO"),
    "interpolative": Blend("SRC_ALPHA", "ONE_MINUS_SRC_ALPHA", src_alpha="ONE"),
    "premultiplied": Blend("ONE", "ONE_MINUS_SRC_ALPHA", premultiply=True),
    "min": Blend("ONE", "ONE", "MIN"),
    "max": Blend("ONE", "ONE", "MAX"),
}


def blend_mode(mode) -> Blend | None:
    """A Blend (or None for opaque) from a name, a Blend, or a tuple (src, dst[, equation])."""
    if mode is None or isinstance(mode, Blend):
        return mode
    if isinstance(mode, str):
        if mode not in BLEND_MODES:
            raise ValueError(f"unknown blend mode {mode!r}; choose one of {sorted(BLEND_MODES)} "
                             "or give a Blend / (src, dst, equation) tuple")
        return BLEND_MODES[mode]
    return Blend(*mode)


SHADINGS = ("constant", "vertex", "random", "lit", "textured")


@dataclass
class Material:
    """How an object looks: ``color`` (rgb or rgba), ``alpha`` (overrides the color's alpha),
    ``blend`` (name, Blend or tuple; default "interpolative" when alpha < 1, else "opaque"),
    ``shading``: "constant" (the color), "vertex" (the mesh's per-vertex colors), "random"
    (a random color per pixel) or "lit" (ambient + the scene's point/spot lights, default);
    ``cull``: cull back faces of opaque objects.
    ``texture``: an image (h, w, 3|4) uint8 (or float in [0, 1]) in texImage2D's row order (row 0
    is v = 0, the bottom as geometry's uvs see it); giving one makes the shading "textured" (the
    texture times the color, unlit), repeated ``texture_repeat`` times, mipmapped and filtered
    with ``texture_filter`` ("linear": LINEAR_MIPMAP_LINEAR / LINEAR, "nearest": NEAREST)."""
    color: tuple = (0.8, 0.8, 0.8)
    alpha: float | None = None
    blend: object = None
    shading: str = "lit"
    cull: bool = False
    texture: object = None
    texture_repeat: tuple = (1.0, 1.0)
    texture_filter: str = "linear"

    def __post_init__(self):
        if self.texture is not None:
            self.shading = "textured"
            image = np.asarray(self.texture)
            if image.ndim != 3 or image.shape[2] not in (3, 4):
                raise ValueError("Material.texture must be an (h, w, 3|4) image")
        elif self.shading == "textured":
            raise ValueError("shading 'textured' needs a texture")
        if self.texture_filter not in ("linear", "nearest"):
            raise ValueError("texture_filter is 'linear' or 'nearest'")
        if self.shading not in SHADINGS:
            raise ValueError(f"unknown shading {self.shading!r}; choose one of {SHADINGS}")
        blend_mode(self.blend)   # validate now, not at render time

    @property
    def rgba(self) -> tuple:
        c = tuple(float(v) for v in self.color)
        alpha = self.alpha if self.alpha is not None else (c[3] if len(c) == 4 else 1.0)
        return c[:3] + (float(alpha),)

    @property
    def blending(self) -> Blend | None:
        if self.blend is None:
            return BLEND_MODES["interpolative"] if self.rgba[3] < 1.0 else None
        return blend_mode(self.blend)


@dataclass
class Node:
    """A mesh placed in the scene by its `model` matrix ((4, 4), math layout)."""
    mesh: object
    material: Material = field(default_factory=Material)
    model: np.ndarray = field(default_factory=T.identity)
    name: str = ""
    casts_shadow: bool = True
    receives_shadow: bool = False

    @property
    def transparent(self) -> bool:
        return self.material.blending is not None

    def center(self) -> np.ndarray:
        """World-space centre of the mesh's bounding box."""
        p = self.mesh.positions
        c = (p.min(axis=0).astype(np.float64) + p.max(axis=0)) / 2
        return (np.asarray(self.model, np.float64) @ np.append(c, 1.0))[:3]


@dataclass
class Light:
    """A point light, or a spot light when `direction` is given (see softgl.programs)."""
    position: tuple = (0.0, 5.0, 5.0)
    color: tuple = (1.0, 1.0, 1.0)
    direction: tuple | None = None
    cutoff: float = 0.0


@dataclass
class Camera:
    """A perspective camera (vertical field of view in degrees), or orthographic when
    `ortho_height` (the visible height) is given."""
    eye: tuple = (0.0, 2.0, 6.0)
    target: tuple = (0.0, 0.0, 0.0)
    up: tuple = (0.0, 1.0, 0.0)
    fovy: float = 45.0
    near: float = 0.1
    far: float = 100.0
    ortho_height: float | None = None

    def view(self) -> np.ndarray:
        return T.look_at(self.eye, self.target, self.up)

    def projection(self, aspect: float) -> np.ndarray:
        if self.ortho_height is not None:
            h = self.ortho_height / 2
            return T.ortho(-h * aspect, h * aspect, -h, h, self.near, self.far)
        return T.perspective(math.radians(self.fovy), aspect, self.near, self.far)


@dataclass
class ProjectedShadows:
    """Shadows of the casters on the plane y = plane_y from a point light: `light` is an index
    into the scene's lights or a position. `alpha` is how dark they are (1: black)."""
    light: int | tuple = 0
    plane_y: float = 0.0
    alpha: float = 0.5
    epsilon: float = 1e-2
    stencil: bool = True

    def matrix(self, scene: "Scene") -> np.ndarray:
        position = (scene.lights[self.light].position if isinstance(self.light, int)
                    else self.light)
        # Sink the shadow ε beyond the plane as seen from the camera (see the module docstring).
        side = 1.0 if scene.camera.eye[1] >= self.plane_y else -1.0
        return T.shadow_matrix(position, self.plane_y, -side * self.epsilon)


@dataclass
class Fog:
    """Fixed-function fog through softgl's SOFTGL_fog extension (OpenGL 1.x fog): `mode` is
    "LINEAR" (start, end), "EXP" or "EXP2" (density); the fog coordinate is the eye depth.
    `blend_aware` fogs blended geometry toward what adds nothing (black for additive blending)
    instead of toward the fog color (FOG_BLEND_AWARE_SOFTGL)."""
    mode: str = "EXP"
    density: float = 0.3
    start: float = 0.0
    end: float = 10.0
    color: tuple = (0.6, 0.65, 0.7)
    blend_aware: bool = False

    def apply(self, gl):
        ext = gl.getExtension("SOFTGL_fog")
        if self.mode not in ("LINEAR", "EXP", "EXP2"):
            raise ValueError(f"unknown fog mode {self.mode!r}")
        gl.enable(ext.FOG)
        ext.fogi(ext.FOG_MODE, getattr(ext, self.mode))
        ext.fogf(ext.FOG_DENSITY, float(self.density))
        ext.fogf(ext.FOG_START, float(self.start))
        ext.fogf(ext.FOG_END, float(self.end))
        ext.fogfv(ext.FOG_COLOR, [float(v) for v in tuple(self.color[:3]) + (1.0,)])
        (gl.enable if self.blend_aware else gl.disable)(ext.FOG_BLEND_AWARE_SOFTGL)

    @staticmethod
    def disable(gl):
        ext = gl.getExtension("SOFTGL_fog")
        gl.disable(ext.FOG)
        gl.disable(ext.FOG_BLEND_AWARE_SOFTGL)


@dataclass
class PassState:
    """WebGL state for the transparent pass, to experiment with: ``depth_func`` (a name like
    "LESS"), ``depth_mask`` (None: what the transparency mode says), ``color_mask`` (r, g, b, a)
    and ``cull`` (None, "BACK", "FRONT" or "FRONT_AND_BACK"; the "two_pass" mode culls itself)."""
    depth_func: str = "LESS"
    depth_mask: bool | None = None
    color_mask: tuple = (True, True, True, True)
    cull: str | None = None


TRANSPARENCY_MODES = ("sorted", "unsorted", "two_pass", "depth_write", "exact")


@dataclass
class Scene:
    objects: list = field(default_factory=list)
    lights: list = field(default_factory=list)
    camera: Camera = field(default_factory=Camera)
    background: tuple = (0.1, 0.1, 0.12, 1.0)
    ambient: tuple = (0.15, 0.15, 0.15)
    transparency: str = "sorted"
    shadows: ProjectedShadows | None = None
    fog: Fog | None = None
    transparent_pass: PassState = field(default_factory=PassState)

    def add(self, mesh, material: Material | None = None, *, model=None, name: str = "",
            casts_shadow: bool = True, receives_shadow: bool = False, **material_args) -> Node:
        """Add a mesh with a material (or the Material arguments as keywords); returns the Node."""
        if material is None:
            material = Material(**material_args)
        elif material_args:
            raise TypeError("give either a Material or its arguments, not both")
        node = Node(mesh, material, T.identity() if model is None else np.asarray(model),
                    name, casts_shadow, receives_shadow)
        self.objects.append(node)
        return node

    def render(self, gl):
        """Draw the scene into gl's drawing buffer (see the module docstring); returns gl."""
        if self.transparency not in TRANSPARENCY_MODES:
            raise ValueError(f"unknown transparency mode {self.transparency!r}; "
                             f"choose one of {TRANSPARENCY_MODES}")
        _renderer(gl).render(self)
        return gl

    def transparent_order(self, view: np.ndarray) -> list:
        """The transparent nodes in the order the transparency mode draws them."""
        nodes = [n for n in self.objects if n.transparent]
        if self.transparency in ("sorted", "two_pass"):
            depth = [(np.asarray(view, np.float64) @ np.append(n.center(), 1.0))[2] for n in nodes]
            nodes = [nodes[i] for i in np.argsort(depth, kind="stable")]   # farthest (most -z) first
        return nodes


# -- Drawing --------------------------------------------------------------------------------------

class _MeshBuffers:
    def __init__(self, gl, mesh):
        self.mesh = mesh   # held so that id(mesh) stays unique while cached
        self.buffers = {}
        for name, data in (("aPosition", mesh.positions), ("aNormal", mesh.normals),
                           ("aColor", mesh.colors), ("aTexCoord", mesh.uvs)):
            if data is not None:
                buf = gl.createBuffer()
                gl.bindBuffer(gl.ARRAY_BUFFER, buf)
                gl.bufferData(gl.ARRAY_BUFFER, np.ascontiguousarray(data, np.float32), gl.STATIC_DRAW)
                self.buffers[name] = (buf, data.shape[1])
        self.index_buffer = gl.createBuffer()
        gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, self.index_buffer)
        gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, mesh.indices, gl.STATIC_DRAW)
        if mesh.indices.dtype == np.uint32 and gl.version == 1:
            gl.getExtension("OES_element_index_uint")


class _Renderer:
    """Programs and mesh buffers of one context, reused across renders."""

    def __init__(self, gl):
        self.gl = weakref.proxy(gl)
        self.programs = {}
        self.meshes = {}
        self.textures = {}
        self.enabled = set()

    def program(self, shading: str, light_count: int) -> programs.Program:
        key = (shading, light_count if shading == "lit" else 0)
        if key not in self.programs:
            gl = self.gl
            self.programs[key] = {"constant": programs.constant_color, "vertex": programs.vertex_color,
                                  "random": programs.random_color, "textured": programs.textured,
                                  }[shading](gl) \
                if shading != "lit" else programs.lights(gl, light_count)
        return self.programs[key]

    def bind_texture(self, material: Material, unit: int = 0):
        """Upload the material's texture once per context (keyed by the array's identity) and
        bind it to `unit`."""
        gl = self.gl
        image = material.texture
        key = (id(image), material.texture_filter)
        entry = self.textures.get(key)
        gl.activeTexture(gl.TEXTURE0 + unit)
        if entry is None:
            data = np.asarray(image)
            if data.dtype != np.uint8:
                data = np.floor(np.clip(data.astype(np.float64), 0, 1) * 255 + 0.5).astype(np.uint8)
            data = np.ascontiguousarray(data)
            h, w, n = data.shape
            fmt = gl.RGBA if n == 4 else gl.RGB
            tex = gl.createTexture()
            gl.bindTexture(gl.TEXTURE_2D, tex)
            gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1)
            gl.texImage2D(gl.TEXTURE_2D, 0, fmt, w, h, 0, fmt, gl.UNSIGNED_BYTE, data)
            pot = (w & (w - 1)) == 0 and (h & (h - 1)) == 0
            linear = material.texture_filter == "linear"
            if pot or gl.version == 2:
                if linear:
                    gl.generateMipmap(gl.TEXTURE_2D)
                wrap = gl.REPEAT
            else:
                wrap = gl.CLAMP_TO_EDGE   # WebGL 1: NPOT textures only clamp, without mipmaps
            gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, wrap)
            gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, wrap)
            mipmapped = linear and (pot or gl.version == 2)
            gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER,
                             gl.LINEAR_MIPMAP_LINEAR if mipmapped else gl.LINEAR if linear else gl.NEAREST)
            gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.LINEAR if linear else gl.NEAREST)
            entry = self.textures[key] = (tex, image)   # hold the image so that its id stays unique
        else:
            gl.bindTexture(gl.TEXTURE_2D, entry[0])

    def draw(self, prog, node: Node, model, uniforms: dict):
        gl = self.gl
        mesh = node.mesh
        entry = self.meshes.get(id(mesh))
        if entry is None:
            entry = self.meshes[id(mesh)] = _MeshBuffers(gl, mesh)
        prog.set(uModel=model, **uniforms)
        if gl.version == 2:
            gl.bindVertexArray(None)
        for loc in self.enabled:
            gl.disableVertexAttribArray(loc)
        self.enabled = set()
        for name, loc in prog.attributes.items():
            if name in entry.buffers:
                buf, size = entry.buffers[name]
                gl.bindBuffer(gl.ARRAY_BUFFER, buf)
                gl.enableVertexAttribArray(loc)
                gl.vertexAttribPointer(loc, size, gl.FLOAT, False, 0, 0)
                self.enabled.add(loc)
            elif name == "aColor":   # a mesh without colors: the material's color for every vertex
                gl.vertexAttrib4f(loc, *uniforms.get("uMaterialDiffuse", (1, 1, 1, 1)))
        gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, entry.index_buffer)
        gl.drawElements(gl.TRIANGLES, mesh.count, mesh.index_type, 0)

    def render(self, scene: Scene):
        gl = self.gl
        w, h = gl.drawingBufferWidth, gl.drawingBufferHeight
        view = scene.camera.view()
        frame = dict(uView=view, uProjection=scene.camera.projection(w / h),
                     uLightAmbient=tuple(scene.ambient[:3]) + (1.0,), uVisibility=1.0)
        n_lights = max(1, len(scene.lights))
        lights = scene.lights or [Light(color=(0, 0, 0))]
        frame.update(
            uLightPositions=[l.position for l in lights],
            uLightDirections=[(0, 0, 0) if l.direction is None else l.direction for l in lights],
            uLightColors=[tuple(l.color[:3]) + (1.0,) for l in lights],
            uLightCutoffs=[l.cutoff for l in lights])

        shadows = scene.shadows
        use_stencil = shadows is not None and shadows.stencil
        if use_stencil and not gl.getContextAttributes()["stencil"]:
            raise ValueError("projected shadows with stencil=True need Context(..., stencil=True) "
                             "(or ProjectedShadows(stencil=False): overlaps then darken twice)")

        gl.viewport(0, 0, w, h)
        gl.disable(gl.SCISSOR_TEST)
        gl.colorMask(True, True, True, True)
        gl.clearColor(*scene.background)
        gl.clearDepth(1.0)
        gl.depthMask(True)
        bits = gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT
        if use_stencil:
            gl.stencilMask(0xFF)
            gl.clearStencil(0)
            bits |= gl.STENCIL_BUFFER_BIT
        gl.clear(bits)
        gl.enable(gl.DEPTH_TEST)
        gl.depthFunc(gl.LESS)
        gl.disable(gl.BLEND)
        gl.disable(gl.STENCIL_TEST)
        gl.disable(gl.CULL_FACE)

        if scene.fog is not None:
            scene.fog.apply(gl)

        def draw_node(node, model=None, shading=None, **extra):
            m = node.material
            blend = m.blending
            uniforms = dict(frame, uMaterialDiffuse=m.rgba, uMaterialAmbient=m.rgba,
                            uNormalMatrix=T.normal_matrix(view @ node.model),
                            uPremultiply=int(bool(blend and blend.premultiply)))
            uniforms.update(extra)
            shading = shading or m.shading
            if shading == "textured":
                self.bind_texture(m)
                uniforms.update(uTexture0=0, uTexScale0=m.texture_repeat)
            prog = self.program(shading, n_lights)
            self.draw(prog, node, node.model if model is None else model, uniforms)

        def set_cull(enabled, face=None):
            if enabled:
                gl.enable(gl.CULL_FACE)
                gl.cullFace(face or gl.BACK)
            else:
                gl.disable(gl.CULL_FACE)

        opaque = [n for n in scene.objects if not n.transparent]
        receivers = [n for n in opaque if n.receives_shadow]
        for node in receivers:
            set_cull(node.material.cull)
            draw_node(node)
        set_cull(False)

        if shadows is not None:
            ms = shadows.matrix(scene)
            gl.depthFunc(gl.GREATER)
            gl.depthMask(False)
            gl.enable(gl.BLEND)
            # Darken the color; leave the canvas alpha as it is.
            gl.blendFuncSeparate(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA, gl.ZERO, gl.ONE)
            gl.blendEquation(gl.FUNC_ADD)
            if use_stencil:
                gl.enable(gl.STENCIL_TEST)
                gl.stencilFunc(gl.EQUAL, 0, 0xFF)
                gl.stencilOp(gl.KEEP, gl.KEEP, gl.INCR)
            for node in scene.objects:
                if node.casts_shadow and not node.receives_shadow:
                    draw_node(node, ms @ np.asarray(node.model, np.float64), shading="constant",
                              uVisibility=0.0, uMaterialDiffuse=(0.0, 0.0, 0.0, shadows.alpha),
                              uPremultiply=0)
            gl.disable(gl.STENCIL_TEST)
            gl.disable(gl.BLEND)
            gl.depthMask(True)
            gl.depthFunc(gl.LESS)

        for node in opaque:
            if not node.receives_shadow:
                set_cull(node.material.cull)
                draw_node(node)
        set_cull(False)

        transparent = scene.transparent_order(view)
        state = scene.transparent_pass
        gl.depthMask(scene.transparency == "depth_write" if state.depth_mask is None
                     else bool(state.depth_mask))
        gl.depthFunc(_enum(state.depth_func))
        gl.colorMask(*(bool(v) for v in state.color_mask))
        set_cull(state.cull is not None, None if state.cull is None else _enum(state.cull))
        exact = gl.getExtension("SOFTGL_exact_transparency") if scene.transparency == "exact" else None
        if exact is not None:
            gl.enable(exact.EXACT_TRANSPARENCY_SOFTGL)
        for node in transparent:
            node.material.blending.apply(gl)
            if scene.transparency == "two_pass":
                set_cull(True, gl.FRONT)    # back faces first
                draw_node(node)
                set_cull(True, gl.BACK)
                draw_node(node)
                set_cull(state.cull is not None, None if state.cull is None else _enum(state.cull))
            else:
                draw_node(node)
        if exact is not None:
            exact.resolve()
            gl.disable(exact.EXACT_TRANSPARENCY_SOFTGL)
        set_cull(False)
        gl.colorMask(True, True, True, True)
        gl.depthFunc(gl.LESS)
        gl.disable(gl.BLEND)
        gl.blendEquation(gl.FUNC_ADD)
        gl.depthMask(True)
        if scene.fog is not None:
            Fog.disable(gl)


_RENDERERS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def draw_mesh(gl, prog: programs.Program, mesh, model=None, **uniforms):
    """Draw a geometry.Mesh with a programs.Program (its buffers are uploaded once per context
    and reused), after setting `uniforms`; the current WebGL state (depth, blending, ...) applies.
    The mesh's positions, normals and colors feed ``aPosition``, ``aNormal`` and ``aColor``."""
    node = Node(mesh, model=T.identity() if model is None else np.asarray(model))
    _renderer(gl).draw(prog, node, node.model, uniforms)


def _renderer(gl) -> _Renderer:
    r = _RENDERERS.get(gl)
    if r is None:
        r = _RENDERERS[gl] = _Renderer(gl)
    return r
