"""The colour kernels blend single-sampled RGBA8 quads that read the destination straight in the
buffer at AVX2 and AVX-512 (Tuning::blend_in_place, fragment_ops.h write_color_quads_at;
`quads_blended_in_place` counts them), instead of gathering the pixels into lanes and back. The
pixels and the other counters must be those of the switch off at the scalar level: small and
large textured, tinted quads (alpha falling to 0, colours out of [0, 1]), over-, additive and
colour-masked writes, with and without destination alpha, quads past the canvas's odd edges,
batches of whole quads (helper lanes kept: one primitive's uncovered pixel of a quad and
another's covered one in the same batch) and of single pixels, flat colours under a depth test,
every SIMD level, 1 and 2 threads."""
import numpy as np
import pytest

import softgl
from softgl import _core

LEVELS = range(_core.testing.simd_level() + 1)
SIMD = ("scalar", "sse2", "avx2", "avx512")

VS = """#version 300 es
in vec3 aPos;
in vec2 aUV;
in vec4 aColor;
out vec2 vUV;
out vec4 vColor;
void main() { vUV = aUV; vColor = aColor; gl_Position = vec4(aPos, 1.0); }
"""
TEXTURED_FS = """#version 300 es
precision mediump float;
uniform sampler2D uTex;
in vec2 vUV;
in vec4 vColor;
out vec4 fragColor;
void main() { fragColor = texture(uTex, vUV) * vColor * 1.3 - 0.1; }
"""
FLAT_FS = """#version 300 es
precision mediump float;
in vec4 vColor;
out vec4 fragColor;
void main() { fragColor = vColor * 0.9 + 0.05; }
"""
# Counters that must agree with the switch off (timings and the in-place count aside).
IGNORED = ("seconds_vertex", "seconds_setup", "seconds_fragment", "quads_blended_in_place")
BLENDS = {
    "over": ("SRC_ALPHA", "ONE_MINUS_SRC_ALPHA", (True,) * 4),
    "additive": ("ONE", "ONE", (True,) * 4),
    "masked_over": ("SRC_ALPHA", "ONE_MINUS_SRC_ALPHA", (True, False, True, False)),
    "masked_plain": ("ONE", "ZERO", (False, True, True, True)),
}


def scene(seed, flat):
    """Quads of 1-48 px and a few large ones (their own batches), as two triangles each."""
    r = np.random.default_rng(seed)
    n = 300
    centre = r.uniform(-1.1, 1.1, (n, 1, 2))
    half = r.uniform(0.5, 24, (n, 1, 1)) / 60
    half[:6] *= 8
    if flat:   # chunks too big to be gathered take the flat primitives' path
        half *= 3
    corner = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], np.float64)[None]
    xy = centre + corner * half * r.uniform(0.7, 1.3, (n, 4, 2))   # not quite squares
    z = np.repeat(r.uniform(-0.9, 0.9, (n, 1, 1)), 4, axis=1) if flat else r.uniform(-0.9, 0.9, (n, 4, 1))
    pos = np.concatenate([xy, z], axis=-1).reshape(-1, 3).astype(np.float32)
    uv = ((corner + 1) / 2 * np.ones((n, 1, 1))).reshape(-1, 2).astype(np.float32)
    colour = r.uniform(-0.2, 1.2, (n, 1, 4))
    colour = (np.repeat(colour, 4, axis=1) if flat else colour + r.uniform(-0.3, 0.3, (n, 4, 4)))
    quad = np.array([0, 1, 2, 0, 2, 3])
    idx = (np.arange(n)[:, None] * 4 + quad[None]).astype(np.uint32).reshape(-1)
    return pos, uv, colour.reshape(-1, 4).astype(np.float32), idx


