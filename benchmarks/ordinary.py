"""Ordinary WebGL content, softgl vs Mesa llvmpipe side by side (issue 18, "The benchmark").

    python benchmarks/ordinary.py [--quick] [--only name,name] [--threads 1,2] [--scaling]
                                  [--budget S] [--out FILE]

Each scene is a function ``setup(gl, width, height)`` written with WebGL 2 calls only: it makes
the programs, uploads the geometry (NumPy, fixed seeds) and the textures, and returns ``frame()``,
which issues one frame's calls (clear, state, uniforms, draws, every pass). The same function runs
on a softgl ``Context`` and on llvmpipe through ``webgl_on_gles.WebGLOnGLES`` (the WebGL calls
mapped to OpenGL ES 3.0; the shaders, GLSL ES 3.00 or 1.00, go to Mesa as written). These scenes
are not forced into the single-pass scene descriptions of scenes.py: shadow mapping, render to
texture and post-processing are several passes with framebuffer switches.

Per scene and thread count: one frame on each side is read back (``readPixels``) and compared
(max channel difference, share of pixels within 1/255 and 4/255 of llvmpipe's); then warm-up
frames, then A/B rounds (softgl frames, llvmpipe frames, llvmpipe, softgl, ...) within a time
budget; each timed frame is ``frame(); gl.finish()`` (llvmpipe's ``glFinish`` waits for its
rasterizer threads; softgl's calls are synchronous, its ``finish`` returns at once), no readback.
The table gives medians and the ratio softgl / llvmpipe (< 1: softgl faster), at threads=1 and 2
(softgl ``Context(threads=N)``, llvmpipe ``LP_NUM_THREADS=N`` in its own process), the geometric
mean, and the load average at the start and end of the run. Results: benchmarks/results/ordinary.md.
"""
from __future__ import annotations

import argparse
import math
import os
import shlex
import statistics
import sys
import time
from dataclasses import dataclass
from pathlib import Path

# NumPy's BLAS threads spin after each call and would steal a core from both renderers.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from reference_gl import machine_name  # noqa: E402
from webgl_on_gles import GlesProcess  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results"

# ---------------------------------------------------------------------------------------------
# Matrices (float64, math layout M[row, col]); `flat` gives WebGL's column-major float32.


def flat(m: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(np.asarray(m, np.float64).T.reshape(-1), np.float32)


def perspective(fovy_deg: float, aspect: float, near: float, far: float) -> np.ndarray:
    f = 1.0 / math.tan(math.radians(fovy_deg) / 2)
    return np.array([[f / aspect, 0, 0, 0], [0, f, 0, 0],
                     [0, 0, (far + near) / (near - far), 2 * far * near / (near - far)],
                     [0, 0, -1, 0]])


def ortho(l, r, b, t, n, f) -> np.ndarray:
    return np.array([[2 / (r - l), 0, 0, -(r + l) / (r - l)], [0, 2 / (t - b), 0, -(t + b) / (t - b)],
                     [0, 0, -2 / (f - n), -(f + n) / (f - n)], [0, 0, 0, 1]])


def look_at(eye, target, up=(0, 1, 0)) -> np.ndarray:
    eye, target, up = (np.asarray(v, np.float64) for v in (eye, target, up))
    z = eye - target
    z /= np.linalg.norm(z)
    x = np.cross(up, z)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    m = np.eye(4)
    m[0, :3], m[1, :3], m[2, :3] = x, y, z
    m[:3, 3] = -m[:3, :3] @ eye
    return m


def translate(x, y, z) -> np.ndarray:
    m = np.eye(4)
    m[:3, 3] = (x, y, z)
    return m


def scale(x, y, z) -> np.ndarray:
    return np.diag([x, y, z, 1.0])


def rotate(angle: float, axis) -> np.ndarray:
    a = np.asarray(axis, np.float64)
    a /= np.linalg.norm(a)
    c, s = math.cos(angle), math.sin(angle)
    x, y, z = a
    m = np.eye(4)
    m[:3, :3] = [[c + x * x * (1 - c), x * y * (1 - c) - z * s, x * z * (1 - c) + y * s],
                 [y * x * (1 - c) + z * s, c + y * y * (1 - c), y * z * (1 - c) - x * s],
                 [z * x * (1 - c) - y * s, z * y * (1 - c) + x * s, c + z * z * (1 - c)]]
    return m


def normal_matrix(m: np.ndarray) -> np.ndarray:
    return np.linalg.inv(m[:3, :3]).T


# ---------------------------------------------------------------------------------------------
# Geometry (NumPy, deterministic).


def _index_array(idx: np.ndarray, vertices: int) -> np.ndarray:
    return np.ascontiguousarray(idx, np.uint16 if vertices <= 65536 else np.uint32).reshape(-1)


def uv_sphere(stacks: int, slices: int):
    """Unit sphere: positions (= normals), uvs and indices; 2 * slices * (stacks - 1) triangles
    (the pole rows are single triangles)."""
    theta = np.linspace(0, math.pi, stacks + 1)[:, None]
    phi = np.linspace(0, 2 * math.pi, slices + 1)[None, :]
    pos = np.stack([np.sin(theta) * np.cos(phi), np.cos(theta) + 0 * phi,
                    -np.sin(theta) * np.sin(phi)], axis=-1).reshape(-1, 3)
    uv = np.stack([np.broadcast_to(phi / (2 * math.pi), (stacks + 1, slices + 1)),
                   np.broadcast_to(theta / math.pi, (stacks + 1, slices + 1))], axis=-1).reshape(-1, 2)
    i, j = np.meshgrid(np.arange(stacks), np.arange(slices), indexing="ij")
    a = i * (slices + 1) + j
    b, c, d = a + slices + 1, a + 1, a + slices + 2
    tris = []
    for k in range(stacks):
        if k != 0:
            tris.append(np.stack([a[k], b[k], c[k]], axis=-1))
        if k != stacks - 1:
            tris.append(np.stack([c[k], b[k], d[k]], axis=-1))
    idx = np.concatenate(tris)
    return pos.astype(np.float32), uv.astype(np.float32), _index_array(idx, len(pos))


def sphere_for(triangles: int):
    """A UV sphere with about ``triangles`` triangles."""
    k = max(3, round(math.sqrt(triangles / 2)))
    return uv_sphere(k, k)


def grid(nx: int, nz: int):
    """An nx x nz quad grid on x, z in [-1, 1] (y = 0): positions, uvs in [0, 1], indices."""
    x, z = np.meshgrid(np.linspace(-1, 1, nx + 1), np.linspace(-1, 1, nz + 1))
    pos = np.stack([x, np.zeros_like(x), z], axis=-1).reshape(-1, 3)
    uv = np.stack([(x + 1) / 2, (z + 1) / 2], axis=-1).reshape(-1, 2)
    i, j = np.meshgrid(np.arange(nz), np.arange(nx), indexing="ij")
    a = i * (nx + 1) + j
    b, c, d = a + nx + 1, a + 1, a + nx + 2
    idx = np.stack([a, b, c, c, b, d], axis=-1)
    return pos.astype(np.float32), uv.astype(np.float32), _index_array(idx, len(pos))


def cube():
    """36 vertices of the unit cube [-0.5, 0.5]^3, counter-clockwise outside, face normals."""
    pos, nrm = [], []
    for axis in range(3):
        for sign in (1.0, -1.0):
            n = np.zeros(3)
            n[axis] = sign
            u, v = np.zeros(3), np.zeros(3)
            u[(axis + 1) % 3], v[(axis + 2) % 3] = 1.0, 1.0
            if sign < 0:
                u, v = v, u
            corners = [n * 0.5 + (su * u + sv * v) * 0.5 for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
            for k in (0, 1, 2, 0, 2, 3):
                pos.append(corners[k])
                nrm.append(n)
    return np.array(pos, np.float32), np.array(nrm, np.float32)


def torus(major: float, minor: float, segments: int, sides: int):
    """Positions, normals and indices of a torus around the y axis: 2 * segments * sides triangles."""
    u = np.linspace(0, 2 * math.pi, segments + 1)[:, None]
    v = np.linspace(0, 2 * math.pi, sides + 1)[None, :]
    nrm = np.stack([np.cos(v) * np.cos(u), np.sin(v) + 0 * u, np.cos(v) * np.sin(u)], axis=-1)
    centre = np.stack([major * np.cos(u), 0 * u, major * np.sin(u)], axis=-1)
    pos = (centre + minor * nrm).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(segments), np.arange(sides), indexing="ij")
    a = i * (sides + 1) + j
    b, c, d = a + sides + 1, a + 1, a + sides + 2
    idx = np.stack([a, c, b, c, d, b], axis=-1)
    return (pos.astype(np.float32), nrm.reshape(-1, 3).astype(np.float32),
            _index_array(idx, len(pos)))


def texture_image(size: int, seed: int) -> np.ndarray:
    """An RGBA8 image (size, size, 4) with detail at every scale: checks, stripes, noise."""
    r = np.random.default_rng(seed)
    y, x = np.mgrid[0:size, 0:size] / size
    checks = ((np.floor(x * 16) + np.floor(y * 16)) % 2)[..., None]
    base = np.array([0.85, 0.75, 0.55]) * checks + np.array([0.35, 0.45, 0.3]) * (1 - checks)
    stripes = 0.5 + 0.5 * np.sin(2 * math.pi * (x * 37 + y * 11))[..., None] * np.array([0.3, 0.2, 0.1])
    noise = r.uniform(-0.12, 0.12, (size, size, 1))
    rgb = np.clip(base * stripes + noise, 0, 1)
    rgba = np.concatenate([rgb, np.ones((size, size, 1))], axis=-1)
    return np.round(rgba * 255).astype(np.uint8)


# ---------------------------------------------------------------------------------------------
# WebGL helpers (WebGL calls only: they run on both sides).


def program(gl, vs: str, fs: str):
    prog = gl.createProgram()
    for kind, src in ((gl.VERTEX_SHADER, vs), (gl.FRAGMENT_SHADER, fs)):
        sh = gl.createShader(kind)
        gl.shaderSource(sh, src)
        gl.compileShader(sh)
        if not gl.getShaderParameter(sh, gl.COMPILE_STATUS):
            raise RuntimeError(f"shader does not compile: {gl.getShaderInfoLog(sh)}\n{src}")
        gl.attachShader(prog, sh)
    gl.linkProgram(prog)
    if not gl.getProgramParameter(prog, gl.LINK_STATUS):
        raise RuntimeError(f"program does not link: {gl.getProgramInfoLog(prog)}")
    return prog


def attribute(gl, prog, name: str, data: np.ndarray, divisor: int = 0, normalized: bool = False):
    """A buffer with ``data`` (n, k) bound to attribute ``name`` of the bound vertex array."""
    loc = gl.getAttribLocation(prog, name)
    if loc < 0:
        raise RuntimeError(f"attribute {name} is not active")
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.bufferData(gl.ARRAY_BUFFER, np.ascontiguousarray(data), gl.STATIC_DRAW)
    gtype = {np.dtype(np.float32): gl.FLOAT, np.dtype(np.uint8): gl.UNSIGNED_BYTE}[data.dtype]
    gl.enableVertexAttribArray(loc)
    gl.vertexAttribPointer(loc, 1 if data.ndim == 1 else data.shape[1], gtype, normalized, 0, 0)
    if divisor:
        gl.vertexAttribDivisor(loc, divisor)
    return buf


def indices(gl, idx: np.ndarray):
    """An element buffer in the bound vertex array; returns (count, type) for drawElements."""
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, buf)
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, idx, gl.STATIC_DRAW)
    return idx.size, (gl.UNSIGNED_SHORT if idx.dtype == np.uint16 else gl.UNSIGNED_INT)


