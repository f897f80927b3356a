"""Shared helpers of the texture tests: a full-viewport quad whose texture coordinates map
linearly to pixel centres, float render targets, and a float64 NumPy reference sampler
(ES 3.0 §3.8.10-11)."""
from __future__ import annotations

import numpy as np

import softgl
from softgl import _core

QUAD = np.array([-1, -1, 1, -1, -1, 1, -1, 1, 1, -1, 1, 1], np.float32)

VS3 = """#version 300 es
in vec2 pos;
uniform vec3 c0, cx, cy;   // coordinate at the bottom-left corner and per viewport width/height
out vec3 uvw;
void main() {
    vec2 f = pos * 0.5 + 0.5;
    uvw = c0 + f.x * cx + f.y * cy;
    gl_Position = vec4(pos, 0.0, 1.0);
}
"""

# A receding quad (w grows along y, so the mip level changes along y) and lookups of its uv in a
# 2D texture, a 2D array and a cube map: the storage tests compare a format against its expansion.
RECEDING_VS = """#version 300 es
in vec2 pos; out vec2 uv;
void main() { float w = 1.0 + (pos.y * 0.5 + 0.5) * 5.0;   // receding: the level changes along y
              uv = (pos * 0.5 + 0.5) * vec2(1.7, 6.0) - vec2(0.35, 0.2);
              gl_Position = vec4(pos * w, 0.0, w); }"""
RECEDING_FS = """#version 300 es
precision highp float; uniform sampler2D tex; in vec2 uv; out vec4 o;
void main() { o = texture(tex, uv); }"""
RECEDING_FS_ARRAY = """#version 300 es
precision highp float; uniform highp sampler2DArray tex; in vec2 uv; out vec4 o;
void main() { o = texture(tex, vec3(uv, uv.y * 0.7)); }"""
RECEDING_FS_CUBE = """#version 300 es
precision highp float; uniform samplerCube tex; in vec2 uv; out vec4 o;
void main() { o = texture(tex, vec3(uv.x - 0.5, 0.8 - uv.y * 0.4, 0.6)); }"""
# (min filter, mag filter) pairs: no LOD choice, bilinear, trilinear.
STORAGE_FILTERS = [("NEAREST", "NEAREST"), ("LINEAR", "LINEAR"), ("LINEAR_MIPMAP_LINEAR", "LINEAR")]



def fs3(sampler="sampler2D", lookup="texture(tex, uvw.xy)", extra=""):
    return f"""#version 300 es
precision highp float;
precision highp sampler2D;
uniform highp {sampler} tex;
uniform float lod;
{extra}
in vec3 uvw;
out vec4 color;
void main() {{ color = vec4({lookup}); }}
"""


def draw_quad(gl, prog, c0=(0, 0, 0), cx=(1, 0, 0), cy=(0, 1, 0)):
    gl.useProgram(prog)
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.bufferData(gl.ARRAY_BUFFER, QUAD, gl.STATIC_DRAW)
    loc = gl.getAttribLocation(prog, "pos")
    gl.enableVertexAttribArray(loc)
    gl.vertexAttribPointer(loc, 2, gl.FLOAT, False, 0, 0)
    for name, v in (("c0", c0), ("cx", cx), ("cy", cy)):
        u = gl.getUniformLocation(prog, name)
        if u is not None:
            gl.uniform3f(u, *[float(x) for x in v])
    gl.drawArrays(gl.TRIANGLES, 0, 6)


def float_source_texture(gl, v, unit=1):
    """An RGBA32F NEAREST texture of v (h, w, 4) on texture unit `unit` (texelFetch of it gives
    exact float32 values); TEXTURE0 is active again afterwards."""
    gl.activeTexture(gl.TEXTURE0 + unit)
    t = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, t)
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, v.shape[1], v.shape[0], 0, gl.RGBA, gl.FLOAT, v)
    for p in (gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER):
        gl.texParameteri(gl.TEXTURE_2D, p, gl.NEAREST)
    gl.activeTexture(gl.TEXTURE0)
    return t

