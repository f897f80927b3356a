"""The colour kernels on multisampled RGBA8 drawing buffers (pipeline/tile_pass.cpp `write`: the
kernel on all lanes of a chunk at once, then each lane's result into its covered samples; a kernel
that reads the destination runs once per sample index) against the lane-by-lane reference, which
writes each covered sample through RenderTarget::write_color and blend_unorm8 (surface/blend.cpp,
the definition: docs/architecture.md, "Numeric rules"). A draw takes the reference while
SOFTGL_introspection is on; introspection only records, it changes no pixel.

Random overlapping triangles with per-vertex colours out of [0, 1] (partial coverage at every
edge, clamping), depth-tested, for each kernel (Plain, AlphaOver, Additive), with and without a
colour mask, with a shaded and a uniform-only colour, at every sample count, SIMD level and 1-3
threads: every colour sample, every depth sample and the samples_written count must be equal."""
import numpy as np
import pytest

import softgl
from softgl import _core

W, H = 150, 110

VS = """#version 300 es
in vec3 pos; in vec4 col; out vec4 v_col;
void main() { v_col = col; gl_Position = vec4(pos, 1.0); }"""
FS_SHADED = """#version 300 es
precision highp float; in vec4 v_col; out vec4 o;
void main() { o = v_col * 1.25 - 0.1; }"""
FS_UNIFORM = """#version 300 es
precision highp float; uniform vec4 u_col; out vec4 o;
void main() { o = u_col; }"""

KERNELS = {
    "plain": None,
    "alpha_over": ("SRC_ALPHA", "ONE_MINUS_SRC_ALPHA"),
    "additive": ("ONE", "ONE"),
}


def draw_scene(gl, kernel, masked, uniform_only, seed):
    rng = np.random.default_rng(seed)
    prog = softgl.program(gl, VS, FS_UNIFORM if uniform_only else FS_SHADED)
    gl.useProgram(prog)
    n = 40
    pos = np.c_[rng.uniform(-1.2, 1.2, (3 * n, 2)), rng.uniform(-0.9, 0.9, 3 * n)].astype(np.float32)
    col = rng.uniform(-0.2, 1.3, (3 * n, 4)).astype(np.float32)
    for data, name, size in ((pos, "pos", 3), (col, "col", 4)):
        loc = gl.getAttribLocation(prog, name)
        if loc < 0:
            continue
        gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
        gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW)
        gl.enableVertexAttribArray(loc)
        gl.vertexAttribPointer(loc, size, gl.FLOAT, False, 0, 0)
    gl.clearColor(0.2, 0.4, 0.6, 0.8)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    gl.enable(gl.DEPTH_TEST)
    gl.depthFunc(gl.LEQUAL)
    if KERNELS[kernel]:
        gl.enable(gl.BLEND)
        gl.blendFunc(*(getattr(gl, f) for f in KERNELS[kernel]))
    if masked:
        gl.colorMask(True, False, True, True)
    u_col = gl.getUniformLocation(prog, "u_col")
    # Several draws: later ones blend over (and are depth-tested against) the earlier ones.
    for k in range(4):
        if u_col is not None:
            gl.uniform4f(u_col, *rng.uniform(-0.2, 1.3, 4))
        gl.drawArrays(gl.TRIANGLES, 10 * 3 * k, 10 * 3)


def run(samples, kernel, masked, uniform_only, threads, simd, reference):
    gl = softgl.Context(W, H, version=2, antialias=True, samples=samples, threads=threads)
    _core.testing.set_tuning(gl, simd=simd)
    if reference:
        ext = gl.getExtension("SOFTGL_introspection")
        gl.enable(ext.INTROSPECTION_SOFTGL)
    before = gl.stats()["samples_written"]
    draw_scene(gl, kernel, masked, uniform_only, seed=samples * 7 + len(kernel))
    plan = gl.last_draw_plan()
    return (_core.testing.read_color_samples(gl), _core.testing.read_depth(gl),
            gl.stats()["samples_written"] - before, plan)


@pytest.mark.parametrize("samples", [2, 4, 8, 16])
@pytest.mark.parametrize("kernel", sorted(KERNELS))
@pytest.mark.parametrize("masked", [False, True])
@pytest.mark.parametrize("uniform_only", [False, True])
def test_multisampled_colour_kernels_give_the_reference_bytes(samples, kernel, masked, uniform_only):
    ref_colour, ref_depth, ref_written, ref_plan = run(samples, kernel, masked, uniform_only, 1, "scalar", True)
    assert ref_plan["color_kernels_why_not"] == "blend_lab"
    assert ref_written > 0
    for threads in (1, 2, 3):
        for simd in ("scalar", "sse2", "avx2", "avx512"):
            colour, depth, written, plan = run(samples, kernel, masked, uniform_only, threads, simd, False)
            assert plan["color_kernels"] and plan["samples"] == samples
            np.testing.assert_array_equal(colour, ref_colour, err_msg=f"threads={threads} simd={simd}")
            np.testing.assert_array_equal(depth, ref_depth, err_msg=f"threads={threads} simd={simd}")
            assert written == ref_written