def texture_2d(gl, rgba: np.ndarray, min_filter, mag_filter, wrap, mipmap: bool = False):
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    h, w = rgba.shape[:2]
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, w, h, 0, gl.RGBA, gl.UNSIGNED_BYTE, rgba)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, min_filter)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, mag_filter)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, wrap)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, wrap)
    if mipmap:
        gl.generateMipmap(gl.TEXTURE_2D)
    return tex


def framebuffer_complete(gl, what: str) -> None:
    status = gl.checkFramebufferStatus(gl.FRAMEBUFFER)
    if status != gl.FRAMEBUFFER_COMPLETE:
        raise RuntimeError(f"{what}: framebuffer incomplete (0x{status:x})")


def fullscreen_quad(gl, prog, name: str = "aPos"):
    """A vertex array with two triangles covering clip space."""
    vao = gl.createVertexArray()
    gl.bindVertexArray(vao)
    attribute(gl, prog, name, np.array([[-1, -1], [1, -1], [1, 1], [-1, -1], [1, 1], [-1, 1]], np.float32))
    return vao


# ---------------------------------------------------------------------------------------------
# Shaders shared by several scenes.

PHONG_VS = """#version 300 es
uniform mat4 uModelView;
uniform mat4 uProjection;
uniform mat3 uNormalMatrix;
in vec3 aPos;
in vec3 aNormal;
out vec3 vNormal;
out vec3 vViewPos;
void main() {
  vec4 p = uModelView * vec4(aPos, 1.0);
  vViewPos = p.xyz;
  vNormal = uNormalMatrix * aNormal;
  gl_Position = uProjection * p;
}
"""
PHONG_FS = """#version 300 es
precision highp float;
uniform vec3 uLightPos;
uniform vec3 uColor;
uniform float uShininess;
in vec3 vNormal;
in vec3 vViewPos;
out vec4 fragColor;
void main() {
  vec3 N = normalize(vNormal);
  vec3 L = normalize(uLightPos - vViewPos);
  vec3 V = normalize(-vViewPos);
  vec3 R = reflect(-L, N);
  float diffuse = max(dot(N, L), 0.0);
  float specular = pow(max(dot(R, V), 0.0), uShininess);
  fragColor = vec4(uColor * (0.15 + 0.85 * diffuse) + vec3(0.6) * specular, 1.0);
}
"""
COLOR_VS_100 = """attribute vec2 aPos;
attribute vec4 aColor;
varying vec4 vColor;
void main() { vColor = aColor; gl_Position = vec4(aPos, 0.0, 1.0); }
"""
COLOR_FS_100 = """precision mediump float;
varying vec4 vColor;
void main() { gl_FragColor = vColor; }
"""
QUAD_VS = """#version 300 es
in vec2 aPos;
out vec2 vUV;
void main() { vUV = aPos * 0.5 + 0.5; gl_Position = vec4(aPos, 0.0, 1.0); }
"""


# ---------------------------------------------------------------------------------------------
# The scenes: setup(gl, w, h) -> frame().


def terrain(gl, w, h):
    """20k-triangle height field, 512² mipmapped RGBA8 texture (LINEAR_MIPMAP_LINEAR), depth test."""
    vs = """#version 300 es
uniform mat4 uMVP;
in vec3 aPos;
in vec3 aNormal;
in vec2 aUV;
out vec2 vUV;
out float vShade;
void main() {
  vUV = aUV;
  vShade = 0.3 + 0.7 * max(dot(normalize(aNormal), vec3(0.48, 0.8, 0.36)), 0.0);
  gl_Position = uMVP * vec4(aPos, 1.0);
}
"""
    fs = """#version 300 es
precision mediump float;
uniform sampler2D uTex;
in vec2 vUV;
in float vShade;
out vec4 fragColor;
void main() { fragColor = vec4(texture(uTex, vUV).rgb * vShade, 1.0); }
"""
    prog = program(gl, vs, fs)
    pos, uv, idx = grid(100, 100)   # 20,000 triangles
    x, z = pos[:, 0].astype(np.float64), pos[:, 2].astype(np.float64)
    rng = np.random.default_rng(10)
    y = (0.12 * np.sin(3.1 * x + 0.5) * np.cos(2.3 * z) + 0.06 * np.sin(7.3 * x * z + 1.0)
         + rng.uniform(-0.004, 0.004, x.shape))
    pos = np.stack([x * 2, y, z * 2], axis=-1)
    n = np.zeros_like(pos)   # vertex normals: sum of face normals
    tri = idx.reshape(-1, 3).astype(np.int64)
    fn = np.cross(pos[tri[:, 1]] - pos[tri[:, 0]], pos[tri[:, 2]] - pos[tri[:, 0]])
    for k in range(3):
        np.add.at(n, tri[:, k], fn)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    n *= np.sign(n[:, 1:2])   # facing up
    vao = gl.createVertexArray()
    gl.bindVertexArray(vao)
    attribute(gl, prog, "aPos", pos.astype(np.float32))
    attribute(gl, prog, "aNormal", n.astype(np.float32))
    attribute(gl, prog, "aUV", (uv * 6).astype(np.float32))
    count, itype = indices(gl, idx)
    gl.activeTexture(gl.TEXTURE0)
    texture_2d(gl, texture_image(512, 11), gl.LINEAR_MIPMAP_LINEAR, gl.LINEAR, gl.REPEAT, mipmap=True)
    gl.useProgram(prog)
    mvp = perspective(55, w / h, 0.05, 20) @ look_at((0, 0.75, 2.0), (0, -0.1, -0.35))
    gl.uniformMatrix4fv(gl.getUniformLocation(prog, "uMVP"), False, flat(mvp))
    gl.uniform1i(gl.getUniformLocation(prog, "uTex"), 0)
    gl.enable(gl.DEPTH_TEST)
    gl.clearColor(0.55, 0.7, 0.9, 1.0)

    def frame():
        gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
        gl.drawElements(gl.TRIANGLES, count, itype, 0)
    return frame


