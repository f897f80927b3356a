"""Texel words for LINEAR (docs/architecture.md, "Fast paths": texel words; Tuning::linear_words).

A texture copy (the shader is one lookup copied to its colour) of a LINEAR lookup of one 8-bit
unorm level (no mipmaps), written plainly, gives each pixel the bytes the colour kernels would make
of the fixed-point rule's value (README "Choices": v = float32(S / (255 * 65536)) of the integer
sum S, written as floor(v * 255 + 1/2)), computed from S in integers: (S + 32768 - (S >> 23)) >> 16.

References: the rule itself in float64 / float32 NumPy for every possible S (the formula), a tie
texture whose 1:1 half-texel lookups hit every tie S = 65536 k + 32768 (the bytes), and the same
draws with linear_words off (the sampler's floats through the colour kernels) at every SIMD level
this CPU has, 1 and 2 threads, every wrap mode, power-of-two and other sizes, 8-bit formats."""
import numpy as np
import pytest

import softgl
from softgl import _core

T = _core.testing
LEVELS = ["scalar", "sse2", "avx2", "avx512"][:T.simd_level() + 1]

VS = """#version 300 es
in vec4 pos;
in vec2 uv;
out vec2 vUV;
void main() { vUV = uv; gl_Position = pos; }
"""
FS = """#version 300 es
precision mediump float;
uniform sampler2D uTex;
in vec2 vUV;
out vec4 fragColor;
void main() { fragColor = texture(uTex, vUV); }
"""
W, H = 61, 47   # odd sizes: partial quads and tiles at the edges

# internal format, format, channels
FORMATS = {"RGBA8": ("RGBA8", "RGBA", 4), "RGB8": ("RGB8", "RGB", 3), "RG8": ("RG8", "RG", 2),
           "R8": ("R8", "RED", 1), "LUMINANCE": ("LUMINANCE", "LUMINANCE", 1),
           "LUMINANCE_ALPHA": ("LUMINANCE_ALPHA", "LUMINANCE_ALPHA", 2), "ALPHA": ("ALPHA", "ALPHA", 1)}

# Two triangles, one at a slant with a perspective w; uv runs past [0, 1] (wrapping) and
# magnifies and minifies.
POSITIONS = np.array([
    [-0.9, -0.95, 0.0, 1.0], [0.95, -0.8, 0.0, 1.0], [-0.85, 0.9, 0.0, 1.0],
    [0.3 * 2.0, -0.7 * 2.0, 0.0, 2.0], [0.9 * 0.7, 0.95 * 0.7, 0.0, 0.7], [-0.6 * 1.4, 0.85 * 1.4, 0.0, 1.4],
], np.float32)
UVS = np.array([[-0.3, -0.2], [1.7, -0.1], [-0.2, 1.4], [1.1, -0.6], [3.9, 2.8], [-0.4, 1.2]], np.float32)


def plain_write_byte(S):
    """The documented rule: v = float32(S / (255 * 65536)) (correctly rounded), then the colour
    kernels' floor(clamp(v) * 255 + 1/2) (ES 3.0 §2.1.6.1), in float64 where that is exact."""
    v = (np.asarray(S, np.float64) / (255.0 * 65536.0)).astype(np.float32).astype(np.float64)
    return np.floor(np.clip(v, 0.0, 1.0) * 255.0 + 0.5).astype(np.int64)


def test_integer_formula_matches_the_rule_for_every_sum():
    S = np.arange(0, 255 * 65536 + 1, dtype=np.int64)
    want = plain_write_byte(S)
    got = (S + 32768 - (S >> 23)) >> 16
    bad = np.flatnonzero(got != want)
    assert bad.size == 0, f"{bad.size} sums differ, first S = {S[bad[0]]}: {got[bad[0]]} vs {want[bad[0]]}"
    # The ties are where it matters: half of them round each way.
    ties = S[(S & 0xFFFF) == 0x8000]
    assert ((want[ties] - (ties >> 16)) == 1).sum() == 128 and ((want[ties] - (ties >> 16)) == 0).sum() == 127


def render(data, internal, fmt, *, positions=POSITIONS, uvs=UVS, size=(W, H), filters=("LINEAR", "LINEAR"),
           wrap="REPEAT", simd=None, threads=1, linear_words=True, words=True):
    gl = softgl.Context(*size, antialias=False, threads=threads)
    fields = dict(linear_words=linear_words, texel_words=words)
    if simd:
        fields["simd"] = simd
    T.set_tuning(gl, **fields)
    prog = softgl.program(gl, VS, FS)
    gl.useProgram(prog)
    for name, arr in (("pos", positions), ("uv", uvs)):
        loc = gl.getAttribLocation(prog, name)
        gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
        gl.bufferData(gl.ARRAY_BUFFER, arr, gl.STATIC_DRAW)
        gl.enableVertexAttribArray(loc)
        gl.vertexAttribPointer(loc, arr.shape[1], gl.FLOAT, False, 0, 0)
    gl.bindTexture(gl.TEXTURE_2D, gl.createTexture())
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1)
    h, w = data.shape[:2]
    gl.texImage2D(gl.TEXTURE_2D, 0, getattr(gl, internal), w, h, 0, getattr(gl, fmt), gl.UNSIGNED_BYTE, data)
    if "MIPMAP" in filters[0]:
        gl.generateMipmap(gl.TEXTURE_2D)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, getattr(gl, filters[0]))
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, getattr(gl, filters[1]))
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, getattr(gl, wrap))
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, getattr(gl, wrap))
    gl.uniform1i(gl.getUniformLocation(prog, "uTex"), 0)
    gl.clearColor(0.2, 0.4, 0.6, 0.8)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.stats(reset=True)
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    stats = gl.stats()
    return gl.readPixels(0, 0, *size, gl.RGBA, gl.UNSIGNED_BYTE), stats, gl.last_draw_plan()


