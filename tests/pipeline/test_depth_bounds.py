"""Depth bounds (pipeline/early_depth DepthBounds): a primitive whose every fragment in a tile
fails the early depth test, judged from the tile's stored depth words, is neither rasterized nor
tested there. It must not change a byte: random depth-tested draws (all 8 depth functions, depth
mask on and off, clears in between, scissor, polygon offset, odd sizes, 1 and 2 threads, every
SIMD level, which picks the block reads' kernel) are compared, colour and depth words, with the
same draws with the bounds off (mode 0); a sabotaged bound (mode 2) must make that comparison fail.
The modes and levels are the context's tuning (depth_bounds 'off', 'on', 'sabotaged_for_tests';
simd)."""
import numpy as np
import pytest

import softgl
from softgl import _core

VS = """#version 300 es
in vec4 aPos;
in vec4 aColor;
out vec4 vColor;
void main() { gl_Position = aPos; vColor = aColor; }
"""
FS = """#version 300 es
precision highp float;
in vec4 vColor;
out vec4 fragColor;
void main() { fragColor = vColor; }
"""
FUNCS = ("NEVER", "LESS", "EQUAL", "LEQUAL", "GREATER", "NOTEQUAL", "GEQUAL", "ALWAYS")
LEVELS = range(_core.testing.simd_level() + 1)
SIMD = ("scalar", "sse2", "avx2", "avx512")   # the tuning's names of LEVELS
MODES = ("off", "on", "sabotaged_for_tests")   # depth bounds modes 0, 1, 2


def scene(seed, n=40):
    """Random large sloped triangles and, per draw, its state: (first, count, func, mask, offset,
    scissor, clear)."""
    rng = np.random.default_rng(seed)
    centre = rng.uniform(-0.7, 0.7, (n, 1, 2))
    xy = (centre + rng.uniform(-0.8, 0.8, (n, 3, 2))).reshape(-1, 2)
    z = np.repeat(rng.uniform(-0.9, 0.9, n), 3) + rng.uniform(-0.3, 0.3, 3 * n)
    pos = np.column_stack([xy, z, np.ones(3 * n)]).astype(np.float32)
    color = rng.uniform(0, 1, (3 * n, 4)).astype(np.float32)
    draws, first = [], 0
    while first < n:
        count = int(rng.integers(3, 15))
        draws.append(dict(first=3 * first, count=3 * min(count, n - first),
                          func=FUNCS[int(rng.integers(8))] if rng.random() < 0.5 else str(rng.choice(["LESS", "LEQUAL", "GREATER", "GEQUAL"])),
                          mask=bool(rng.random() < 0.75), offset=bool(rng.random() < 0.3),
                          scissor=tuple(int(v) for v in rng.integers(0, 60, 4)) if rng.random() < 0.3 else None,
                          clear=float(rng.uniform(0, 1)) if rng.random() < 0.3 else None))
        first += count
    return pos, color, draws


def bind_scene(gl, pos, color):
    """The colour program and the (n, 4) position and colour arrays as its attributes."""
    gl.useProgram(softgl.program(gl, VS, FS, {"aPos": 0, "aColor": 1}))
    gl.bindVertexArray(gl.createVertexArray())
    for loc, data in ((0, pos), (1, color)):
        gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
        gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW)
        gl.enableVertexAttribArray(loc)
        gl.vertexAttribPointer(loc, 4, gl.FLOAT, False, 0, 0)


