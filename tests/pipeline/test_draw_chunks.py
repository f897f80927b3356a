"""Large draws are shaded and set up in chunks of vertices and primitives on the thread pool
(pipeline/draw.cpp). The chunks are gathered in primitive order, so a draw must give the same bytes
and the same gl.stats() counters for every thread count, and the same bytes as the same primitives
drawn as many small draws (each inside one chunk: the straightforward serial path).

Every draw here has several thousand primitives (more than one chunk) and uses blending, depth or
both, so a primitive reordered inside a tile would change the bytes.
"""
import numpy as np
import pytest

import softgl
from blended_draws import FS, VS, BlendedDraws

THREADS = (1, 2, 3, 8)
SIZE = 80

class Painter(BlendedDraws):
    size = SIZE


def _vertices(rng, n, scale, z_range=(-0.9, 0.9), w_range=(1.0, 1.0)):
    """n vertices in small clusters of three (so triangles stay small), colors in [0, 1]."""
    centre = np.repeat(rng.uniform(-1.1, 1.1, (n // 3 + 1, 2)), 3, axis=0)[:n]
    xy = centre + rng.uniform(-scale, scale, (n, 2))
    z = np.repeat(rng.uniform(*z_range, n // 3 + 1), 3)[:n]
    w = rng.uniform(*w_range, n)
    pos = np.column_stack([xy * w[:, None], z * w, w])
    return pos, rng.uniform(0, 1, (n, 4))


def _same_for_every_thread_count(make, draw):
    results = {}
    for t in THREADS:
        p = make(t)
        draw(p)
        results[t] = p.result()
    images = {t: r[0] for t, r in results.items()}
    counters = {t: r[1] for t, r in results.items()}
    assert len(set(images.values())) == 1, "bytes depend on the thread count"
    for t in THREADS:
        assert counters[t] == counters[1], f"gl.stats() with {t} threads differs from 1 thread"
    return results[1]


MODES = {
    "tiny_triangles": ("TRIANGLES", 3 * 6000, 0.04),
    "triangle_strip": ("TRIANGLE_STRIP", 5000, 0.1),
    "triangle_fan": ("TRIANGLE_FAN", 3000, 0.1),
    "lines": ("LINES", 2 * 4000, 0.15),
    "line_strip": ("LINE_STRIP", 4000, 0.1),
    "line_loop": ("LINE_LOOP", 3000, 0.1),
    "points": ("POINTS", 6000, 1.0),
}


@pytest.mark.parametrize("name", sorted(MODES))
def test_draw_arrays_is_the_same_for_every_thread_count_and_as_small_draws(name):
    mode, n, scale = MODES[name]
    pos, color = _vertices(np.random.default_rng(len(name)), n, scale)
    image, counters = _same_for_every_thread_count(
        lambda t: Painter(t, pos, color), lambda p: p.gl.drawArrays(getattr(p.gl, mode), 0, n))
    assert counters["primitives"] > 2048   # more than one setup chunk
    if mode in ("TRIANGLE_FAN", "LINE_LOOP"):
        return   # their primitives share vertex 0: not expressible as independent small draws
    # The serial reference: the same primitives as draws of at most 300 primitives each.
    p = Painter(1, pos, color)
    gl = p.gl
    per = {"TRIANGLES": 3, "LINES": 2, "POINTS": 1}.get(mode)
    step = 300 * (per or 1)
    for first in range(0, n, step):
        count = min(step, n - first)
        if per is None:   # strips overlap by the shared vertices; `first` stays even (windings)
            count = min(step + (2 if mode == "TRIANGLE_STRIP" else 1), n - first)
        gl.drawArrays(getattr(gl, mode), first, count)
    small_image, small_counters = p.result()
    assert small_image == image, "chunked draw differs from the same primitives drawn one chunk at a time"
    for key in ("primitives", "primitives_rasterized", "primitives_zero_area", "quads",
                "fragments_shaded", "samples_written", "samples_blended"):
        assert small_counters[key] == counters[key], key


def test_strips_with_primitive_restart():
    rng = np.random.default_rng(7)
    n = 6000
    pos, color = _vertices(rng, n, 0.15)
    # Strips of random lengths (1 to 40 vertices, some too short to make a triangle) between
    # restart indices, vertices in a shuffled order and reused.
    indices = []
    order = rng.permutation(n)
    i = 0
    while i < 3 * n:
        length = int(rng.integers(1, 41))
        indices += [int(order[(i + k) % n]) for k in range(length)] + [0xFFFF]
        i += length

    def make(t):
        p = Painter(t, pos, color)
        p.elements(indices, np.uint16)
        return p
    for mode in ("TRIANGLE_STRIP", "LINE_STRIP", "TRIANGLE_FAN"):
        _, counters = _same_for_every_thread_count(
            make, lambda p: p.gl.drawElements(getattr(p.gl, mode), len(indices), p.gl.UNSIGNED_SHORT, 0))
        assert counters["primitives"] > 2048
        assert counters["vertices_shaded"] == n   # each distinct index shaded once


def test_instanced_draws():
    rng = np.random.default_rng(11)
    pos, color = _vertices(rng, 3 * 400, 0.05)
    offsets = rng.uniform(-0.5, 0.5, (12, 2))
    _, counters = _same_for_every_thread_count(
        lambda t: Painter(t, pos, color, offsets),
        lambda p: p.gl.drawArraysInstanced(p.gl.TRIANGLES, 0, 3 * 400, 12))
    assert counters["primitives"] == 12 * 400
    assert counters["vertices_shaded"] == 12 * 3 * 400

    indices = rng.integers(0, 3 * 400, 3 * 900)

    def make(t):
        p = Painter(t, pos, color, offsets)
        p.elements(indices, np.uint32)
        return p
    _, counters = _same_for_every_thread_count(
        make, lambda p: p.gl.drawElementsInstanced(p.gl.LINES, len(indices), p.gl.UNSIGNED_INT, 0, 5))
    assert counters["primitives"] == 5 * len(indices) // 2


def test_clipped_primitives():
    # Vertices beyond near and far, behind the eye (w < 0) and far outside the guard band.
    rng = np.random.default_rng(13)
    n = 3 * 4000
    pos, color = _vertices(rng, n, 0.6, z_range=(-1.6, 1.6), w_range=(-0.3, 2.0))
    pos[::97, :2] *= 3e6
    for mode in ("TRIANGLES", "LINES", "POINTS"):
        _, counters = _same_for_every_thread_count(
            lambda t: Painter(t, pos, color), lambda p: p.gl.drawArrays(getattr(p.gl, mode), 0, n))
        if mode != "POINTS":
            assert counters["primitives_clipped"] > 100
        assert counters["primitives_outside"] > 100


# The tile pass moves a chunk's destination pixels between the RGBA8 drawing buffer and the colour
# kernels' lanes in whole rows of four quads, quad by quad at triangle edges and at the buffer's
# edge (odd sizes: quads reaching past it), keeping a partial quad's uncovered pixels. An RGBA8
# framebuffer object takes the straightforward path instead (RenderTarget::write_color, pixel by
# pixel), so it is the reference: the same draws must give the same bytes there.
COPY_FS = """#version 300 es
precision highp float;
in vec4 vColor;
flat in vec4 vFlat;
out vec4 fragColor;
void main() { fragColor = vColor; }
"""


@pytest.mark.parametrize("blend", ["off", "alpha", "additive", "masked"])
@pytest.mark.parametrize("fs", ["copy", "computed"])
def test_large_triangles_same_bytes_as_a_framebuffer_object(blend, fs):
    rng = np.random.default_rng(5)
    w, h = 83, 61   # odd: quads on the last column and row reach past the buffer
    n = 3 * 40
    centre = np.repeat(rng.uniform(-0.5, 0.5, (n // 3, 2)), 3, axis=0)
    pos = np.column_stack([centre + rng.uniform(-1.2, 1.2, (n, 2)), np.zeros(n), np.ones(n)])
    color = rng.uniform(0, 1, (n, 4))
    images = []
    for target in ("drawing buffer", "framebuffer object"):
        gl = softgl.Context(w, h, antialias=False, threads=1, preserveDrawingBuffer=True)
        # Every fragment reaches the colour kernels: no hidden-surface removal (its own tests).
        softgl._core.testing.set_tuning(gl, hidden_surface_removal="off")
        prog = softgl.program(gl, VS, COPY_FS if fs == "copy" else FS)
        gl.useProgram(prog)
        if target == "framebuffer object":
            tex = gl.createTexture()
            gl.bindTexture(gl.TEXTURE_2D, tex)
            gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, w, h, 0, gl.RGBA, gl.UNSIGNED_BYTE, None)
            gl.bindFramebuffer(gl.FRAMEBUFFER, gl.createFramebuffer())
            gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0)
        gl.bindVertexArray(gl.createVertexArray())
        for name, data in (("aPos", pos), ("aColor", color)):
            loc = gl.getAttribLocation(prog, name)
            gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
            gl.bufferData(gl.ARRAY_BUFFER, np.ascontiguousarray(data, np.float32), gl.STATIC_DRAW)
            gl.enableVertexAttribArray(loc)
            gl.vertexAttribPointer(loc, 4, gl.FLOAT, False, 0, 0)
        gl.vertexAttrib2f(gl.getAttribLocation(prog, "aOffset"), 0.0, 0.0)
        gl.clearColor(0.1, 0.2, 0.3, 0.4)
        gl.clear(gl.COLOR_BUFFER_BIT)
        if blend != "off":
            gl.enable(gl.BLEND)
            if blend == "additive":
                gl.blendFunc(gl.ONE, gl.ONE)
            else:
                gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)
        if blend == "masked":
            gl.colorMask(True, False, True, False)
        gl.drawArrays(gl.TRIANGLES, 0, n)
        images.append(gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE))
        stats = gl.stats()
        assert stats["samples_written"] > 3 * w * h   # overlapping triangles
        assert stats["blocks_accepted_whole"] > 50    # whole 8x8 blocks: rows of four whole quads
        assert gl.last_draw_plan()["hidden_surface_removal_why_not"] == "tuning_off"
    np.testing.assert_array_equal(images[0], images[1])
    assert len(np.unique(images[0].reshape(-1, 4), axis=0)) > 100   # not one flat colour