def _textured_fill(gl, w, h, min_filter: str):
    vs = """#version 300 es
uniform vec2 uScale;
uniform vec2 uOffset;
in vec2 aPos;
out vec2 vUV;
void main() { vUV = (aPos * 0.5 + 0.5) * uScale + uOffset; gl_Position = vec4(aPos, 0.0, 1.0); }
"""
    fs = """#version 300 es
precision mediump float;
uniform sampler2D uTex;
in vec2 vUV;
out vec4 fragColor;
void main() { fragColor = texture(uTex, vUV); }
"""
    prog = program(gl, vs, fs)
    fullscreen_quad(gl, prog)
    mipmap = "MIPMAP" in min_filter
    texture_2d(gl, texture_image(512, 12), getattr(gl, min_filter),
               gl.NEAREST if min_filter == "NEAREST" else gl.LINEAR, gl.REPEAT, mipmap=mipmap)
    gl.useProgram(prog)
    # 1.5 texels per pixel on both axes: minified, so LINEAR_MIPMAP_LINEAR blends levels 0 and 1.
    gl.uniform2f(gl.getUniformLocation(prog, "uScale"), 1.5 * w / 512, 1.5 * h / 512)
    gl.uniform1i(gl.getUniformLocation(prog, "uTex"), 0)
    offset = gl.getUniformLocation(prog, "uOffset")
    offsets = [(0.0, 0.0), (0.31, 0.17), (0.62, 0.41), (0.13, 0.77)]

    def frame():
        gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
        for u, v in offsets:   # four separate full-screen draws
            gl.uniform2f(offset, u, v)
            gl.drawArrays(gl.TRIANGLES, 0, 6)
    return frame


def tex_nearest(gl, w, h):
    """4 full-screen quads (4 draws), one lookup of a 512² texture, NEAREST, 1.5 texels/pixel."""
    return _textured_fill(gl, w, h, "NEAREST")


def tex_linear(gl, w, h):
    """As tex_nearest, LINEAR."""
    return _textured_fill(gl, w, h, "LINEAR")


def tex_trilinear(gl, w, h):
    """As tex_nearest, mipmapped, LINEAR_MIPMAP_LINEAR."""
    return _textured_fill(gl, w, h, "LINEAR_MIPMAP_LINEAR")


