"""Depth-only draws test the 8x8 blocks a primitive covers whole in place, without quads (draw plan
`depth_blocks`: docs/architecture.md, "Fast paths"; pipeline/whole_rect.h depth_covered_part;
`blocks_depth_in_place` counts the blocks), and the rest of the primitive as the rasterizer's
quads. The depth words and the counters must be those of the switch off (Tuning::depth_blocks):
random large and small triangles, all 8 depth functions, depth mask on and off, polygon offset,
scissor, partial clears, odd sizes, every SIMD level, 1 and 2 threads, in a framebuffer with only
a depth attachment and on the canvas with colour masked off. Not taken with the stencil test, a
shader that may discard or writes gl_FragDepth, or multisampling."""
import numpy as np
import pytest

import softgl
from softgl import _core
from test_depth_bounds import LEVELS, SIMD, draw_calls, scene

VS = """#version 300 es
in vec4 aPos;
void main() { gl_Position = aPos; }
"""
DEPTH_FS = """#version 300 es
precision mediump float;
void main() {}
"""
COLOR_FS = """#version 300 es
precision mediump float;
out vec4 fragColor;
void main() { fragColor = vec4(0.5); }
"""
DISCARD_FS = """#version 300 es
precision highp float;
void main() { if (gl_FragCoord.x < 20.0) discard; }
"""
FRAG_DEPTH_FS = """#version 300 es
precision highp float;
void main() { gl_FragDepth = gl_FragCoord.z; }
"""
# Counters that must agree with the switch off (timings, and the in-place blocks themselves, aside).
IGNORED = ("seconds_vertex", "seconds_setup", "seconds_fragment", "blocks_depth_in_place")


def render(on, level, seed, size, threads, target="fbo", fs=DEPTH_FS, stencil=False, antialias=False):
    """The scene's draws as depth-only draws; returns (depth words, counters, plans of the draws)."""
    pos, _, draws = scene(seed)
    gl = softgl.Context(*size, threads=threads, antialias=antialias, stencil=stencil, preserveDrawingBuffer=True)
    _core.testing.set_tuning(gl, depth_blocks=on, **({"simd": SIMD[level]} if level >= 0 else {}))
    gl.useProgram(softgl.program(gl, VS, fs, {"aPos": 0}))
    gl.bindVertexArray(gl.createVertexArray())
    gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
    gl.bufferData(gl.ARRAY_BUFFER, pos, gl.STATIC_DRAW)
    gl.enableVertexAttribArray(0)
    gl.vertexAttribPointer(0, 4, gl.FLOAT, False, 0, 0)
    fb = None
    if target == "fbo":   # a shadow map's pass: a depth attachment only
        depth = gl.createTexture()
        gl.bindTexture(gl.TEXTURE_2D, depth)
        gl.texStorage2D(gl.TEXTURE_2D, 1, gl.DEPTH24_STENCIL8, *size)
        fb = gl.createFramebuffer()
        gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
        gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.DEPTH_STENCIL_ATTACHMENT, gl.TEXTURE_2D, depth, 0)
        assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == gl.FRAMEBUFFER_COMPLETE
    elif target == "mask":
        gl.colorMask(False, False, False, False)
    gl.clearDepth(0.5 if seed % 2 else 1.0)
    gl.clearStencil(0)
    gl.clear(gl.DEPTH_BUFFER_BIT | gl.STENCIL_BUFFER_BIT | gl.COLOR_BUFFER_BIT)
    gl.enable(gl.DEPTH_TEST)
    if stencil:
        gl.enable(gl.STENCIL_TEST)
        gl.stencilFunc(gl.ALWAYS, 1, 0xFF)
        gl.stencilOp(gl.KEEP, gl.INCR, gl.INCR)
    gl.stats(reset=True)
    plans = []   # of the draws that rasterize (not those with nothing to write: depth mask off)

    def keep_plan():
        plan = gl.last_draw_plan()
        if plan["skip"] == "no":
            plans.append(plan)

    draw_calls(gl, draws, size, keep_plan)
    assert gl.getError() == gl.NO_ERROR and plans
    stats = gl.stats()
    gl.disable(gl.SCISSOR_TEST)
    if fb is not None:   # the attachment's words, blitted to the canvas to read them
        gl.bindFramebuffer(gl.READ_FRAMEBUFFER, fb)
        gl.bindFramebuffer(gl.DRAW_FRAMEBUFFER, None)
        gl.blitFramebuffer(0, 0, *size, 0, 0, *size, gl.DEPTH_BUFFER_BIT, gl.NEAREST)
        assert gl.getError() == gl.NO_ERROR
    words = _core.testing.read_depth(gl).tobytes()
    stencil_bytes = _core.testing.read_stencil(gl).tobytes() if stencil else b""
    return words + stencil_bytes, stats, plans