def draw_calls(gl, draws, size, after=None):
    """The scene's draws, each with its depth function, mask, polygon offset, scissor and partial
    depth clear; after() runs after each draw."""
    for d in draws:
        if d["clear"] is not None:   # a partial clear of the depth words (scissored)
            gl.enable(gl.SCISSOR_TEST)
            gl.scissor(size[0] // 4, size[1] // 3, size[0] // 2, size[1] // 2)
            gl.depthMask(True)
            gl.clearDepth(d["clear"])
            gl.clear(gl.DEPTH_BUFFER_BIT)
            gl.disable(gl.SCISSOR_TEST)
        gl.depthFunc(getattr(gl, d["func"]))
        gl.depthMask(d["mask"])
        if d["offset"]:
            gl.enable(gl.POLYGON_OFFSET_FILL)
            gl.polygonOffset(2.0, 40.0)
        else:
            gl.disable(gl.POLYGON_OFFSET_FILL)
        if d["scissor"]:
            gl.enable(gl.SCISSOR_TEST)
            gl.scissor(*d["scissor"])
        else:
            gl.disable(gl.SCISSOR_TEST)
        gl.drawArrays(gl.TRIANGLES, d["first"], d["count"])
        if after is not None:
            after()


def render(mode, level, seed, size, threads, antialias=False, smooth=False):
    """The scene's draws; returns (colour bytes, depth words, counters)."""
    pos, color, draws = scene(seed)
    gl = softgl.Context(*size, threads=threads, antialias=antialias, preserveDrawingBuffer=True)
    _core.testing.set_tuning(gl, depth_bounds=MODES[mode], **({"simd": SIMD[level]} if level >= 0 else {}))
    bind_scene(gl, pos, color)
    gl.clearColor(0.2, 0.4, 0.6, 1.0)
    gl.clearDepth(0.5 if seed % 2 else 1.0)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    gl.enable(gl.DEPTH_TEST)
    if smooth:
        gl.enable(gl.getExtension("SOFTGL_smooth").POLYGON_SMOOTH)
    gl.stats(reset=True)
    draw_calls(gl, draws, size)
    assert gl.getError() == gl.NO_ERROR
    stats = {k: v for k, v in gl.stats().items() if not k.startswith("seconds")}
    image = gl.readPixels(0, 0, *size, gl.RGBA, gl.UNSIGNED_BYTE).tobytes()
    return image, _core.testing.read_depth(gl).tobytes(), stats


@pytest.mark.parametrize("size", [(133, 97), (64, 64), (200, 71)])
def test_same_bytes_with_and_without_bounds(size):
    hidden = 0
    for seed in range(6):
        off = render(0, -1, seed, size, 1)
        assert off[2]["primitives_depth_hidden"] == 0
        for threads in (1, 2):
            for level in LEVELS:
                on = render(1, level, seed, size, threads)
                where = f"seed {seed}, threads {threads}, simd level {level}"
                assert on[0] == off[0], f"colour differs, {where}"
                assert on[1] == off[1], f"depth differs, {where}"
                # Skipped primitives have no surviving fragment: the same shading and writes,
                # fewer tests.
                for key in ("quads", "fragments_shaded", "samples_written", "fragments_hidden"):
                    assert on[2][key] == off[2][key], f"{key}, {where}"
                assert on[2]["fragments_killed_early"] <= off[2]["fragments_killed_early"]
        hidden += on[2]["primitives_depth_hidden"]
    assert hidden > 0, "the scenes never exercise the bounds"


def test_sabotaged_bounds_are_caught():
    caught = 0
    for seed in range(6):
        off = render(0, -1, seed, (133, 97), 1)
        bad = render(2, -1, seed, (133, 97), 1)
        caught += bad[0] != off[0] or bad[1] != off[1]
    assert caught >= 3


@pytest.mark.parametrize("kw", [dict(antialias=True), dict(smooth=True)])
def test_off_for_multisampling_and_area_coverage(kw):
    off = render(0, -1, 1, (133, 97), 1, **kw)
    on = render(1, -1, 1, (133, 97), 2, **kw)
    assert on[0] == off[0] and on[1] == off[1]
    assert on[2]["primitives_depth_hidden"] == 0


def test_the_large_triangle_scene_skips_most_hidden_primitives():
    """100 large constant-depth triangles (benchmarks' large_triangles): most (primitive, tile)
    pairs behind the stored depth are skipped, with the same bytes."""
    rng = np.random.default_rng(2)
    n = 100
    centre = rng.uniform(-0.4, 0.4, (n, 1, 2))
    ang = rng.uniform(0, 2 * np.pi, (n, 1)) + np.array([0, 2.1, 4.2])[None, :]
    rad = rng.uniform(0.9, 1.3, (n, 3))
    xy = (centre + np.stack([np.cos(ang) * rad, np.sin(ang) * rad], axis=2)).reshape(-1, 2)
    z = np.repeat(rng.uniform(-0.9, 0.9, n), 3)
    pos = np.column_stack([xy, z, np.ones(3 * n)]).astype(np.float32)
    color = rng.uniform(0, 1, (3 * n, 4)).astype(np.float32)
    out = {}
    for mode in (0, 1):
        gl = softgl.Context(256, 256, antialias=False)
        _core.testing.set_tuning(gl, depth_bounds=MODES[mode])
        bind_scene(gl, pos, color)
        gl.enable(gl.DEPTH_TEST)
        gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
        gl.stats(reset=True)
        gl.drawArrays(gl.TRIANGLES, 0, 3 * n)
        assert gl.last_draw_plan()["depth_bounds"] == (mode == 1)
        out[mode] = (gl.readPixels(0, 0, 256, 256, gl.RGBA, gl.UNSIGNED_BYTE).tobytes(),
                     _core.testing.read_depth(gl).tobytes(), gl.stats())
    assert out[1][0] == out[0][0] and out[1][1] == out[0][1]
    assert out[1][2]["primitives_depth_hidden"] > 100
    assert out[1][2]["fragments_killed_early"] < out[0][2]["fragments_killed_early"] // 2