def sprites(gl, w, h):
    """5,000 textured quads of 8-48 px from a 512² atlas, tinted (normalized UNSIGNED_BYTE
    colours), alpha-blended (SRC_ALPHA, ONE_MINUS_SRC_ALPHA), one indexed draw; GLSL ES 1.00."""
    vs = """attribute vec2 aPos;
attribute vec2 aUV;
attribute vec4 aColor;
uniform vec2 uViewport;
varying vec2 vUV;
varying vec4 vColor;
void main() {
  vUV = aUV;
  vColor = aColor;
  gl_Position = vec4(aPos / uViewport * 2.0 - 1.0, 0.0, 1.0);
}
"""
    fs = """precision mediump float;
uniform sampler2D uAtlas;
varying vec2 vUV;
varying vec4 vColor;
void main() { gl_FragColor = texture2D(uAtlas, vUV) * vColor; }
"""
    prog = program(gl, vs, fs)
    n, r = 5000, np.random.default_rng(20)
    centre = r.uniform(0, 1, (n, 1, 2)) * (w, h)
    half = r.uniform(4, 24, (n, 1, 1))
    corner = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], np.float64)[None]
    pos = (centre + corner * half).reshape(-1, 2)
    cell = r.integers(0, 64, n)
    cu, cv = (cell % 8) / 8, (cell // 8) / 8
    inset = 0.5 / 512
    uv0 = np.stack([cu + inset, cv + inset], axis=-1)[:, None]
    uv = (uv0 + (corner + 1) / 2 * (1 / 8 - 2 * inset)).reshape(-1, 2)
    color = np.repeat(r.integers(96, 256, (n, 1, 4)), 4, axis=1).reshape(-1, 4).astype(np.uint8)
    quad = np.array([0, 1, 2, 0, 2, 3])
    idx = (np.arange(n)[:, None] * 4 + quad[None]).astype(np.uint16).reshape(-1)
    # The atlas: 8 x 8 cells of 64 px, each a soft disc with rings, alpha falling to 0 at the rim.
    yy, xx = (np.mgrid[0:64, 0:64] + 0.5) / 32 - 1
    rad = np.sqrt(xx ** 2 + yy ** 2)
    atlas = np.zeros((512, 512, 4))
    for k in range(64):
        hue = np.array([0.5 + 0.5 * math.cos(k * 0.7 + o) for o in (0, 2.1, 4.2)])
        rings = 0.75 + 0.25 * np.cos(rad * (6 + k % 5) * math.pi)
        cell_rgba = np.concatenate([hue[None, None] * rings[..., None],
                                    np.clip(1.2 - rad, 0, 1)[..., None] ** 1.5], axis=-1)
        atlas[(k // 8) * 64:(k // 8 + 1) * 64, (k % 8) * 64:(k % 8 + 1) * 64] = cell_rgba
    atlas = np.round(np.clip(atlas, 0, 1) * 255).astype(np.uint8)
    vao = gl.createVertexArray()
    gl.bindVertexArray(vao)
    attribute(gl, prog, "aPos", pos.astype(np.float32))
    attribute(gl, prog, "aUV", uv.astype(np.float32))
    attribute(gl, prog, "aColor", color, normalized=True)
    count, itype = indices(gl, idx)
    texture_2d(gl, atlas, gl.LINEAR, gl.LINEAR, gl.CLAMP_TO_EDGE)
    gl.useProgram(prog)
    gl.uniform2f(gl.getUniformLocation(prog, "uViewport"), w, h)
    gl.uniform1i(gl.getUniformLocation(prog, "uAtlas"), 0)
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)
    gl.clearColor(0.1, 0.1, 0.15, 1.0)

    def frame():
        gl.clear(gl.COLOR_BUFFER_BIT)
        gl.drawElements(gl.TRIANGLES, count, itype, 0)
    return frame


BOX_VS = """#version 300 es
uniform mat4 uViewProj;
uniform mat4 uModel;
in vec3 aPos;
in vec3 aNormal;
out float vShade;
void main() {
  vec3 n = normalize(mat3(uModel) * aNormal);
  vShade = 0.35 + 0.65 * max(dot(n, normalize(vec3(0.4, 0.9, 0.6))), 0.0);
  gl_Position = uViewProj * uModel * vec4(aPos, 1.0);
}
"""
BOX_FS = """#version 300 es
precision mediump float;
uniform vec4 uColor;
in float vShade;
out vec4 fragColor;
void main() { fragColor = vec4(uColor.rgb * vShade, uColor.a); }
"""


def sorted_transparency(gl, w, h):
    """An opaque floor, then 50 transparent boxes sorted back to front, one draw each (model
    matrix and colour uniforms), depth test on (writes on), back faces culled, blending."""
    prog = program(gl, BOX_VS, BOX_FS)
    pos, nrm = cube()
    vao = gl.createVertexArray()
    gl.bindVertexArray(vao)
    attribute(gl, prog, "aPos", pos)
    attribute(gl, prog, "aNormal", nrm)
    eye = np.array([0.0, 3.2, 6.0])
    view_proj = perspective(50, w / h, 0.1, 50) @ look_at(eye, (0, 0.2, 0))
    r = np.random.default_rng(30)
    boxes = []
    for _ in range(50):
        c = np.array([r.uniform(-3.5, 3.5), 0, r.uniform(-3.5, 2.5)])
        s = r.uniform(0.4, 1.1, 3)
        c[1] = s[1] / 2 + r.uniform(0, 0.6)
        model = translate(*c) @ rotate(r.uniform(0, math.pi), (0, 1, 0)) @ scale(*s)
        color = (*r.uniform(0.2, 1.0, 3), r.uniform(0.3, 0.6))
        boxes.append((float(np.linalg.norm(c - eye)), flat(model), color))
    boxes.sort(key=lambda b: -b[0])   # back to front
    floor = flat(translate(0, -0.05, 0) @ scale(10, 0.1, 10))
    gl.useProgram(prog)
    gl.uniformMatrix4fv(gl.getUniformLocation(prog, "uViewProj"), False, flat(view_proj))
    u_model, u_color = gl.getUniformLocation(prog, "uModel"), gl.getUniformLocation(prog, "uColor")
    gl.enable(gl.DEPTH_TEST)
    gl.enable(gl.CULL_FACE)
    gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)
    gl.clearColor(0.2, 0.22, 0.25, 1.0)

    def frame():
        gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
        gl.disable(gl.BLEND)
        gl.uniformMatrix4fv(u_model, False, floor)
        gl.uniform4f(u_color, 0.55, 0.5, 0.45, 1.0)
        gl.drawArrays(gl.TRIANGLES, 0, 36)
        gl.enable(gl.BLEND)
        for _, model, color in boxes:
            gl.uniformMatrix4fv(u_model, False, model)
            gl.uniform4f(u_color, *color)
            gl.drawArrays(gl.TRIANGLES, 0, 36)
    return frame


def wireframe(gl, w, h):
    """A 141 x 141 grid surface as 40,044 LINES (indexed) + an 8,000-point LINE_STRIP (a spiral),
    per-vertex colours, depth test on."""
    vs = """#version 300 es
uniform mat4 uMVP;
in vec3 aPos;
in vec3 aColor;
out vec3 vColor;
void main() { vColor = aColor; gl_Position = uMVP * vec4(aPos, 1.0); }
"""
    fs = """#version 300 es
precision mediump float;
in vec3 vColor;
out vec4 fragColor;
void main() { fragColor = vec4(vColor, 1.0); }
"""
    prog = program(gl, vs, fs)
    n = 141
    x, z = np.meshgrid(np.linspace(-1, 1, n + 1), np.linspace(-1, 1, n + 1))
    y = 0.15 * np.sin(4 * x) * np.cos(3 * z)
    gpos = np.stack([x * 1.6, y, z * 1.6], axis=-1).reshape(-1, 3)
    gcol = np.stack([0.3 + 2 * y + 0 * x, 0.6 + 0 * x, 0.9 - 2 * y], axis=-1).reshape(-1, 3)
    vid = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    rows = np.stack([vid[:, :-1], vid[:, 1:]], axis=-1).reshape(-1, 2)
    cols = np.stack([vid[:-1, :], vid[1:, :]], axis=-1).reshape(-1, 2)
    idx = np.concatenate([rows, cols]).astype(np.uint16).reshape(-1)   # 40,044 segments
    t = np.linspace(0, 1, 8000)
    spos = np.stack([1.3 * np.cos(t * 60) * (1 - 0.6 * t), 0.25 + 0.6 * t,
                     1.3 * np.sin(t * 60) * (1 - 0.6 * t)], axis=-1)
    scol = np.stack([1 - t, 0.8 * t + 0.2, 0.3 + 0 * t], axis=-1)
    grid_vao = gl.createVertexArray()
    gl.bindVertexArray(grid_vao)
    attribute(gl, prog, "aPos", gpos.astype(np.float32))
    attribute(gl, prog, "aColor", gcol.astype(np.float32))
    count, itype = indices(gl, idx)
    strip_vao = gl.createVertexArray()
    gl.bindVertexArray(strip_vao)
    attribute(gl, prog, "aPos", spos.astype(np.float32))
    attribute(gl, prog, "aColor", scol.astype(np.float32))
    gl.useProgram(prog)
    mvp = perspective(50, w / h, 0.1, 20) @ look_at((0, 1.6, 2.6), (0, 0.1, 0))
    gl.uniformMatrix4fv(gl.getUniformLocation(prog, "uMVP"), False, flat(mvp))
    gl.enable(gl.DEPTH_TEST)
    gl.clearColor(0.05, 0.05, 0.08, 1.0)

    def frame():
        gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
        gl.bindVertexArray(grid_vao)
        gl.drawElements(gl.LINES, count, itype, 0)
        gl.bindVertexArray(strip_vao)
        gl.drawArrays(gl.LINE_STRIP, 0, 8000)
    return frame


def _phong_spheres(gl, w, h, triangles_per_sphere: int):
    prog = program(gl, PHONG_VS, PHONG_FS)
    pos, _, idx = sphere_for(triangles_per_sphere)
    vao = gl.createVertexArray()
    gl.bindVertexArray(vao)
    attribute(gl, prog, "aPos", pos)
    attribute(gl, prog, "aNormal", pos)
    count, itype = indices(gl, idx)
    gl.useProgram(prog)
    gl.uniformMatrix4fv(gl.getUniformLocation(prog, "uProjection"), False,
                        flat(perspective(45, w / h, 0.5, 30)))
    gl.uniform3f(gl.getUniformLocation(prog, "uLightPos"), 4.0, 5.0, 2.0)
    gl.uniform1f(gl.getUniformLocation(prog, "uShininess"), 24.0)
    u_mv, u_nm = gl.getUniformLocation(prog, "uModelView"), gl.getUniformLocation(prog, "uNormalMatrix")
    u_color = gl.getUniformLocation(prog, "uColor")
    spheres = []
    for k in range(10):
        col, row = k % 5, k // 5
        mv = (translate(-3.6 + 1.8 * col, 1.05 - 2.1 * row, -8.0 + 0.5 * ((col + row) % 2))
              @ rotate(0.3 * k, (0.3, 1, 0.1)))
        color = (0.5 + 0.5 * math.cos(k), 0.5 + 0.5 * math.cos(k + 2.1), 0.5 + 0.5 * math.cos(k + 4.2))
        spheres.append((flat(mv), flat(normal_matrix(mv)), color))
    gl.enable(gl.DEPTH_TEST)
    gl.enable(gl.CULL_FACE)
    gl.clearColor(0.1, 0.1, 0.12, 1.0)

    def frame():
        gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
        for mv, nm, color in spheres:
            gl.uniformMatrix4fv(u_mv, False, mv)
            gl.uniformMatrix3fv(u_nm, False, nm)
            gl.uniform3f(u_color, *color)
            gl.drawElements(gl.TRIANGLES, count, itype, 0)
    return frame


def phong_spheres(gl, w, h):
    """10 spheres of 19,800 triangles (about 4 px each), per-pixel Phong (normalize, reflect,
    `pow` specular), one draw per sphere, depth test, back faces culled."""
    return _phong_spheres(gl, w, h, 20_000)


def spot_plane(gl, w, h):
    """An 80,000-triangle plane lit per pixel by three spotlights (uniform arrays, `pow` cone
    falloff and specular)."""
    vs = """#version 300 es
uniform mat4 uMVP;
in vec3 aPos;
out vec3 vPos;
out vec3 vNormal;
void main() { vPos = aPos; vNormal = vec3(0.0, 1.0, 0.0); gl_Position = uMVP * vec4(aPos, 1.0); }
"""
    fs = """#version 300 es
precision highp float;
const int numLights = 3;
uniform vec3 uLightPos[numLights];
uniform vec3 uLightDir[numLights];
uniform vec3 uLightColor[numLights];
uniform float uCutoff;
uniform float uExponent;
uniform vec3 uEye;
in vec3 vPos;
in vec3 vNormal;
out vec4 fragColor;
void main() {
  vec3 n = normalize(vNormal);
  vec3 v = normalize(uEye - vPos);
  vec3 c = vec3(0.04);
  for (int i = 0; i < numLights; i++) {
    vec3 l = normalize(uLightPos[i] - vPos);
    float s = dot(-l, normalize(uLightDir[i]));
    if (s > uCutoff) {
      float spot = pow(s, uExponent);
      float diffuse = max(dot(n, l), 0.0);
      float specular = pow(max(dot(n, normalize(l + v)), 0.0), 40.0);
      c += uLightColor[i] * spot * (0.8 * diffuse + specular);
    }
  }
  fragColor = vec4(c, 1.0);
}
"""
    prog = program(gl, vs, fs)
    pos, _, idx = grid(200, 200)   # 80,000 triangles
    vao = gl.createVertexArray()
    gl.bindVertexArray(vao)
    attribute(gl, prog, "aPos", pos * np.float32(3.0))
    count, itype = indices(gl, idx)
    eye = (0.0, 1.5, 2.1)
    gl.useProgram(prog)
    mvp = perspective(50, w / h, 0.1, 20) @ look_at(eye, (0, 0, -0.6))
    gl.uniformMatrix4fv(gl.getUniformLocation(prog, "uMVP"), False, flat(mvp))
    gl.uniform3fv(gl.getUniformLocation(prog, "uLightPos"),
                  np.array([-1.5, 1.5, 0.5, 1.5, 1.8, -0.5, 0.0, 1.2, 1.2], np.float32))
    gl.uniform3fv(gl.getUniformLocation(prog, "uLightDir"),
                  np.array([0.4, -1, -0.3, -0.5, -1, 0.1, 0.1, -1, -0.6], np.float32))
    gl.uniform3fv(gl.getUniformLocation(prog, "uLightColor"),
                  np.array([1, 0.4, 0.3, 0.3, 1, 0.4, 0.4, 0.5, 1], np.float32))
    gl.uniform1f(gl.getUniformLocation(prog, "uCutoff"), 0.75)
    gl.uniform1f(gl.getUniformLocation(prog, "uExponent"), 12.0)
    gl.uniform3f(gl.getUniformLocation(prog, "uEye"), *eye)
    gl.enable(gl.DEPTH_TEST)
    gl.clearColor(0, 0, 0, 1)

    def frame():
        gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
        gl.drawElements(gl.TRIANGLES, count, itype, 0)
    return frame


def small_blended(gl, w, h):
    """10,000 triangles about 12 px across, per-vertex colours, alpha-blended; GLSL ES 1.00."""
    prog = program(gl, COLOR_VS_100, COLOR_FS_100)
    n, r = 10_000, np.random.default_rng(40)
    centre = r.uniform(-1, 1, (n, 1, 2))
    offsets = r.uniform(-1, 1, (n, 3, 2)) * (12.0 / np.array([w, h]))
    pos = (centre + offsets).reshape(-1, 2)
    color = r.uniform(0, 1, (n * 3, 4))
    color[:, 3] = r.uniform(0.2, 0.8, n * 3)
    vao = gl.createVertexArray()
    gl.bindVertexArray(vao)
    attribute(gl, prog, "aPos", pos.astype(np.float32))
    attribute(gl, prog, "aColor", color.astype(np.float32))
    gl.useProgram(prog)
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)
    gl.clearColor(0, 0, 0, 1)

    def frame():
        gl.clear(gl.COLOR_BUFFER_BIT)
        gl.drawArrays(gl.TRIANGLES, 0, 3 * n)
    return frame


