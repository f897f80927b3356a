"""LINEAR filtering of 8-bit unorm textures follows the fixed-point rule of README "Choices":
weights A = round(256 a), B = round(256 b) (nearest, ties to even) of the fractions of ES 3.0
eq. 3.20, texels as their bytes k, and the value
    ((256 - A)(256 - B) k00 + A (256 - B) k10 + (256 - A) B k01 + A B k11) / (255 * 65536)
rounded to float32; mipmap levels blend in float32 as (1 - f) * lo + f * hi.

Each draw is compared, bit for bit, with that rule computed here from float32 coordinates (the
shader computes them from gl_FragCoord, so they are known exactly) and float64/integer sums, on
every sampler path (general, fast scalar, AVX2 blocks, best SIMD: the context's tuning) and at 1
and 2 threads, at the first draw (texels read from the float storage) and the second (the byte
copy, Texture::rgba8). The float64 quotient rounds to float32 as the exact one does: the sum's
quotient by 255 * 2^16 is m / 2^16 exactly or has a binary expansion of period 8 that is not all
zeros or ones, so no double rounding can land on a float32 tie."""
import numpy as np
import pytest

import softgl
from softgl import _core
from helpers import float_target

PATHS = ["general", "scalar", "avx2", "best"]
W, H = 40, 36   # target size

VS = """#version 300 es
in vec2 pos;
void main() { gl_Position = vec4(pos, 0.0, 1.0); }
"""
FS = """#version 300 es
precision highp float;
precision highp sampler2D;
uniform highp sampler2D tex;
uniform vec2 scale, offset;
uniform float lod;
uniform bool explicit_lod;
out vec4 color;
void main() {
    vec2 uv = gl_FragCoord.xy * scale + offset;
    color = explicit_lod ? textureLod(tex, uv, lod) : texture(tex, uv);
}
"""
QUAD = np.array([-1, -1, 1, -1, -1, 1, -1, 1, 1, -1, 1, 1], np.float32)
F = np.float32


def wrap(i, n, mode):
    if mode == "REPEAT":
        return np.mod(i, n)
    if mode == "MIRRORED_REPEAT":
        m = np.mod(i, 2 * n)
        return np.where(m < n, m, 2 * n - 1 - m)
    return np.clip(i, 0, n - 1)


def rule_level(k, s, t, wrap_s, wrap_t):
    """The rule on one level: k (h, w, 4) uint8 bytes, s, t float32 arrays -> float32 (..., 4)."""
    h, w = k.shape[:2]
    u0 = s * F(w) - F(0.5)     # float32, as the sampler: s * w (+ offset 0), then - 1/2
    v0 = t * F(h) - F(0.5)
    fu, fv = np.floor(u0), np.floor(v0)
    a, b = u0 - fu, v0 - fv
    A = np.round(a.astype(np.float64) * 256).astype(np.int64)[..., None]   # ties to even
    B = np.round(b.astype(np.float64) * 256).astype(np.int64)[..., None]
    i0, j0 = fu.astype(np.int64), fv.astype(np.int64)
    i1, j1 = wrap(i0 + 1, w, wrap_s), wrap(j0 + 1, h, wrap_t)
    i0, j0 = wrap(i0, w, wrap_s), wrap(j0, h, wrap_t)
    kk = k.astype(np.int64)
    total = ((256 - A) * (256 - B) * kk[j0, i0] + A * (256 - B) * kk[j0, i1] +
             (256 - A) * B * kk[j1, i0] + A * B * kk[j1, i1])
    assert total.max() < 2**24
    return (total / (255.0 * 65536.0)).astype(np.float32)


def coords(scale, offset):
    y, x = np.mgrid[0:H, 0:W].astype(np.float32)
    s = (x + F(0.5)) * F(scale[0]) + F(offset[0])
    t = (y + F(0.5)) * F(scale[1]) + F(offset[1])
    return s, t