def render(on, level, seed, size, threads, blend, alpha=True, helper_lanes=False, flat=False):
    gl = softgl.Context(*size, threads=threads, alpha=alpha, depth=True, antialias=False)
    _core.testing.set_tuning(gl, blend_in_place=on, skip_helper_lanes=not helper_lanes, simd=SIMD[level])
    prog = softgl.program(gl, VS, FLAT_FS if flat else TEXTURED_FS, {"aPos": 0, "aUV": 1, "aColor": 2})
    gl.useProgram(prog)
    gl.bindVertexArray(gl.createVertexArray())
    pos, uv, colour, idx = scene(seed, flat)
    for loc, data, comps in ((0, pos, 3), (1, uv, 2), (2, colour, 4)):
        gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
        gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW)
        gl.enableVertexAttribArray(loc)
        gl.vertexAttribPointer(loc, comps, gl.FLOAT, False, 0, 0)
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, gl.createBuffer())
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, idx, gl.STATIC_DRAW)
    # A soft disc: alpha 0 at the corners, every byte value somewhere.
    yy, xx = (np.mgrid[0:32, 0:32] + 0.5) / 16 - 1
    rad = np.sqrt(xx ** 2 + yy ** 2)
    texels = np.stack([np.cos(rad * 7) * 0.5 + 0.5, xx * 0.5 + 0.5, yy * 0.5 + 0.5, np.clip(1.1 - rad, 0, 1)], -1)
    gl.bindTexture(gl.TEXTURE_2D, gl.createTexture())
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, 32, 32, 0, gl.RGBA, gl.UNSIGNED_BYTE,
                  np.round(texels * 255).astype(np.uint8))
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.LINEAR)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.LINEAR)
    gl.clearColor(0.2, 0.5, 0.7, 0.6)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    src, dst, mask = BLENDS[blend]
    gl.enable(gl.BLEND)
    gl.blendFunc(getattr(gl, src), getattr(gl, dst))
    gl.colorMask(*mask)
    if flat:
        gl.enable(gl.DEPTH_TEST)
    gl.stats(reset=True)
    gl.drawElements(gl.TRIANGLES, len(idx), gl.UNSIGNED_INT, 0)
    gl.drawElements(gl.TRIANGLES, len(idx) // 2, gl.UNSIGNED_INT, 0)   # over the first draw's pixels
    assert gl.getError() == gl.NO_ERROR
    stats = gl.stats()
    assert gl.last_draw_plan()["color_kernels"]
    return gl.readPixels(0, 0, *size, gl.RGBA, gl.UNSIGNED_BYTE).tobytes(), stats


def same_counters(on, off, where):
    for key, value in off.items():
        if key not in IGNORED:
            assert on[key] == value, f"{key}: {on[key]} in place, {value} without; {where}"


@pytest.mark.parametrize("blend", sorted(BLENDS))
@pytest.mark.parametrize("helper_lanes", [False, True])
def test_same_pixels_and_counters_as_lanes(blend, helper_lanes):
    size = (133, 97)
    in_place = 0
    for seed in range(2):
        for alpha in (True, False):
            want, want_stats = render(False, 0, seed, size, 1, blend, alpha, helper_lanes)
            assert want_stats["quads_blended_in_place"] == 0
            for threads in (1, 2):
                for level in LEVELS:
                    for on in (False, True):
                        got, stats = render(on, level, seed, size, threads, blend, alpha, helper_lanes)
                        where = f"seed {seed}, alpha {alpha}, threads {threads}, level {level}, in place {on}"
                        assert got == want, f"pixels differ, {where}"
                        same_counters(stats, want_stats, where)
                        if not on or level < 2:
                            assert stats["quads_blended_in_place"] == 0, where
                        in_place += stats["quads_blended_in_place"]
    if max(LEVELS) >= 2:
        assert in_place > 1000, "no quad was blended in place"


def test_the_comparison_sees_the_blend():
    # The scene's blending changes pixels that a plain write would not (the comparison can fail).
    over, _ = render(True, max(LEVELS), 0, (133, 97), 1, "over")
    masked, _ = render(True, max(LEVELS), 0, (133, 97), 1, "masked_over")
    assert over != masked


@pytest.mark.parametrize("blend", ["over", "additive"])
def test_flat_colours_under_a_depth_test(blend):
    # One colour per primitive (flat primitives: a whole chunk of one colour, which the AVX-512
    # level blends by table), early depth killing some.
    want, want_stats = render(False, 0, 5, (150, 90), 1, blend, flat=True)
    assert want_stats["fragments_flat"] > 0 and want_stats["fragments_killed_early"] > 0
    for threads in (1, 2):
        for level in LEVELS:
            got, stats = render(True, level, 5, (150, 90), threads, blend, flat=True)
            assert got == want, f"threads {threads}, level {level}"
            same_counters(stats, want_stats, f"threads {threads}, level {level}")
