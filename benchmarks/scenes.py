"""The scenes of the issue-7 suite and the issue-3 executor benchmark, as plain scene descriptions
(``reference_gl.Scene``), plus the softgl side: ``SoftglRenderer`` replays a scene through softgl's
WebGL API exactly as ``reference_gl.LlvmpipeRenderer`` replays it through Mesa's GLES.

Each scene is built once, deterministically (fixed seeds), at any size, so the same description
serves the benchmark (1024x1024) and the byte-exact regression test (small sizes).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

try:  # as a script (python benchmarks/suite.py) or as a package module (tests)
    from reference_gl import GL, Draw, Scene, State, Texture, _enum
except ImportError:  # pragma: no cover
    from .reference_gl import GL, Draw, Scene, State, Texture, _enum

# ---------------------------------------------------------------------------------------------
# Shaders: GLSL ES 3.00, given unchanged to both implementations.

COLOR_VS = """#version 300 es
in vec2 aPos;
in vec4 aColor;
out vec4 vColor;
void main() { vColor = aColor; gl_Position = vec4(aPos, 0.0, 1.0); }
"""
COLOR_VS_Z = """#version 300 es
in vec3 aPos;
in vec4 aColor;
out vec4 vColor;
void main() { vColor = aColor; gl_Position = vec4(aPos, 1.0); }
"""
COLOR_FS = """#version 300 es
precision mediump float;
in vec4 vColor;
out vec4 fragColor;
void main() { fragColor = vColor; }
"""
UNIFORM_VS = """#version 300 es
in vec2 aPos;
void main() { gl_Position = vec4(aPos, 0.0, 1.0); }
"""
UNIFORM_FS = """#version 300 es
precision mediump float;
uniform vec4 uColor;
out vec4 fragColor;
void main() { fragColor = uColor; }
"""
POINT_VS = """#version 300 es
uniform vec2 uOffset;
uniform float uSize;
void main() { gl_Position = vec4(uOffset, 0.0, 1.0); gl_PointSize = uSize; }
"""
SPOT_VS = """#version 300 es
const int numLights = 3;
uniform mat4 uModelViewMatrix;
uniform mat4 uNormalMatrix;
uniform mat4 uProjectionMatrix;
uniform vec3 uLightPositions[numLights];
uniform vec3 uLightDirections[numLights];
in vec3 aPos;
in vec3 aNormal;
out vec3 vRay[numLights];
out vec3 vTransformedNormals[numLights];
void main(void) {
  vec4 vertex = uModelViewMatrix * vec4(aPos, 1.0);
  vec3 normal = vec3(uNormalMatrix * vec4(aNormal, 1.0));
  for (int i = 0; i < numLights; i++) {
    vec4 lightPosition = uModelViewMatrix * vec4(uLightPositions[i], 1.0);
    vRay[i] = vertex.xyz - lightPosition.xyz;
    vec3 directionLight = vec3(uNormalMatrix * vec4(uLightDirections[i], 1.0));
    vTransformedNormals[i] = normal - directionLight;
  }
  gl_Position = uProjectionMatrix * vertex;
}"""
SPOT_FS = """#version 300 es
precision mediump float;
const int numLights = 3;
uniform vec4 uLightColors[numLights];
uniform vec4 uMaterialAmbient;
uniform vec4 uMaterialDiffuse;
uniform vec4 uLightAmbient;
uniform float uLightCutOff;
in vec3 vRay[numLights];
in vec3 vTransformedNormals[numLights];
out vec4 fragColor;
void main(void) {
  vec4 Ia = uLightAmbient * uMaterialAmbient;
  vec4 Id = vec4(0.0);
  for (int i = 0; i < numLights; i++) {
    vec3 N = normalize(vTransformedNormals[i]);
    vec3 L = normalize(vRay[i]);
    float lambertTerm = dot(N, -L);
    if (lambertTerm > uLightCutOff) {
      Id += uLightColors[i] * uMaterialDiffuse * pow(lambertTerm, 10.0 * uLightCutOff);
    }
  }
  fragColor = vec4(vec3(Ia + Id), 1.0);
}"""

# The textured variant (issue 7 #5 as written): the same lighting, modulated by a texture.
SPOT_TEX_VS = SPOT_VS.replace("in vec3 aNormal;", "in vec3 aNormal;\nin vec2 aUV;\nout vec2 vUV;").replace(
    "  gl_Position = uProjectionMatrix * vertex;", "  vUV = aUV * vec2(4.0, 2.0);\n  gl_Position = uProjectionMatrix * vertex;")
SPOT_TEX_FS = SPOT_FS.replace("out vec4 fragColor;", "uniform sampler2D uTex;\nin vec2 vUV;\nout vec4 fragColor;").replace(
    "  fragColor = vec4(vec3(Ia + Id), 1.0);", "  fragColor = vec4(vec3(Ia + Id) * texture(uTex, vUV).rgb, 1.0);")

# ---------------------------------------------------------------------------------------------
# Scene builders. `size` is the framebuffer side in pixels; geometry is given in clip space or
# scaled so that the pixel sizes the issue names hold at any framebuffer size.


def _rng(seed: int) -> np.random.Generator:
    return np.random.default_rng(seed)


def small_blended_triangles(size: int, n: int = 10_000, pixels: float = 12.0) -> Scene:
    """Issue 7 #1: n small (about `pixels` px across) alpha-blended triangles, colors per vertex."""
    r = _rng(1)
    centre = r.uniform(-1, 1, (n, 1, 2))
    offsets = r.uniform(-1, 1, (n, 3, 2)) * (pixels / size)
    pos = (centre + offsets).reshape(-1, 2)
    color = r.uniform(0, 1, (n * 3, 4))
    color[:, 3] = r.uniform(0.2, 0.8, n * 3)
    return Scene(COLOR_VS, COLOR_FS, {"aPos": pos, "aColor": color},
                 state=State(blend=True, blend_func=("SRC_ALPHA", "ONE_MINUS_SRC_ALPHA")))