def float_target(gl, w, h):
    """A bound RGBA32F framebuffer (WebGL 2 + EXT_color_buffer_float) of w x h."""
    assert gl.getExtension("EXT_color_buffer_float") is not None
    tex = gl.createTexture()
    gl.activeTexture(gl.TEXTURE15)
    gl.bindTexture(gl.TEXTURE_2D, tex)
    gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA32F, w, h)
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0)
    assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == gl.FRAMEBUFFER_COMPLETE
    gl.viewport(0, 0, w, h)
    gl.activeTexture(gl.TEXTURE0)
    return fb, tex


def render_float(gl, fs, w, h, c0, cx, cy, setup=None):
    """Draws the quad with fragment shader `fs` into a float target; returns (h, w, 4) float32."""
    float_target(gl, w, h)
    prog = softgl.program(gl, VS3, fs)
    gl.useProgram(prog)
    if setup:
        setup(prog)
    draw_quad(gl, prog, c0, cx, cy)
    return gl.readPixels(0, 0, w, h, gl.RGBA, gl.FLOAT)


def pixel_coords(w, h, c0, cx, cy):
    """float64 coordinates at the pixel centres, as the quad interpolates them."""
    y, x = np.mgrid[0:h, 0:w].astype(np.float64)
    fx, fy = (x + 0.5) / w, (y + 0.5) / h
    c0, cx, cy = (np.asarray(v, np.float64) for v in (c0, cx, cy))
    return [c0[k] + fx * cx[k] + fy * cy[k] for k in range(3)]


# ---------------------------------------------------------------------------- float64 reference

def wrap(i, size, mode):
    if mode == "REPEAT":
        return np.mod(i, size)
    if mode == "MIRRORED_REPEAT":
        m = np.mod(i, 2 * size)
        return np.where(m < size, m, 2 * size - 1 - m)
    return np.clip(i, 0, size - 1)


def weight8(frac):
    """README "Choices": LINEAR filtering of 8-bit unorm textures uses 8-bit weights,
    round(256 frac) to nearest even, over 256."""
    return np.round(np.asarray(frac, np.float64) * 256) / 256


def near_weight_tie(s, t, sizes, eps=1e-3):
    """Pixels whose 256 * frac(u - 1/2) or 256 * frac(v - 1/2) lies within eps of a rounding tie on
    a level of one of `sizes` (w, h): there float32 coordinates (interpolated by the pipeline)
    and the float64 ones of the reference may round the 8-bit weight differently."""
    mask = np.zeros(np.shape(s), bool)
    for w, h in sizes:
        for c, n in ((s, w), (t, h)):
            if n == 1:
                continue   # one texel: the weights do not matter
            x = np.asarray(c, np.float64) * n - 0.5
            x = (x - np.floor(x)) * 256
            mask |= np.abs(x - np.floor(x) - 0.5) < eps
    return mask


def sample_level(img, s, t, linear, wrap_s="REPEAT", wrap_t="REPEAT", weights8=False):
    """img: (h, w, 4) float64; s, t arrays; returns (..., 4). weights8: the 8-bit weights of
    LINEAR filtering of 8-bit unorm textures (weight8)."""
    h, w = img.shape[:2]
    u, v = s * w, t * h
    if not linear:
        return img[wrap(np.floor(v).astype(np.int64), h, wrap_t), wrap(np.floor(u).astype(np.int64), w, wrap_s)]
    u0, v0 = u - 0.5, v - 0.5
    i0, j0 = np.floor(u0).astype(np.int64), np.floor(v0).astype(np.int64)
    a, b = (u0 - np.floor(u0))[..., None], (v0 - np.floor(v0))[..., None]
    if weights8:
        a, b = weight8(a), weight8(b)
    i1, j1 = wrap(i0 + 1, w, wrap_s), wrap(j0 + 1, h, wrap_t)
    i0, j0 = wrap(i0, w, wrap_s), wrap(j0, h, wrap_t)
    return ((1 - a) * (1 - b) * img[j0, i0] + a * (1 - b) * img[j0, i1] +
            (1 - a) * b * img[j1, i0] + a * b * img[j1, i1])