def layers(gl, w, h):
    """32 full-screen quads, colours per vertex (a gradient each), alpha-blended, one draw;
    GLSL ES 1.00."""
    prog = program(gl, COLOR_VS_100, COLOR_FS_100)
    quad = np.array([[-1, -1], [1, -1], [1, 1], [-1, -1], [1, 1], [-1, 1]], np.float32)
    r = np.random.default_rng(50)
    corners = r.uniform(0, 1, (32, 4, 4))
    corners[..., 3] = r.uniform(0.1, 0.3, (32, 4))
    color = corners[:, [0, 1, 2, 0, 2, 3]].reshape(-1, 4)
    vao = gl.createVertexArray()
    gl.bindVertexArray(vao)
    attribute(gl, prog, "aPos", np.tile(quad, (32, 1)))
    attribute(gl, prog, "aColor", color.astype(np.float32))
    gl.useProgram(prog)
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)
    gl.clearColor(0, 0, 0, 1)

    def frame():
        gl.clear(gl.COLOR_BUFFER_BIT)
        gl.drawArrays(gl.TRIANGLES, 0, 6 * 32)
    return frame


def small_draws(gl, w, h):
    """50 lit cubes on a 300x150 canvas, one drawArrays per cube with its MVP and model matrices
    and colour as uniforms; depth test; GLSL ES 1.00."""
    vs = """attribute vec3 aPos;
attribute vec3 aNormal;
uniform mat4 uMVP;
uniform mat4 uModel;
varying float vShade;
void main() {
  vec3 n = normalize(mat3(uModel) * aNormal);
  vShade = 0.3 + 0.7 * max(dot(n, vec3(0.36, 0.8, 0.48)), 0.0);
  gl_Position = uMVP * vec4(aPos, 1.0);
}
"""
    fs = """precision mediump float;
uniform vec4 uColor;
varying float vShade;
void main() { gl_FragColor = vec4(uColor.rgb * vShade, 1.0); }
"""
    prog = program(gl, vs, fs)
    pos, nrm = cube()
    vao = gl.createVertexArray()
    gl.bindVertexArray(vao)
    attribute(gl, prog, "aPos", pos)
    attribute(gl, prog, "aNormal", nrm)
    view_proj = perspective(45, w / h, 0.1, 50) @ look_at((0, 0, 9), (0, 0, 0))
    cubes = []
    for k in range(50):
        col, row = k % 10, k // 10
        model = (translate(-5.4 + 1.2 * col, 2.0 - 1.0 * row, 0) @ rotate(0.4 + 0.37 * k, (1, 1, 0))
                 @ scale(0.7, 0.7, 0.7))
        cubes.append((flat(view_proj @ model), flat(model),
                      (0.5 + 0.5 * math.sin(k), 0.5 + 0.5 * math.sin(k + 2), 0.5 + 0.5 * math.sin(k + 4), 1.0)))
    gl.useProgram(prog)
    u_mvp, u_model = gl.getUniformLocation(prog, "uMVP"), gl.getUniformLocation(prog, "uModel")
    u_color = gl.getUniformLocation(prog, "uColor")
    gl.enable(gl.DEPTH_TEST)
    gl.clearColor(0.9, 0.9, 0.9, 1)

    def frame():
        gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
        for mvp, model, color in cubes:
            gl.uniformMatrix4fv(u_mvp, False, mvp)
            gl.uniformMatrix4fv(u_model, False, model)
            gl.uniform4f(u_color, *color)
            gl.drawArrays(gl.TRIANGLES, 0, 36)
    return frame


def shadow_map(gl, w, h):
    """Shadow mapping: a 1024² DEPTH_COMPONENT24 texture rendered from a directional light
    (orthographic), then the camera pass with `sampler2DShadow` lookups (COMPARE_REF_TO_TEXTURE,
    LINEAR: 2x2 percentage-closer filtering); a floor, 8 spheres (1,984 triangles) and 4 boxes,
    13 draws per pass."""
    depth_vs = """#version 300 es
uniform mat4 uLightMVP;
in vec3 aPos;
void main() { gl_Position = uLightMVP * vec4(aPos, 1.0); }
"""
    depth_fs = """#version 300 es
precision mediump float;
void main() {}
"""
    vs = """#version 300 es
uniform mat4 uViewProj;
uniform mat4 uLightViewProj;
uniform mat4 uModel;
in vec3 aPos;
in vec3 aNormal;
out vec3 vNormal;
out vec3 vShadowCoord;
void main() {
  vec4 world = uModel * vec4(aPos, 1.0);
  vNormal = mat3(uModel) * aNormal;
  vec4 l = uLightViewProj * world;
  vShadowCoord = l.xyz / l.w * 0.5 + 0.5;
  gl_Position = uViewProj * world;
}
"""
    fs = """#version 300 es
precision highp float;
uniform highp sampler2DShadow uShadowMap;
uniform vec3 uLightDir;
uniform vec3 uColor;
in vec3 vNormal;
in vec3 vShadowCoord;
out vec4 fragColor;
void main() {
  float lit = texture(uShadowMap, vec3(vShadowCoord.xy, vShadowCoord.z - 0.004));
  float diffuse = max(dot(normalize(vNormal), uLightDir), 0.0);
  fragColor = vec4(uColor * (0.25 + 0.75 * diffuse * lit), 1.0);
}
"""
    depth_prog, prog = program(gl, depth_vs, depth_fs), program(gl, vs, fs)
    spos, _, sidx = sphere_for(2000)
    cpos, cnrm = cube()
    # One vertex array per mesh and program (attribute locations may differ between programs).
    meshes = {}
    for p in (depth_prog, prog):
        vao = gl.createVertexArray()
        gl.bindVertexArray(vao)
        attribute(gl, p, "aPos", spos)
        if p is prog:
            attribute(gl, p, "aNormal", spos)
        count, itype = indices(gl, sidx)
        meshes[("sphere", id(p))] = (vao, count, itype)
        vao = gl.createVertexArray()
        gl.bindVertexArray(vao)
        attribute(gl, p, "aPos", cpos)
        if p is prog:
            attribute(gl, p, "aNormal", cnrm)
        meshes[("cube", id(p))] = (vao, 36, None)
    r = np.random.default_rng(60)
    objects = [("cube", translate(0, -0.05, 0) @ scale(12, 0.1, 12), (0.7, 0.7, 0.65))]
    for k in range(8):
        rad = r.uniform(0.35, 0.7)
        objects.append(("sphere", translate(r.uniform(-3, 3), rad + r.uniform(0, 0.8), r.uniform(-3, 2))
                        @ scale(rad, rad, rad), tuple(r.uniform(0.3, 1, 3))))
    for k in range(4):
        s = r.uniform(0.5, 1.2, 3)
        objects.append(("cube", translate(r.uniform(-3, 3), s[1] / 2, r.uniform(-3, 2))
                        @ rotate(r.uniform(0, 3), (0, 1, 0)) @ scale(*s), tuple(r.uniform(0.3, 1, 3))))
    light_dir = np.array([0.5, 1.0, 0.35])
    light_dir /= np.linalg.norm(light_dir)
    light_vp = ortho(-6, 6, -6, 6, 0.5, 20) @ look_at(light_dir * 9, (0, 0, 0), (0, 1, 0.01))
    view_proj = perspective(50, w / h, 0.1, 40) @ look_at((0, 4.5, 7.5), (0, 0.3, -0.5))
    # The shadow map and its framebuffer (depth only).
    size = 1024
    shadow = gl.createTexture()
    gl.activeTexture(gl.TEXTURE0)
    gl.bindTexture(gl.TEXTURE_2D, shadow)
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.DEPTH_COMPONENT24, size, size, 0, gl.DEPTH_COMPONENT,
                  gl.UNSIGNED_INT, None)
    for pname, value in ((gl.TEXTURE_MIN_FILTER, gl.LINEAR), (gl.TEXTURE_MAG_FILTER, gl.LINEAR),
                         (gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE), (gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE),
                         (gl.TEXTURE_COMPARE_MODE, gl.COMPARE_REF_TO_TEXTURE),
                         (gl.TEXTURE_COMPARE_FUNC, gl.LEQUAL)):
        gl.texParameteri(gl.TEXTURE_2D, pname, value)
    fbo = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fbo)
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.TEXTURE_2D, shadow, 0)
    framebuffer_complete(gl, "shadow map")
    gl.bindFramebuffer(gl.FRAMEBUFFER, None)
    gl.useProgram(prog)
    gl.uniformMatrix4fv(gl.getUniformLocation(prog, "uViewProj"), False, flat(view_proj))
    gl.uniformMatrix4fv(gl.getUniformLocation(prog, "uLightViewProj"), False, flat(light_vp))
    gl.uniform3f(gl.getUniformLocation(prog, "uLightDir"), *light_dir)
    gl.uniform1i(gl.getUniformLocation(prog, "uShadowMap"), 0)
    u_model, u_color = gl.getUniformLocation(prog, "uModel"), gl.getUniformLocation(prog, "uColor")
    u_light_mvp = gl.getUniformLocation(depth_prog, "uLightMVP")
    depth_draws = [(meshes[(kind, id(depth_prog))], flat(light_vp @ m)) for kind, m, _ in objects]
    color_draws = [(meshes[(kind, id(prog))], flat(m), c) for kind, m, c in objects]
    gl.enable(gl.DEPTH_TEST)
    gl.clearColor(0.6, 0.7, 0.8, 1)

    def draw(mesh):
        vao, count, itype = mesh
        gl.bindVertexArray(vao)
        if itype is None:
            gl.drawArrays(gl.TRIANGLES, 0, count)
        else:
            gl.drawElements(gl.TRIANGLES, count, itype, 0)

    def frame():
        gl.bindFramebuffer(gl.FRAMEBUFFER, fbo)
        gl.viewport(0, 0, size, size)
        gl.clear(gl.DEPTH_BUFFER_BIT)
        gl.useProgram(depth_prog)
        for mesh, mvp in depth_draws:
            gl.uniformMatrix4fv(u_light_mvp, False, mvp)
            draw(mesh)
        gl.bindFramebuffer(gl.FRAMEBUFFER, None)
        gl.viewport(0, 0, w, h)
        gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
        gl.useProgram(prog)
        for mesh, model, color in color_draws:
            gl.uniformMatrix4fv(u_model, False, model)
            gl.uniform3f(u_color, *color)
            draw(mesh)
    return frame