def large_triangles(size: int, blend: bool, depth: bool, n: int = 100) -> Scene:
    """Issue 7 #2: n large overlapping triangles (each about a third of the screen), fill rate."""
    r = _rng(2)
    centre = r.uniform(-0.4, 0.4, (n, 1, 2))
    ang = r.uniform(0, 2 * math.pi, (n, 1)) + np.array([0, 2.1, 4.2])[None, :]
    rad = r.uniform(0.9, 1.3, (n, 3))
    xy = centre + np.stack([np.cos(ang) * rad, np.sin(ang) * rad], axis=2)
    z = np.repeat(r.uniform(-0.9, 0.9, (n, 1)), 3, axis=1)[..., None]
    pos = np.concatenate([xy, z], axis=2).reshape(-1, 3)
    color = r.uniform(0, 1, (n * 3, 4))
    color[:, 3] = 0.5
    return Scene(COLOR_VS_Z, COLOR_FS, {"aPos": pos, "aColor": color},
                 state=State(blend=blend, blend_func=("SRC_ALPHA", "ONE_MINUS_SRC_ALPHA"),
                             depth_test=depth, depth_func="LESS"))


def tiny_depth_triangles(size: int, n: int = 100_000, pixels: float = 2.0) -> Scene:
    """Issue 7 #3: n tiny (about `pixels` px) depth-tested triangles: setup/binning rate."""
    r = _rng(3)
    centre = r.uniform(-1, 1, (n, 1, 2))
    offsets = r.uniform(-1, 1, (n, 3, 2)) * (pixels / size)
    xy = centre + offsets
    z = np.repeat(r.uniform(-1, 1, (n, 1)), 3, axis=1)[..., None]
    pos = np.concatenate([xy, z], axis=2).reshape(-1, 3)
    color = r.uniform(0, 1, (n * 3, 4))
    color[:, 3] = 1
    return Scene(COLOR_VS_Z, COLOR_FS, {"aPos": pos, "aColor": color},
                 state=State(depth_test=True, depth_func="LESS"))


def point_draws(size: int, n: int = 1000) -> Scene:
    """Issue 7 #4: n draw calls of one point each, with uniform changes between them."""
    r = _rng(4)
    draws = [Draw(0, 1, {"uOffset": tuple(float(v) for v in r.uniform(-1, 1, 2)),
                         "uColor": tuple(float(v) for v in r.uniform(0, 1, 4))}) for _ in range(n)]
    return Scene(POINT_VS, UNIFORM_FS, {}, uniforms={"uSize": 4.0}, mode="POINTS", count=1,
                 draws=draws)