def same_counters(on, off, where):
    for key, value in off.items():
        if key not in IGNORED:
            assert on[key] == value, f"{key}: {on[key]} with blocks in place, {value} without; {where}"


@pytest.mark.parametrize("target", ["fbo", "mask"])
@pytest.mark.parametrize("size", [(133, 97), (64, 64), (200, 71)])
def test_same_words_and_counters_as_quads(size, target):
    in_place = 0
    for seed in range(4):
        off, off_stats, off_plans = render(False, -1, seed, size, 1, target)
        assert off_stats["blocks_depth_in_place"] == 0
        assert all(p["depth_blocks_why_not"] == "tuning_off" for p in off_plans)
        for threads in (1, 2):
            for level in LEVELS:
                on, on_stats, on_plans = render(True, level, seed, size, threads, target)
                where = f"seed {seed}, threads {threads}, simd level {level}"
                assert all(p["depth_only"] and p["depth_blocks"] for p in on_plans), where
                assert on == off, f"depth differs, {where}"
                same_counters(on_stats, off_stats, where)
                in_place += on_stats["blocks_depth_in_place"]
        # The scene has tests that fail and words that change (the comparison can fail).
        assert off_stats["fragments_killed_early"] > 0 and off_stats["quads"] > 0
    assert in_place > 100, "the scenes never cover whole blocks"


def test_same_words_as_draws_that_write_colour():
    # The depth a draw that shades and writes colour leaves (no depth-only path at all).
    for seed in range(3):
        shaded, stats, plans = render(True, -1, seed, (133, 97), 2, target="canvas", fs=COLOR_FS)
        assert not any(p["depth_only"] or p["depth_blocks"] for p in plans) and stats["fragments_shaded"] > 0
        blocks, stats, _ = render(True, -1, seed, (133, 97), 2, target="mask")
        assert stats["blocks_depth_in_place"] > 0
        assert blocks == shaded, f"seed {seed}"


@pytest.mark.parametrize("target", ["fbo", "mask"])
def test_not_taken_with_the_stencil_test(target):
    # Stencil operations run per sample (the quad early depth test has none): no blocks in place,
    # and the depth and stencil bytes of the switch off.
    off, off_stats, _ = render(False, -1, 1, (133, 97), 2, target, stencil=True)
    on, on_stats, plans = render(True, -1, 1, (133, 97), 2, target, stencil=True)
    assert all(p["depth_only"] and not p["depth_blocks"] and p["depth_blocks_why_not"] == "stencil_test"
               for p in plans)
    assert on_stats["blocks_depth_in_place"] == 0 and on == off
    same_counters(on_stats, off_stats, "stencil")


@pytest.mark.parametrize("fs, reason", [(DISCARD_FS, "discard"), (FRAG_DEPTH_FS, "frag_depth")])
def test_not_taken_when_the_shader_decides(fs, reason):
    off, _, _ = render(False, -1, 2, (133, 97), 1, "fbo", fs=fs)
    on, stats, plans = render(True, -1, 2, (133, 97), 1, "fbo", fs=fs)
    assert all(not p["depth_blocks"] and p["depth_blocks_why_not"] == reason for p in plans)
    assert stats["blocks_depth_in_place"] == 0 and stats["fragments_shaded"] > 0 and on == off


def test_not_taken_when_multisampled():
    off, _, _ = render(False, -1, 3, (133, 97), 1, "mask", antialias=True)
    on, stats, plans = render(True, -1, 3, (133, 97), 2, "mask", antialias=True)
    assert all(p["depth_only"] and p["depth_blocks_why_not"] == "multisampled" for p in plans)
    assert stats["blocks_depth_in_place"] == 0 and on == off