def _lit_torus(gl, w, h):
    """A Phong-lit torus of 20,000 triangles, most of the canvas: (vao, count, type, program)."""
    prog = program(gl, PHONG_VS, PHONG_FS)
    pos, nrm, idx = torus(1.0, 0.42, 200, 50)
    vao = gl.createVertexArray()
    gl.bindVertexArray(vao)
    attribute(gl, prog, "aPos", pos)
    attribute(gl, prog, "aNormal", nrm)
    count, itype = indices(gl, idx)
    gl.useProgram(prog)
    mv = translate(0, 0, -3.6) @ rotate(1.0, (1, 0, 0)) @ rotate(0.4, (0, 0, 1))
    gl.uniformMatrix4fv(gl.getUniformLocation(prog, "uProjection"), False,
                        flat(perspective(45, w / h, 0.5, 20)))
    gl.uniformMatrix4fv(gl.getUniformLocation(prog, "uModelView"), False, flat(mv))
    gl.uniformMatrix3fv(gl.getUniformLocation(prog, "uNormalMatrix"), False, flat(normal_matrix(mv)))
    gl.uniform3f(gl.getUniformLocation(prog, "uLightPos"), 3.0, 4.0, 1.0)
    gl.uniform3f(gl.getUniformLocation(prog, "uColor"), 0.9, 0.55, 0.25)
    gl.uniform1f(gl.getUniformLocation(prog, "uShininess"), 32.0)
    return vao, count, itype, prog


def rtt_blur(gl, w, h):
    """Render to texture + a two-pass blur: a lit torus into an RGBA8 texture with a
    DEPTH_COMPONENT24 renderbuffer (cleared each frame), a horizontal 9-tap Gaussian into a second
    texture, the vertical one onto the canvas."""
    blur_fs = """#version 300 es
precision mediump float;
uniform sampler2D uSrc;
uniform vec2 uStep;
in vec2 vUV;
out vec4 fragColor;
const float weight[5] = float[5](0.227027, 0.1945946, 0.1216216, 0.054054, 0.016216);
void main() {
  vec4 c = texture(uSrc, vUV) * weight[0];
  for (int i = 1; i < 5; i++) {
    c += texture(uSrc, vUV + uStep * float(i)) * weight[i];
    c += texture(uSrc, vUV - uStep * float(i)) * weight[i];
  }
  fragColor = c;
}
"""
    torus_vao, count, itype, torus_prog = _lit_torus(gl, w, h)
    blur = program(gl, QUAD_VS, blur_fs)
    quad_vao = fullscreen_quad(gl, blur)
    targets = []
    for with_depth in (True, False):
        tex = gl.createTexture()
        gl.bindTexture(gl.TEXTURE_2D, tex)
        gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, w, h, 0, gl.RGBA, gl.UNSIGNED_BYTE, None)
        for pname, value in ((gl.TEXTURE_MIN_FILTER, gl.LINEAR), (gl.TEXTURE_MAG_FILTER, gl.LINEAR),
                             (gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE), (gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE)):
            gl.texParameteri(gl.TEXTURE_2D, pname, value)
        fbo = gl.createFramebuffer()
        gl.bindFramebuffer(gl.FRAMEBUFFER, fbo)
        gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0)
        if with_depth:
            rb = gl.createRenderbuffer()
            gl.bindRenderbuffer(gl.RENDERBUFFER, rb)
            gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH_COMPONENT24, w, h)
            gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.RENDERBUFFER, rb)
        framebuffer_complete(gl, "render target")
        targets.append((fbo, tex))
    gl.bindFramebuffer(gl.FRAMEBUFFER, None)
    gl.useProgram(blur)
    gl.uniform1i(gl.getUniformLocation(blur, "uSrc"), 0)
    u_step = gl.getUniformLocation(blur, "uStep")
    (scene_fbo, scene_tex), (half_fbo, half_tex) = targets
    gl.clearColor(0.15, 0.2, 0.3, 1)

    def frame():
        gl.bindFramebuffer(gl.FRAMEBUFFER, scene_fbo)
        gl.enable(gl.DEPTH_TEST)
        gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
        gl.useProgram(torus_prog)
        gl.bindVertexArray(torus_vao)
        gl.drawElements(gl.TRIANGLES, count, itype, 0)
        gl.disable(gl.DEPTH_TEST)
        gl.useProgram(blur)
        gl.bindVertexArray(quad_vao)
        gl.bindFramebuffer(gl.FRAMEBUFFER, half_fbo)
        gl.bindTexture(gl.TEXTURE_2D, scene_tex)
        gl.uniform2f(u_step, 1.5 / w, 0.0)
        gl.drawArrays(gl.TRIANGLES, 0, 6)
        gl.bindFramebuffer(gl.FRAMEBUFFER, None)
        gl.bindTexture(gl.TEXTURE_2D, half_tex)
        gl.uniform2f(u_step, 0.0, 1.5 / h)
        gl.drawArrays(gl.TRIANGLES, 0, 6)
    return frame


def instancing(gl, w, h):
    """10,000 instances of a 12-triangle cube (per-instance offset and colour attributes,
    vertexAttribDivisor 1), one drawArraysInstanced, per-vertex lighting, depth test."""
    vs = """#version 300 es
uniform mat4 uViewProj;
in vec3 aPos;
in vec3 aNormal;
in vec3 aOffset;
in vec3 aColor;
out vec3 vColor;
void main() {
  float d = max(dot(aNormal, normalize(vec3(0.3, 0.8, 0.5))), 0.0);
  vColor = aColor * (0.3 + 0.7 * d);
  gl_Position = uViewProj * vec4(aPos * 0.12 + aOffset, 1.0);
}
"""
    fs = """#version 300 es
precision mediump float;
in vec3 vColor;
out vec4 fragColor;
void main() { fragColor = vec4(vColor, 1.0); }
"""
    prog = program(gl, vs, fs)
    pos, nrm = cube()
    turn = rotate(0.6, (1, 1, 0))[:3, :3]   # three faces towards the camera
    pos, nrm = (pos @ turn.T).astype(np.float32), (nrm @ turn.T).astype(np.float32)
    n, r = 10_000, np.random.default_rng(70)
    depth = r.uniform(6, 14, n)
    half_h = math.tan(math.radians(22.5)) * depth
    offsets = np.stack([r.uniform(-1, 1, n) * half_h * w / h, r.uniform(-1, 1, n) * half_h, -depth], axis=-1)
    colors = r.uniform(0.2, 1.0, (n, 3))
    vao = gl.createVertexArray()
    gl.bindVertexArray(vao)
    attribute(gl, prog, "aPos", pos)
    attribute(gl, prog, "aNormal", nrm)
    attribute(gl, prog, "aOffset", offsets.astype(np.float32), divisor=1)
    attribute(gl, prog, "aColor", colors.astype(np.float32), divisor=1)
    gl.useProgram(prog)
    view_proj = perspective(45, w / h, 0.5, 30)
    gl.uniformMatrix4fv(gl.getUniformLocation(prog, "uViewProj"), False, flat(view_proj))
    gl.enable(gl.DEPTH_TEST)
    gl.enable(gl.CULL_FACE)
    gl.clearColor(0.05, 0.05, 0.05, 1)

    def frame():
        gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
        gl.drawArraysInstanced(gl.TRIANGLES, 0, 36, n)
    return frame