def _mat(m: np.ndarray) -> tuple:
    return tuple(float(v) for v in np.asarray(m, np.float64).T.ravel())   # column-major


def spotlight_mesh(size: int, segments: int = 64) -> Scene:
    """Issue 7 #5 (untextured until softgl has textures): a torus lit by 3 spotlights, filling
    most of the screen, depth-tested. The fragment shader is issue 3's (b)."""
    from softgl import geometry, transforms as T
    mesh = geometry.torus(0.75, 0.35, segments, segments // 2)
    proj = T.perspective(math.radians(45), 1.0, 0.1, 10.0)
    mv = T.translate(0, 0, -2.6) @ T.rotate(0.6, (1, 0, 0)) @ T.rotate(0.3, (0, 1, 0))
    nm = np.asarray(T.normal_matrix(mv), np.float64)
    nm4 = np.eye(4)
    nm4[:nm.shape[0], :nm.shape[1]] = nm
    return Scene(SPOT_VS, SPOT_FS, {"aPos": mesh.positions, "aNormal": mesh.normals},
                 indices=mesh.indices.astype(np.uint32),
                 uniforms={"uModelViewMatrix": _mat(mv), "uNormalMatrix": _mat(nm4),
                           "uProjectionMatrix": _mat(proj),
                           "uLightPositions": (0.0, 1.5, 1.0, -1.5, 0.0, 1.0, 1.5, -0.5, 1.0),
                           "uLightDirections": (0.0, -0.3, -1.0, 0.3, 0.0, -1.0, -0.3, 0.2, -1.0),
                           "uLightColors": (1.0, 0.3, 0.3, 1.0, 0.3, 1.0, 0.3, 1.0, 0.3, 0.3, 1.0, 1.0),
                           "uMaterialAmbient": (0.2, 0.2, 0.2, 1.0),
                           "uMaterialDiffuse": (0.9, 0.9, 0.9, 1.0),
                           "uLightAmbient": (0.3, 0.3, 0.3, 1.0), "uLightCutOff": 0.2},
                 state=State(depth_test=True, depth_func="LESS", clear_color=(0, 0, 0, 1)))


def spotlight_mesh_textured(size: int, segments: int = 64) -> Scene:
    """Issue 7 #5 as written: the lit torus of spotlight_mesh, its colour modulated by a
    mipmapped 256x256 texture (trilinear), texture coordinates from the mesh."""
    from softgl import geometry
    base = spotlight_mesh(size, segments)
    mesh = geometry.torus(0.75, 0.35, segments, segments // 2)
    attrs = dict(base.attributes)
    attrs["aUV"] = mesh.uvs
    tex = {"uTex": Texture(_texture_image(256, 33), "LINEAR_MIPMAP_LINEAR", "LINEAR", mipmap=True)}
    return Scene(SPOT_TEX_VS, SPOT_TEX_FS, attrs, indices=base.indices, uniforms=dict(base.uniforms),
                 textures=tex, state=base.state)


def fullscreen_layers(size: int, layers: int = 32) -> Scene:
    """Issue 7 #7: `layers` full-screen translucent quads, blended: bandwidth."""
    quad = np.array([[-1, -1], [1, -1], [1, 1], [-1, -1], [1, 1], [-1, 1]], np.float32)
    r = _rng(7)
    draws = [Draw(6 * k, 6, {"uColor": tuple(float(v) for v in r.uniform(0, 1, 4))})
             for k in range(layers)]
    return Scene(UNIFORM_VS, UNIFORM_FS, {"aPos": np.tile(quad, (layers, 1))}, draws=draws,
                 state=State(blend=True, blend_func=("SRC_ALPHA", "ONE_MINUS_SRC_ALPHA")))


def lines(size: int, n: int = 10_000, pixels: float = 40.0) -> Scene:
    """Issue 7 #8: n lines of about `pixels` px, width 1, colors per vertex."""
    r = _rng(8)
    a = r.uniform(-1, 1, (n, 1, 2))
    ang = r.uniform(0, 2 * math.pi, (n, 1))
    d = np.stack([np.cos(ang), np.sin(ang)], axis=2) * (pixels / size)
    pos = np.concatenate([a, a + d], axis=1).reshape(-1, 2)
    color = r.uniform(0, 1, (n * 2, 4))
    color[:, 3] = 1
    return Scene(COLOR_VS, COLOR_FS, {"aPos": pos, "aColor": color}, mode="LINES")


TEX_VS = """#version 300 es
in vec2 aPos;
uniform float uScale;
out vec2 vUV;
void main() { vUV = (aPos * 0.5 + 0.5) * uScale; gl_Position = vec4(aPos, 0.0, 1.0); }
"""
TEX1_FS = """#version 300 es
precision mediump float;
uniform sampler2D uTex;
in vec2 vUV;
out vec4 fragColor;
void main() { fragColor = texture(uTex, vUV); }
"""
TEX2_FS = """#version 300 es
precision mediump float;
uniform sampler2D uBase;
uniform sampler2D uDetail;
in vec2 vUV;
out vec4 fragColor;
void main() { fragColor = texture(uBase, vUV) * texture(uDetail, vUV * 4.0); }
"""


def _texture_image(size: int, seed: int) -> np.ndarray:
    """A (size, size, 4) RGBA8 image with detail at every scale (checks + noise)."""
    r = _rng(seed)
    y, x = np.mgrid[0:size, 0:size]
    checks = (((x // 8) + (y // 8)) % 2)[..., None] * 96
    noise = r.integers(0, 160, (size, size, 4))
    img = np.clip(checks + noise, 0, 255).astype(np.uint8)
    img[..., 3] = 255
    return img


def textured_quads(kind: str, layers: int = 8, tex_size: int = 512, scale: float = 3.0) -> Scene:
    """Issue 5 textured fill rate (one lookup: nearest, bilinear, trilinear) and issue 3 (c) (two
    lookups): `layers` full-screen quads, no blending, no depth. Texture coordinates run over
    `scale` repeats of a `tex_size`² texture, so at 1024² a pixel covers 1.5 texels (LOD ~0.6:
    minified, trilinear blends levels 0 and 1). Each quad is a draw of its own, so that every
    layer is shaded (softgl removes hidden surfaces within a draw)."""
    quad = np.array([[-1, -1], [1, -1], [1, 1], [-1, -1], [1, 1], [-1, 1]], np.float32)
    pos = np.tile(quad, (layers, 1))
    if kind == "two":
        tex = {"uBase": Texture(_texture_image(tex_size, 31), "LINEAR_MIPMAP_LINEAR", "LINEAR", mipmap=True),
               "uDetail": Texture(_texture_image(64, 32), "LINEAR", "LINEAR")}
        return Scene(TEX_VS, TEX2_FS, {"aPos": pos}, uniforms={"uScale": scale}, textures=tex,
                     draws=_quad_draws(layers))
    filters = {"nearest": ("NEAREST", "NEAREST", False), "bilinear": ("LINEAR", "LINEAR", False),
               "trilinear": ("LINEAR_MIPMAP_LINEAR", "LINEAR", True)}[kind]
    tex = {"uTex": Texture(_texture_image(tex_size, 30), filters[0], filters[1], mipmap=filters[2])}
    return Scene(TEX_VS, TEX1_FS, {"aPos": pos}, uniforms={"uScale": scale}, textures=tex,
                 draws=_quad_draws(layers))


def _quad_draws(layers: int) -> list:
    """One draw per full-screen quad (6 vertices each)."""
    return [Draw(6 * k, 6) for k in range(layers)]


def executor_scene(kind: str, layers: int = 8) -> Scene:
    """Issue 3's executor benchmark: `layers` full-screen quads with (a) an interpolated color or
    (b) Lambert with 3 spotlights, no blending, no depth: every pixel is shaded `layers` times
    (a draw per quad: softgl removes hidden surfaces within a draw)."""
    quad = np.array([[-1, -1], [1, -1], [1, 1], [-1, -1], [1, 1], [-1, 1]], np.float32)
    pos = np.tile(quad, (layers, 1))
    if kind == "color":
        color = np.tile(np.array([[1, 0, 0, 1], [0, 1, 0, 1], [0, 0, 1, 1], [1, 0, 0, 1],
                                  [0, 0, 1, 1], [1, 1, 1, 1]], np.float32), (layers, 1))
        return Scene(COLOR_VS, COLOR_FS, {"aPos": pos, "aColor": color}, draws=_quad_draws(layers))
    if kind == "spot":
        base = spotlight_mesh(64)
        p3 = np.concatenate([pos * 0.9, np.full((len(pos), 1), -2.0)], axis=1)
        normal = np.tile(np.array([[0.3, 0.2, 1], [-0.3, 0.1, 1], [0, -0.4, 1], [0.3, 0.2, 1],
                                   [0, -0.4, 1], [0.2, 0.4, 0.9]], np.float32), (layers, 1))
        u = dict(base.uniforms)
        u["uModelViewMatrix"] = _mat(np.eye(4))
        u["uNormalMatrix"] = _mat(np.eye(4))
        # Orthographic-like projection: clip = (x, y, 0, 1) after w = 1 (z = -2 mapped into range).
        proj = np.array([[1 / 0.9, 0, 0, 0], [0, 1 / 0.9, 0, 0], [0, 0, 0.1, 0], [0, 0, 0, 1]])
        u["uProjectionMatrix"] = _mat(proj)
        return Scene(SPOT_VS, SPOT_FS, {"aPos": p3, "aNormal": normal}, uniforms=u, draws=_quad_draws(layers))
    raise ValueError(kind)


@dataclass
class SceneSpec:
    key: str
    title: str
    build: object            # size -> Scene
    samples: int = 0
    note: str = ""
    bytes_per_frame: object = None   # (scene, size, samples) -> bytes the scene must move at least
    extra: dict = field(default_factory=dict)


def _fill_bytes(layers: int, read: bool, depth: bool, coverage: float = 1.0):
    """A fill-bound frame: each covered pixel writes 4 color bytes (+ reads 4 when blending,
    + reads and writes 3..4 depth bytes when depth-tested), `layers` times, over `coverage` of it."""
    def f(scene, size, samples):
        per = 4 + (4 if read else 0) + (8 if depth else 0)
        return layers * coverage * size * size * per * max(1, samples)
    return f


SUITE = [
    SceneSpec("small_blend", "10k small blended triangles", small_blended_triangles),
    SceneSpec("large_b0_d0", "100 large tris, blend off, depth off", lambda s: large_triangles(s, False, False)),
    SceneSpec("large_b1_d0", "100 large tris, blend on, depth off", lambda s: large_triangles(s, True, False)),
    SceneSpec("large_b0_d1", "100 large tris, blend off, depth on", lambda s: large_triangles(s, False, True)),
    SceneSpec("large_b1_d1", "100 large tris, blend on, depth on", lambda s: large_triangles(s, True, True)),
    SceneSpec("tiny_depth", "100k tiny depth-tested triangles", tiny_depth_triangles),
    SceneSpec("points_1000", "1000 single-point draws + uniforms", point_draws),
    SceneSpec("spot_mesh", "lit mesh, 3 spotlights (untextured)", spotlight_mesh),
    SceneSpec("spot_mesh_tex", "lit textured mesh, 3 spotlights", spotlight_mesh_textured),
    SceneSpec("spot_mesh_msaa", "same, MSAA 4x", spotlight_mesh, samples=4),
    SceneSpec("layers_32", "32 full-screen blended layers", fullscreen_layers,
              bytes_per_frame=_fill_bytes(32, True, False)),
    SceneSpec("lines_10k", "10k lines", lines),
]

EXECUTOR = [
    SceneSpec("exec_color", "(a) interpolated color", lambda s: executor_scene("color")),
    SceneSpec("exec_spot", "(b) Lambert, 3 spotlights", lambda s: executor_scene("spot")),
    SceneSpec("exec_tex2", "(c) two texture lookups", lambda s: textured_quads("two")),
]

# Issue 5: textured fill rate, 8 full-screen quads with one lookup (1 thread and all threads).
TEXTURED = [
    SceneSpec("tex_nearest", "textured fill, nearest", lambda s: textured_quads("nearest"),
              bytes_per_frame=_fill_bytes(8, False, False)),
    SceneSpec("tex_bilinear", "textured fill, bilinear", lambda s: textured_quads("bilinear"),
              bytes_per_frame=_fill_bytes(8, False, False)),
    SceneSpec("tex_trilinear", "textured fill, trilinear (mipmapped)", lambda s: textured_quads("trilinear"),
              bytes_per_frame=_fill_bytes(8, False, False)),
]


# ---------------------------------------------------------------------------------------------
# The softgl side.

class SoftglRenderer:
    """Replays a ``Scene`` through softgl's WebGL API (the same calls a WebGL page would make)."""

    def __init__(self, width: int, height: int, threads: int = 1, samples: int = 0):
        import softgl
        self.softgl = softgl
        kw = dict(antialias=samples > 0, threads=threads, preserveDrawingBuffer=True)
        if samples:
            kw["samples"] = samples
        self.gl = softgl.Context(width, height, **kw)
        self.width, self.height, self.threads, self.samples = width, height, threads, samples
        self._prepared: dict[int, tuple] = {}

    def _uniform_call(self, prog, name: str, value):
        gl = self.gl
        base = name[:-3] if name.endswith("[0]") else name
        loc = gl.getUniformLocation(prog, base)
        if loc is None:
            loc = gl.getUniformLocation(prog, base + "[0]")
        if loc is None:
            return None
        info = None
        for i in range(gl.getProgramParameter(prog, gl.ACTIVE_UNIFORMS)):
            a = gl.getActiveUniform(prog, i)
            if a.name in (base, base + "[0]"):
                info = a
                break
        t = info.type
        v = np.atleast_1d(np.asarray(value, np.float64))
        floats = {gl.FLOAT: 1, gl.FLOAT_VEC2: 2, gl.FLOAT_VEC3: 3, gl.FLOAT_VEC4: 4}
        mats = {gl.FLOAT_MAT4: "uniformMatrix4fv", gl.FLOAT_MAT3: "uniformMatrix3fv",
                gl.FLOAT_MAT2: "uniformMatrix2fv"}
        if t in floats:
            k = floats[t]
            if len(v) == k and k > 0:
                fn = getattr(gl, f"uniform{k}f")
                args = (loc, *(float(x) for x in v))
                return fn, args
            return getattr(gl, f"uniform{k}fv"), (loc, v.astype(np.float32))
        if t in mats:
            return getattr(gl, mats[t]), (loc, False, v.astype(np.float32))
        ints = {gl.INT: 1, gl.SAMPLER_2D: 1, gl.BOOL: 1}
        if t in ints:
            return gl.uniform1i, (loc, int(v[0]))
        raise NotImplementedError(f"uniform type {t:#x} of {name}")

    def prepare(self, scene: Scene):
        key = id(scene)
        if key in self._prepared:
            return self._prepared[key]
        gl = self.gl
        prog = self.softgl.program(gl, scene.vertex_shader, scene.fragment_shader)
        gl.useProgram(prog)
        # Textures: unit i for the i-th sampler, as reference_gl does.
        for unit, (name, tex) in enumerate(scene.textures.items()):
            data = np.ascontiguousarray(tex.data, dtype=np.uint8)
            h, w = data.shape[:2]
            gl.activeTexture(gl.TEXTURE0 + unit)
            gl.bindTexture(gl.TEXTURE_2D, gl.createTexture())
            gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1)
            gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, w, h, 0, gl.RGBA, gl.UNSIGNED_BYTE, data)
            for pname, value in ((gl.TEXTURE_MIN_FILTER, tex.min_filter), (gl.TEXTURE_MAG_FILTER, tex.mag_filter),
                                 (gl.TEXTURE_WRAP_S, tex.wrap_s), (gl.TEXTURE_WRAP_T, tex.wrap_t)):
                gl.texParameteri(gl.TEXTURE_2D, pname, _enum(value))
            if tex.mipmap:
                gl.generateMipmap(gl.TEXTURE_2D)
            gl.uniform1i(gl.getUniformLocation(prog, name), unit)
        vao = gl.createVertexArray()
        gl.bindVertexArray(vao)
        for name, array in scene.attributes.items():
            loc = gl.getAttribLocation(prog, name)
            if loc < 0:
                continue
            data = np.ascontiguousarray(array, np.float32)
            comps = 1 if data.ndim == 1 else data.shape[1]
            buf = gl.createBuffer()
            gl.bindBuffer(gl.ARRAY_BUFFER, buf)
            gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW)
            gl.enableVertexAttribArray(loc)
            gl.vertexAttribPointer(loc, comps, gl.FLOAT, False, 0, 0)
        index_type = None
        if scene.indices is not None:
            idx = np.ascontiguousarray(scene.indices)
            if idx.dtype not in (np.uint8, np.uint16, np.uint32):
                idx = idx.astype(np.uint32)
            index_type = {np.dtype(np.uint8): gl.UNSIGNED_BYTE, np.dtype(np.uint16): gl.UNSIGNED_SHORT,
                          np.dtype(np.uint32): gl.UNSIGNED_INT}[idx.dtype]
            index_size = idx.itemsize
            buf = gl.createBuffer()
            gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, buf)
            gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, idx, gl.STATIC_DRAW)
        mode = _enum(scene.mode)
        calls = [c for c in (self._uniform_call(prog, n, v) for n, v in scene.uniforms.items()) if c]
        total = scene.vertex_count()
        for d in (scene.draws if scene.draws is not None else [Draw()]):
            calls += [c for c in (self._uniform_call(prog, n, v) for n, v in d.uniforms.items()) if c]
            count = total - d.first if d.count is None else d.count
            if index_type is None:
                calls.append((gl.drawArrays, (mode, d.first, count)))
            else:
                calls.append((gl.drawElements, (mode, count, index_type, d.first * index_size)))
        prepared = (prog, vao, calls, scene)
        self._prepared[key] = prepared
        return prepared

    def _apply_state(self, s: State) -> None:
        gl = self.gl
        (gl.enable if s.blend else gl.disable)(gl.BLEND)
        f = [_enum(x) for x in s.blend_func]
        gl.blendFuncSeparate(*(f * 2 if len(f) == 2 else f))
        e = [_enum(x) for x in s.blend_equation]
        gl.blendEquationSeparate(*(e * 2 if len(e) == 1 else e))
        gl.blendColor(*s.blend_color)
        (gl.enable if s.depth_test else gl.disable)(gl.DEPTH_TEST)
        gl.depthFunc(_enum(s.depth_func))
        gl.depthMask(bool(s.depth_mask))
        (gl.enable if s.cull_face is not None else gl.disable)(gl.CULL_FACE)
        if s.cull_face is not None:
            gl.cullFace(_enum(s.cull_face))
        gl.frontFace(_enum(s.front_face))
        gl.colorMask(*(bool(m) for m in s.color_mask))
        gl.lineWidth(s.line_width)
        gl.clearColor(*s.clear_color)
        gl.clearDepth(s.clear_depth)

    def _begin(self, scene: Scene):
        p = self.prepare(scene)
        self.gl.useProgram(p[0])
        self.gl.bindVertexArray(p[1])
        self._apply_state(scene.state)
        return p

    def _frame(self, p) -> None:
        gl = self.gl
        s = p[3].state
        gl.depthMask(True)
        gl.colorMask(True, True, True, True)
        gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
        gl.depthMask(bool(s.depth_mask))
        gl.colorMask(*(bool(m) for m in s.color_mask))
        for fn, args in p[2]:
            fn(*args)

    def render(self, scene: Scene) -> np.ndarray:
        self._frame(self._begin(scene))
        gl = self.gl
        return gl.readPixels(0, 0, self.width, self.height, gl.RGBA, gl.UNSIGNED_BYTE)

    def time_draws(self, scene: Scene, repeats: int = 10, warmup: int = 1) -> list[float]:
        p = self._begin(scene)
        for _ in range(warmup):
            self._frame(p)
        out = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            self._frame(p)
            out.append(time.perf_counter() - t0)
        return out

    def stats(self) -> dict:
        return self.gl.stats()