def assert_bytes_equal(got, want, what):
    bad = np.argwhere((got != want).any(axis=-1))
    assert bad.size == 0, f"{what}: {len(bad)} pixels differ, first at {bad[0]}: {got[tuple(bad[0])]} vs {want[tuple(bad[0])]}"


@pytest.mark.parametrize("simd", LEVELS)
@pytest.mark.parametrize("wrap", ["REPEAT", "CLAMP_TO_EDGE"])
def test_every_tie_gives_the_rules_byte(simd, wrap):
    """A 256x4 texture whose horizontal neighbours sum to every odd number 1 .. 509 (and 255 +
    0 where REPEAT wraps), read 1:1 half a texel to the right: A = 128 and B = 0 (the rows are
    equal, so B = 256 would read the same), S = 32768 (k0 + k1), a tie wherever k0 + k1 is odd."""
    k = np.arange(256)
    rows = np.stack([k, 255 - k, (k * 7) % 256, np.minimum(k, 255 - k) * 2 + (k & 1)], -1).astype(np.uint8)
    tex = np.repeat(rows[None], 4, axis=0)
    quad = np.array([[-1, -1, 0, 1], [1, -1, 0, 1], [-1, 1, 0, 1], [-1, 1, 0, 1], [1, -1, 0, 1], [1, 1, 0, 1]], np.float32)
    uv = ((quad[:, :2] + 1) / 2 + np.array([0.5 / 256, 0.0])).astype(np.float32)
    got, stats, _ = render(tex, "RGBA8", "RGBA", positions=quad, uvs=uv, size=(256, 4), wrap=wrap, simd=simd)
    assert stats["draws_texel_words"] == 1
    right = np.roll(tex, -1, axis=1) if wrap == "REPEAT" else np.concatenate([tex[:, 1:], tex[:, -1:]], axis=1)
    want = plain_write_byte(32768 * (tex.astype(np.int64) + right)).astype(np.uint8)
    assert_bytes_equal(got, want, f"ties, {wrap} at {simd}")
    assert ((tex.astype(int) + right) % 2 == 1).sum() > 900   # ties indeed
    off, stats, _ = render(tex, "RGBA8", "RGBA", positions=quad, uvs=uv, size=(256, 4), wrap=wrap, simd=simd,
                           linear_words=False)
    assert stats["draws_texel_words"] == 0
    assert_bytes_equal(off, want, f"ties, {wrap} at {simd}, floats")


@pytest.mark.parametrize("simd", LEVELS)
@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("wrap", ["REPEAT", "CLAMP_TO_EDGE", "MIRRORED_REPEAT"])
@pytest.mark.parametrize("size", [(16, 8), (13, 7)])   # powers of two, and not
@pytest.mark.parametrize("name", list(FORMATS))
def test_same_bytes_as_the_float_path(simd, threads, wrap, size, name):
    internal, fmt, channels = FORMATS[name]
    rng = np.random.default_rng(hash((wrap, size, name)) % 2**32)
    data = rng.integers(0, 256, (size[1], size[0], channels)).astype(np.uint8)
    data[0, 0] = 255   # extremes: S = 0 and S = 255 * 65536 somewhere
    data[-1, -1] = 0
    kw = dict(wrap=wrap, simd=simd, threads=threads)
    got, stats, plan = render(data, internal, fmt, **kw)
    assert stats["draws_texel_words"] == 1 and plan["texel_words"], plan
    want, stats, plan = render(data, internal, fmt, **kw, linear_words=False)
    assert stats["draws_texture_copy"] == 1 and stats["draws_texel_words"] == 0
    assert not plan["texel_words"]
    assert_bytes_equal(got, want, f"{name} {wrap} {size} at {simd}, {threads} thread(s)")
    # The draw reads between texels (the words are not NEAREST's).
    nearest = render(data, internal, fmt, **kw, filters=("NEAREST", "NEAREST"))[0]
    assert (nearest != got).any()


@pytest.mark.parametrize("filters, words", [(("LINEAR", "NEAREST"), 0), (("NEAREST", "LINEAR"), 0),
                                            (("LINEAR_MIPMAP_LINEAR", "LINEAR"), 0), (("LINEAR", "LINEAR"), 1)])
def test_only_one_linear_level_takes_it(filters, words):
    """Filters that differ between magnification and minification (the LOD chooses) or mipmaps
    keep the floats; all give the executor's bytes."""
    data = np.random.default_rng(5).integers(0, 256, (8, 16, 4)).astype(np.uint8)
    got, stats, _ = render(data, "RGBA8", "RGBA", filters=filters)
    assert stats["draws_texel_words"] == words
    want, stats, _ = render(data, "RGBA8", "RGBA", filters=filters, linear_words=False, words=False)
    assert stats["draws_texel_words"] == 0
    assert_bytes_equal(got, want, str(filters))