def sample_mipmapped(levels, s, t, lam, min_filter, mag_filter="NEAREST", wrap_s="REPEAT", wrap_t="REPEAT",
                     weights8=False):
    """ES 3.0 §3.8.11 with c = 0; `lam` per pixel (weights8: as sample_level)."""
    q = len(levels) - 1
    out = np.zeros(s.shape + (4,))
    mag = lam <= 0
    out[mag] = sample_level(levels[0], s[mag], t[mag], mag_filter == "LINEAR", wrap_s, wrap_t, weights8)
    m = ~mag
    lin = min_filter.startswith("LINEAR")
    if min_filter in ("NEAREST", "LINEAR"):
        out[m] = sample_level(levels[0], s[m], t[m], lin, wrap_s, wrap_t, weights8)
        return out
    L = lam[m]
    if min_filter.endswith("MIPMAP_NEAREST"):
        d = np.where(L <= 0.5, 0, np.where(L <= q + 0.5, np.ceil(L + 0.5) - 1, q)).astype(int)
        res = np.zeros(L.shape + (4,))
        for level in range(q + 1):
            k = d == level
            res[k] = sample_level(levels[level], s[m][k], t[m][k], lin, wrap_s, wrap_t, weights8)
        out[m] = res
        return out
    d1 = np.where(L >= q, q, np.floor(L)).astype(int)
    d2 = np.where(L >= q, q, d1 + 1)
    frac = (L - np.floor(L))[..., None]
    res = np.zeros(L.shape + (4,))
    for level in range(q + 1):
        k1 = d1 == level
        res[k1] += np.where(d2[k1, None] == d1[k1, None], 1.0, 1 - frac[k1]) * sample_level(levels[level], s[m][k1], t[m][k1], lin, wrap_s, wrap_t, weights8)
        k2 = (d2 == level) & (d2 != d1)
        res[k2] += frac[k2] * sample_level(levels[level], s[m][k2], t[m][k2], lin, wrap_s, wrap_t, weights8)
    out[m] = res
    return out


def rgba_expansion(v):
    """RGBA of texels v (..., channels): absent channels 0, alpha 1 (ES 3.0 table 3.24)."""
    out = np.zeros(v.shape[:-1] + (4,), np.float32)
    out[..., 3] = 1.0
    out[..., :v.shape[-1]] = v
    return out


def sampling_configs():
    """(threads, simd, sampler_path): every SIMD level of this CPU, 2 threads, the general path."""
    simd = ["scalar", "sse2", "avx2", "avx512"][:_core.testing.simd_level() + 1]
    return [(1, lv, "best") for lv in simd] + [(2, simd[-1], "best"), (1, simd[-1], "general")]


def float_sampling_context(w, h, threads, simd, path):
    """A WebGL 2 context drawing into a w x h RGBA32F renderbuffer (so every bit a lookup returns
    is kept), with float textures filterable and the given speed-path switches."""
    gl = softgl.Context(w, h, threads=threads, antialias=False, version=2)
    _core.testing.set_tuning(gl, simd=simd, sampler_path=path)
    assert gl.getExtension("EXT_color_buffer_float") is not None
    assert gl.getExtension("OES_texture_float_linear") is not None
    rb = gl.createRenderbuffer()
    gl.bindRenderbuffer(gl.RENDERBUFFER, rb)
    gl.renderbufferStorage(gl.RENDERBUFFER, gl.RGBA32F, w, h)
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.RENDERBUFFER, rb)
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1)
    return gl


def read_float_quad(gl, vs, fs, w, h):
    """Draws the full-viewport quad with (vs, fs); the w x h float pixels it wrote."""
    draw_quad(gl, softgl.program(gl, vs, fs))
    out = np.asarray(gl.readPixels(0, 0, w, h, gl.RGBA, gl.FLOAT), np.float32)
    assert gl.getError() == gl.NO_ERROR
    return out


def sample_float_levels(levels, internal, fmt, filters, wrap, threads, simd, path, w, h):
    """The w x h float pixels of RECEDING_FS over a 2D texture of `internal` whose mip levels are
    `levels` (float arrays, uploaded as FLOAT), with the (min, mag) filters and the wrap mode."""
    gl = float_sampling_context(w, h, threads, simd, path)
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    for k, level in enumerate(levels):
        lh, lw = level.shape[:2]
        gl.texImage2D(gl.TEXTURE_2D, k, getattr(gl, internal), lw, lh, 0, getattr(gl, fmt), gl.FLOAT,
                      np.ascontiguousarray(level))
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, getattr(gl, filters[0]))
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, getattr(gl, filters[1]))
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, getattr(gl, wrap))
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, getattr(gl, wrap))
    return read_float_quad(gl, RECEDING_VS, RECEDING_FS, w, h)