def cubemap_env(gl, w, h):
    """Environment mapping: a 6 x 256² RGBA8 cube map, a full-screen sky (one lookup along each
    pixel's view ray) and a reflective sphere of 8,064 triangles over most of the canvas height
    (`reflect`, a second lookup there); LINEAR filtering."""
    sky_vs = """#version 300 es
uniform mat4 uInvViewProj;
in vec2 aPos;
out vec3 vDir;
void main() {
  vec4 far = uInvViewProj * vec4(aPos, 1.0, 1.0);
  vec4 near = uInvViewProj * vec4(aPos, -1.0, 1.0);
  vDir = far.xyz / far.w - near.xyz / near.w;
  gl_Position = vec4(aPos, 0.0, 1.0);
}
"""
    sky_fs = """#version 300 es
precision mediump float;
uniform samplerCube uEnv;
in vec3 vDir;
out vec4 fragColor;
void main() { fragColor = texture(uEnv, normalize(vDir)); }
"""
    obj_vs = """#version 300 es
uniform mat4 uViewProj;
uniform mat4 uModel;
in vec3 aPos;
in vec3 aNormal;
out vec3 vWorld;
out vec3 vNormal;
void main() {
  vec4 world = uModel * vec4(aPos, 1.0);
  vWorld = world.xyz;
  vNormal = mat3(uModel) * aNormal;
  gl_Position = uViewProj * world;
}
"""
    obj_fs = """#version 300 es
precision highp float;
uniform samplerCube uEnv;
uniform vec3 uEye;
in vec3 vWorld;
in vec3 vNormal;
out vec4 fragColor;
void main() {
  vec3 r = reflect(normalize(vWorld - uEye), normalize(vNormal));
  fragColor = vec4(texture(uEnv, r).rgb * 0.85 + vec3(0.05), 1.0);
}
"""
    sky, obj = program(gl, sky_vs, sky_fs), program(gl, obj_vs, obj_fs)
    sky_vao = fullscreen_quad(gl, sky)
    spos, _, sidx = sphere_for(8000)
    obj_vao = gl.createVertexArray()
    gl.bindVertexArray(obj_vao)
    attribute(gl, obj, "aPos", spos)
    attribute(gl, obj, "aNormal", spos)
    count, itype = indices(gl, sidx)
    env = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_CUBE_MAP, env)
    for face in range(6):
        img = texture_image(256, 80 + face).astype(np.float64)
        img[..., :3] *= np.array([[1, 0.6, 0.6], [0.6, 1, 0.6], [0.6, 0.6, 1],
                                  [1, 1, 0.5], [0.5, 1, 1], [1, 0.5, 1]])[face]
        gl.texImage2D(gl.TEXTURE_CUBE_MAP_POSITIVE_X + face, 0, gl.RGBA8, 256, 256, 0, gl.RGBA,
                      gl.UNSIGNED_BYTE, np.round(img).astype(np.uint8))
    for pname, value in ((gl.TEXTURE_MIN_FILTER, gl.LINEAR), (gl.TEXTURE_MAG_FILTER, gl.LINEAR),
                         (gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE), (gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE)):
        gl.texParameteri(gl.TEXTURE_CUBE_MAP, pname, value)
    eye = np.array([0.0, 0.5, 2.6])
    view_proj = perspective(60, w / h, 0.1, 20) @ look_at(eye, (0, 0, 0))
    gl.useProgram(sky)
    gl.uniformMatrix4fv(gl.getUniformLocation(sky, "uInvViewProj"), False, flat(np.linalg.inv(view_proj)))
    gl.uniform1i(gl.getUniformLocation(sky, "uEnv"), 0)
    gl.useProgram(obj)
    gl.uniformMatrix4fv(gl.getUniformLocation(obj, "uViewProj"), False, flat(view_proj))
    gl.uniformMatrix4fv(gl.getUniformLocation(obj, "uModel"), False, flat(scale(1.25, 1.25, 1.25)))
    gl.uniform3f(gl.getUniformLocation(obj, "uEye"), *eye)
    gl.uniform1i(gl.getUniformLocation(obj, "uEnv"), 0)
    gl.enable(gl.CULL_FACE)

    def frame():
        gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
        gl.disable(gl.DEPTH_TEST)
        gl.useProgram(sky)
        gl.bindVertexArray(sky_vao)
        gl.drawArrays(gl.TRIANGLES, 0, 6)
        gl.enable(gl.DEPTH_TEST)
        gl.useProgram(obj)
        gl.bindVertexArray(obj_vao)
        gl.drawElements(gl.TRIANGLES, count, itype, 0)
    return frame


def msaa(gl, w, h):
    """WebGL's default context (antialias: true, 4 samples): the lit torus of rtt_blur. The frame
    ends with readPixels of the canvas into a preallocated array: that is where softgl resolves
    its samples (there is no other way to see them), and llvmpipe's readPixels resolves with a
    blit first, so both sides pay one resolve and one 3 MB copy."""
    vao, count, itype, prog = _lit_torus(gl, w, h)
    gl.enable(gl.DEPTH_TEST)
    gl.clearColor(0.15, 0.2, 0.3, 1)
    pixels = np.empty((h, w, 4), np.uint8)

    def frame():
        gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
        gl.drawElements(gl.TRIANGLES, count, itype, 0)
        gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, pixels)
    return frame


def msaa_fbo(gl, w, h):
    """WebGL 2's multisampled render target: the lit torus into a framebuffer of 4-sample RGBA8
    and DEPTH_COMPONENT24 renderbuffers (renderbufferStorageMultisample), resolved onto the
    (single-sampled) canvas with blitFramebuffer."""
    vao, count, itype, prog = _lit_torus(gl, w, h)
    fbo = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fbo)
    for fmt, attachment in ((gl.RGBA8, gl.COLOR_ATTACHMENT0), (gl.DEPTH_COMPONENT24, gl.DEPTH_ATTACHMENT)):
        rb = gl.createRenderbuffer()
        gl.bindRenderbuffer(gl.RENDERBUFFER, rb)
        gl.renderbufferStorageMultisample(gl.RENDERBUFFER, 4, fmt, w, h)
        gl.framebufferRenderbuffer(gl.FRAMEBUFFER, attachment, gl.RENDERBUFFER, rb)
    framebuffer_complete(gl, "multisampled target")
    gl.enable(gl.DEPTH_TEST)
    gl.clearColor(0.15, 0.2, 0.3, 1)

    def frame():
        gl.bindFramebuffer(gl.FRAMEBUFFER, fbo)
        gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
        gl.drawElements(gl.TRIANGLES, count, itype, 0)
        gl.bindFramebuffer(gl.READ_FRAMEBUFFER, fbo)
        gl.bindFramebuffer(gl.DRAW_FRAMEBUFFER, None)
        gl.blitFramebuffer(0, 0, w, h, 0, 0, w, h, gl.COLOR_BUFFER_BIT, gl.NEAREST)
    return frame


def phong_1e3(gl, w, h):
    """The phong_spheres scene with 10³ triangles in all (10 spheres)."""
    return _phong_spheres(gl, w, h, 100)


def phong_1e4(gl, w, h):
    """... 10⁴ triangles."""
    return _phong_spheres(gl, w, h, 1_000)


def phong_1e5(gl, w, h):
    """... 10⁵ triangles."""
    return _phong_spheres(gl, w, h, 10_000)


def phong_1e6(gl, w, h):
    """... 10⁶ triangles."""
    return _phong_spheres(gl, w, h, 100_000)


@dataclass(frozen=True)
class Spec:
    key: str
    title: str
    setup: object
    width: int = 1024
    height: int = 768
    samples: int = 0   # 4: WebGL's default antialiased context


SCENES = [
    Spec("terrain", "20k-triangle height field, 512² mipmapped texture, trilinear", terrain),
    Spec("tex_nearest", "textured fill, NEAREST (4 full-screen quads)", tex_nearest),
    Spec("tex_linear", "textured fill, LINEAR", tex_linear),
    Spec("tex_trilinear", "textured fill, LINEAR_MIPMAP_LINEAR", tex_trilinear),
    Spec("sprites", "5,000 textured blended sprites, 8-48 px", sprites),
    Spec("sorted_transparency", "floor + 50 sorted transparent boxes", sorted_transparency),
    Spec("wireframe", "40k LINES + 8k-point LINE_STRIP", wireframe),
    Spec("phong_spheres", "10 Phong spheres x 20k triangles", phong_spheres),
    Spec("spot_plane", "80k-triangle plane, 3 spotlights", spot_plane),
    Spec("small_blended", "10k small blended triangles", small_blended),
    Spec("layers", "32 full-screen blended layers", layers),
    Spec("small_draws", "50 cube draws, 300x150", small_draws, 300, 150),
    Spec("shadow_map", "shadow mapping (depth texture + sampler2DShadow)", shadow_map),
    Spec("rtt_blur", "render to texture + 2-pass blur", rtt_blur),
    Spec("instancing", "10k instanced cubes", instancing),
    Spec("cubemap_env", "cube-map environment mapping", cubemap_env),
    Spec("msaa", "default 4x MSAA canvas, lit torus, resolved by readPixels", msaa, samples=4),
]
# Not in the list, so not in the geometric mean: a WebGL 2 technique that shows a cliff.
EXTRA = [
    Spec("msaa_fbo", "4x multisampled FBO, lit torus, blitFramebuffer resolve to the canvas", msaa_fbo),
]
SCALING = [
    Spec("phong_1e3", "Phong spheres, 10³ triangles", phong_1e3),
    Spec("phong_1e4", "Phong spheres, 10⁴ triangles", phong_1e4),
    Spec("phong_1e5", "Phong spheres, 10⁵ triangles", phong_1e5),
    Spec("phong_1e6", "Phong spheres, 10⁶ triangles", phong_1e6),
]
ALL = {s.key: s for s in SCENES + EXTRA + SCALING}


# ---------------------------------------------------------------------------------------------
# The softgl side and the comparison.


