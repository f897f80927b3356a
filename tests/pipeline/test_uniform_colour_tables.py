"""Blended draws whose shader gives one colour to every fragment of a batch (a lit box's face)
take blend tables that the AVX-512 colour kernel keeps per thread for the last few colours
(pipeline/fragment_ops.cpp, UniformColorTables; docs/architecture.md, "Fast paths", colour
kernels). The tables outlive draws and contexts, so state that changes between draws must not
reach a table made before it: each draw here is checked against the reference blend
(`_core.testing.blend_unorm8`, the scalar per-pixel definition) of its colour over the pixels
read back before it, while the colour mask changes and colours come in turns.
"""
import numpy as np
import pytest

import softgl
from softgl import _core
from test_uniform_only_shading import PER_FRAGMENT_FS

VS = """#version 300 es
in vec4 aPos;
void main() { gl_Position = aPos; }
"""
W, H = 37, 21   # odd sizes: partial quads at the right and top edges
FUNCS = {"alpha_over": ("SRC_ALPHA", "ONE_MINUS_SRC_ALPHA"), "additive": ("ONE", "ONE")}


def context(threads, funcs):
    gl = softgl.Context(W, H, threads=threads, antialias=False, preserveDrawingBuffer=True)
    prog = softgl.program(gl, VS, PER_FRAGMENT_FS)   # shaded per fragment: the lane kernels run
    gl.useProgram(prog)
    gl.bindVertexArray(gl.createVertexArray())
    gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
    gl.bufferData(gl.ARRAY_BUFFER, np.array([[-1, -1], [1, -1], [1, 1], [-1, -1], [1, 1], [-1, 1]], np.float32),
                  gl.STATIC_DRAW)
    gl.enableVertexAttribArray(0)
    gl.vertexAttribPointer(0, 2, gl.FLOAT, False, 0, 0)
    # A background of many byte values (scissored clears).
    rng = np.random.default_rng(3)
    gl.enable(gl.SCISSOR_TEST)
    for y in range(0, H, 3):
        for x in range(0, W, 4):
            gl.scissor(x, y, 4, 3)
            gl.clearColor(*(float(v) for v in rng.integers(0, 256, 4) / 255))
            gl.clear(gl.COLOR_BUFFER_BIT)
    gl.disable(gl.SCISSOR_TEST)
    gl.enable(gl.BLEND)
    gl.blendFunc(getattr(gl, funcs[0]), getattr(gl, funcs[1]))
    return gl, gl.getUniformLocation(prog, "uColor")


def draw_and_check(gl, loc, funcs, colour, mask):
    before = gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE).reshape(-1, 4)
    gl.colorMask(*mask)
    gl.uniform4f(loc, *(float(c) for c in colour))
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    got = gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE).reshape(-1, 4)
    fe = [getattr(softgl, f) for f in (*funcs, *funcs)] + [softgl.FUNC_ADD, softgl.FUNC_ADD]
    src = np.repeat(np.asarray(colour, np.float32)[None], W * H, axis=0)
    want = _core.testing.blend_unorm8(fe, (0.0, 0.0, 0.0, 0.0), mask, True, src, before)
    np.testing.assert_array_equal(got, want, err_msg=f"colour {colour} mask {mask}")


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("name", sorted(FUNCS))
def test_a_colour_mask_change_between_draws_reaches_every_channel(name, threads):
    # The same colour drawn with green masked out (often enough that a table is made then), then
    # with every channel written: green must blend.
    gl, loc = context(threads, FUNCS[name])
    colour = (0.3, 0.6, 0.9, 0.5)
    some, every = (True, False, True, False), (True, True, True, True)
    for mask in [some, some, some, every, every, some, every]:
        draw_and_check(gl, loc, FUNCS[name], colour, mask)


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("name", sorted(FUNCS))
def test_colours_in_turns_between_draws(name, threads):
    # More colours than tables kept, in turns and repeated; one differs from another in alpha
    # only, one in green only, by one ulp.
    gl, loc = context(threads, FUNCS[name])
    rng = np.random.default_rng(11)
    palette = rng.uniform(0.05, 0.95, (6, 4)).astype(np.float32)
    palette[5] = palette[4]
    palette[5][3] = 1 - palette[4][3]
    palette[3] = palette[2]
    palette[3][1] = np.nextafter(palette[2][1], np.float32(0))
    order = [0, 1, 0, 1, 2, 0, 3, 4, 5, 4, 5, 1, 2, 3, 0, 5, 5, 4]
    for k in order:
        draw_and_check(gl, loc, FUNCS[name], tuple(palette[k]), (True,) * 4)