class Scene:
    def __init__(self, threads, levels, internal, fmt, wrap_s, wrap_t, min_filter):
        gl = self.gl = softgl.Context(8, 8, antialias=False, threads=threads)
        float_target(gl, W, H)
        self.prog = softgl.program(gl, VS, FS)
        gl.useProgram(self.prog)
        buf = gl.createBuffer()
        gl.bindBuffer(gl.ARRAY_BUFFER, buf)
        gl.bufferData(gl.ARRAY_BUFFER, QUAD, gl.STATIC_DRAW)
        loc = gl.getAttribLocation(self.prog, "pos")
        gl.enableVertexAttribArray(loc)
        gl.vertexAttribPointer(loc, 2, gl.FLOAT, False, 0, 0)
        tex = gl.createTexture()
        gl.bindTexture(gl.TEXTURE_2D, tex)
        gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1)
        for level, data in enumerate(levels):
            gl.texImage2D(gl.TEXTURE_2D, level, getattr(gl, internal), data.shape[1], data.shape[0], 0,
                          getattr(gl, fmt), gl.UNSIGNED_BYTE, np.ascontiguousarray(data))
        gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAX_LEVEL, len(levels) - 1)
        gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, getattr(gl, min_filter))
        gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.LINEAR)
        gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, getattr(gl, wrap_s))
        gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, getattr(gl, wrap_t))
        assert gl.getError() == gl.NO_ERROR

    def draw(self, path, scale, offset, lod=None):
        gl, p = self.gl, self.prog
        _core.testing.set_tuning(gl, sampler_path=path)
        gl.stats(reset=True)
        gl.uniform2f(gl.getUniformLocation(p, "scale"), *scale)
        gl.uniform2f(gl.getUniformLocation(p, "offset"), *offset)
        gl.uniform1f(gl.getUniformLocation(p, "lod"), 0.0 if lod is None else lod)
        gl.uniform1i(gl.getUniformLocation(p, "explicit_lod"), int(lod is not None))
        gl.drawArrays(gl.TRIANGLES, 0, 6)
        assert gl.getError() == gl.NO_ERROR
        assert (gl.stats()["texture_queries_fast"] > 0) == (path != "general"), path
        return gl.readPixels(0, 0, W, H, gl.RGBA, gl.FLOAT)


def expand(k8, fmt):
    """The bytes a texel of `fmt` samples as (ES 3.0 table 3.24: missing G, B are 0, A is 1)."""
    if fmt == "RGBA":
        return k8
    out = np.zeros(k8.shape[:2] + (4,), np.uint8)
    out[..., 0] = k8[..., 0]
    out[..., 3] = 255
    return out


RNG = np.random.default_rng(1807)
CASES = [   # (internal, format, channels, (w, h), wrap_s, wrap_t)
    ("RGBA8", "RGBA", 4, (64, 32), "REPEAT", "REPEAT"),
    ("RGBA8", "RGBA", 4, (37, 23), "CLAMP_TO_EDGE", "MIRRORED_REPEAT"),
    ("R8", "RED", 1, (29, 30), "MIRRORED_REPEAT", "REPEAT"),
]


# A texture's byte copy is made at the second draw that binds it unchanged (Texture::refresh_rgba8).
DRAWS = ("first draw (float storage)", "second draw (byte copy)", "third draw")


def assert_bits(got, want, what):
    np.testing.assert_array_equal(got.view(np.uint32), want.view(np.uint32), err_msg=what)


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("case", CASES, ids=lambda c: f"{c[0]}-{c[3][0]}x{c[3][1]}-{c[4]}-{c[5]}")
def test_bilinear_is_the_fixed_point_rule(case, threads):
    internal, fmt, ch, (w, h), wrap_s, wrap_t = case
    k8 = RNG.integers(0, 256, (h, w, ch), dtype=np.uint8)
    # Magnified (0.53 and 0.71 texels per pixel), starting left of and below the texture.
    scale, offset = (0.53 / w, 0.71 / h), (-0.377, -0.61)
    s, t = coords(scale, offset)
    want = rule_level(expand(k8, fmt), s, t, wrap_s, wrap_t)
    for path in PATHS:
        scene = Scene(threads, [k8], internal, fmt, wrap_s, wrap_t, "LINEAR")
        for draw in DRAWS:
            assert_bits(scene.draw(path, scale, offset), want, f"{draw}, path {path}")


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("lod", [0.375, 1.8125])
def test_trilinear_is_the_rule_blended_in_float32(threads, lod):
    n = 32
    levels = [RNG.integers(0, 256, (n >> k, n >> k, 4), dtype=np.uint8) for k in range(6)]
    scale, offset = (1.37 / n, 1.21 / n), (0.113, -0.29)
    s, t = coords(scale, offset)
    d = int(np.floor(lod))
    lo = rule_level(levels[d], s, t, "REPEAT", "REPEAT")
    hi = rule_level(levels[d + 1], s, t, "REPEAT", "REPEAT")
    f = F(lod) - np.floor(F(lod))
    want = (F(1) - f) * lo + f * hi   # float32, as ES 3.0 §3.8.11.2 blends (no FMA)
    for path in PATHS:
        scene = Scene(threads, levels, "RGBA8", "RGBA", "REPEAT", "REPEAT", "LINEAR_MIPMAP_LINEAR")
        for draw in DRAWS:
            assert_bits(scene.draw(path, scale, offset, lod), want, f"{draw}, path {path}")


def test_texels_scale_back_to_their_bytes():
    """The rule reads float storage as k = 255 v: exact for every v = k / 255 in float32."""
    k = np.arange(256, dtype=np.float32)
    np.testing.assert_array_equal((k / F(255)) * F(255), k)