def softgl_context(spec: Spec, width: int, height: int, threads: int | None):
    """A softgl WebGL 2 context for ``spec``: WebGL's default attributes except ``antialias``
    (on only for the MSAA scene; llvmpipe's canvas is multisampled only there); GL errors raise."""
    import softgl
    return softgl.Context(width, height, antialias=spec.samples > 0, threads=threads, strict=True)


def canvas_pixels(gl) -> np.ndarray:
    gl.bindFramebuffer(gl.FRAMEBUFFER, None)
    return gl.readPixels(0, 0, gl.drawingBufferWidth, gl.drawingBufferHeight, gl.RGBA,
                         gl.UNSIGNED_BYTE)


def compare(a: np.ndarray, b: np.ndarray) -> dict:
    """Max channel difference and shares of pixels whose max channel difference is <= 1, <= 4
    and > 16 (the last one flags a scene that does not agree: an adapter or softgl bug)."""
    d = np.abs(a.astype(np.int16) - b.astype(np.int16)).max(axis=-1)
    return dict(maxdiff=int(d.max()), within1=float((d <= 1).mean()), within4=float((d <= 4).mean()),
                over16=float((d > 16).mean()))


GROSS_SHARE = 0.05   # more than this share of pixels off by more than 16: the images disagree


def time_softgl(gl, frame, n: int) -> list[float]:
    out, clock = [], time.perf_counter
    for _ in range(n):
        t0 = clock()
        frame()
        gl.finish()
        out.append(clock() - t0)
    return out


def run_scene(spec: Spec, threads: int, lp: GlesProcess, budget: float, scale_down: int = 1) -> dict:
    if spec.width * spec.height < 2 * 300 * 150:   # already small: --quick keeps its size
        scale_down = 1
    w, h = spec.width // scale_down, spec.height // scale_down
    gl = softgl_context(spec, w, h, threads)
    frame = spec.setup(gl, w, h)
    info = lp.setup(spec.setup, w, h, spec.samples)
    frame()
    a = canvas_pixels(gl)
    b = lp.render()
    cmp = compare(a, b)
    # Warm-up (llvmpipe compiles its shader variants at first use), and one frame each that
    # decides how many fit in the budget.
    time_softgl(gl, frame, 1)
    lp.time_frames(1)
    per_frame = max(time_softgl(gl, frame, 1)[0], lp.time_frames(1)[0], 1e-4)
    total = int(min(40, max(5, budget / per_frame)))
    rounds = 4 if total >= 8 else 2
    per_round = max(1, -(-total // rounds))
    ts, tl = [], []
    for k in range(rounds):
        if k % 2 == 0:
            ts += time_softgl(gl, frame, per_round)
            tl += lp.time_frames(per_round)
        else:
            tl += lp.time_frames(per_round)
            ts += time_softgl(gl, frame, per_round)
    ms, ml = statistics.median(ts), statistics.median(tl)
    return dict(key=spec.key, title=spec.title, threads=threads, width=w, height=h,
                samples=spec.samples, softgl=ms, llvmpipe=ml, ratio=ms / ml, n=len(ts),
                soft_spread=(min(ts), max(ts)), lp_spread=(min(tl), max(tl)), llvmpipe_info=info,
                **cmp)


def fmt_ms(t: float) -> str:
    return f"{t * 1e3:.2f}" if t < 0.1 else f"{t * 1e3:.1f}"


def geomean(values) -> float:
    values = list(values)
    return math.exp(statistics.mean(math.log(v) for v in values)) if values else float("nan")


def report(rows: list[dict], load0, load1, started: str, info: dict, command: str,
           note: str = "") -> str:
    out = [f"# Ordinary content: softgl vs llvmpipe (issue 18)\n"]
    out.append(f"- machine: {machine_name()}, {os.cpu_count()} logical CPUs; run {started}")
    out.append(f"- load average (1, 5, 15 min): {load0[0]:.2f}, {load0[1]:.2f}, {load0[2]:.2f} at "
               f"start; {load1[0]:.2f}, {load1[1]:.2f}, {load1[2]:.2f} at end")
    out.append(f"- llvmpipe: {info.get('renderer', '?')} / {info.get('version', '?')}")
    out.append("- times: median ms per frame (`frame(); gl.finish()`, every pass of the frame, no "
               "readback), A/B alternated; ratio = softgl / llvmpipe (< 1: softgl faster); max diff "
               "= largest channel difference of the two canvases; ≤1 and ≤4 = share of pixels "
               "whose channels are all within 1/255 and 4/255 of llvmpipe's")
    out.append(f"- command: `{command}`")
    if note:
        out.append(f"- {note}")
    out.append("")
    mean_keys = {s.key for s in SCENES}
    for scaling in (False, True):
        keys = {s.key for s in (SCALING if scaling else SCENES + EXTRA)}
        part = [r for r in rows if r["key"] in keys]
        for t in sorted({r["threads"] for r in part}):
            sub = [r for r in part if r["threads"] == t]
            head = "Scaling (per-triangle cost)" if scaling else "Scenes"
            out.append(f"## {head}, threads = {t} (softgl threads={t}, LP_NUM_THREADS={t})\n")
            out.append("| scene | canvas | softgl ms | llvmpipe ms | ratio | max diff | ≤1 | ≤4 |")
            out.append("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |")
            for r in sub:
                flag = " **images differ**" if r["over16"] > GROSS_SHARE else ""
                if not scaling and r["key"] not in mean_keys:
                    flag += " (extra: not in the mean)"
                canvas = f"{r['width']}x{r['height']}" + (f" {r['samples']}x" if r["samples"] else "")
                out.append(f"| {r['key']}: {r['title']}{flag} | {canvas} | {fmt_ms(r['softgl'])} | "
                           f"{fmt_ms(r['llvmpipe'])} | {r['ratio']:.2f} | {r['maxdiff']} | "
                           f"{r['within1'] * 100:.1f}% | {r['within4'] * 100:.1f}% |")
            if not scaling:
                mean = [r for r in sub if r["key"] in mean_keys]
                g = geomean(r["ratio"] for r in mean)
                out.append(f"\ngeometric mean ratio: **{g:.2f}** over {len(mean)} scenes "
                           f"({sum(r['ratio'] < 1 for r in mean)} faster than llvmpipe)")
            out.append("")
    return "\n".join(out)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true",
                    help="smoke run: canvases a quarter of the size, short budget")
    ap.add_argument("--only", default="", help="comma-separated scene keys")
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--scaling", action="store_true",
                    help="also the Phong scene at 10³..10⁶ triangles (" + ", ".join(s.key for s in SCALING) + ")")
    ap.add_argument("--budget", type=float, default=None, help="seconds of timed frames per side and scene")
    ap.add_argument("--out", default=None, help="results file (default: results/ordinary.md, written "
                    "by a full run only: without --quick, --only and --budget)")
    ap.add_argument("--note", default="", help="a line added to the report (e.g. which build)")
    args = ap.parse_args(argv)
    only = [k for k in args.only.split(",") if k]
    unknown = [k for k in only if k not in ALL]
    if unknown:
        ap.error(f"unknown scene(s) {', '.join(unknown)}; known: {', '.join(ALL)}")
    specs = [ALL[k] for k in only] if only else SCENES + EXTRA + (SCALING if args.scaling else [])
    if only and args.scaling:
        specs += [s for s in SCALING if s not in specs]
    threads_list = [int(t) for t in args.threads.split(",")]
    budget = args.budget or (0.3 if args.quick else 1.6)
    scale_down = 4 if args.quick else 1
    # The published table is written by a full default run only; partial runs need --out.
    full = not (args.quick or only or args.budget)
    out_path = args.out or (str(RESULTS / "ordinary.md") if full else None)

    import softgl
    load0, started, t_start = os.getloadavg(), time.strftime("%Y-%m-%d %H:%M"), time.perf_counter()
    print(f"softgl from {Path(softgl.__file__).parent}; load average {load0[0]:.2f}", flush=True)
    rows, info = [], {}
    for t in threads_list:
        with GlesProcess(t) as lp:
            for spec in specs:
                r = run_scene(spec, t, lp, budget, scale_down)
                info = r["llvmpipe_info"]
                rows.append(r)
                flag = "  IMAGES DIFFER" if r["over16"] > GROSS_SHARE else ""
                print(f"  t={t} {spec.key:<20} softgl {fmt_ms(r['softgl']):>8} ms  llvmpipe "
                      f"{fmt_ms(r['llvmpipe']):>8} ms  ratio {r['ratio']:5.2f}  maxdiff {r['maxdiff']:3d}"
                      f"  <=1 {r['within1'] * 100:5.1f}%  >16 {r['over16'] * 100:4.1f}%  n={r['n']}{flag}",
                      flush=True)
    load1 = os.getloadavg()
    command = shlex.join(["python", "benchmarks/ordinary.py", *(argv if argv is not None else sys.argv[1:])])
    text = report(rows, load0, load1, started, info, command, args.note)
    print()
    print(text)
    print(f"({time.perf_counter() - t_start:.0f} s)")
    if out_path:
        Path(out_path).parent.mkdir(parents=True, exist_ok=True)
        Path(out_path).write_text(text)
    return rows


if __name__ == "__main__":
    main()
