"""A draw runs in batches of primitives (pipeline/draw.cpp): each batch goes through the vertex
stage (only the vertices its primitives use), setup and binning, and the per-tile pass before the
next, so a draw's working memory is bounded. Batches must not change a byte.

Here the batch size is set small (the batch_primitives field of the contexts' tuning, set as the
default for the contexts each test makes: softgl._core.testing.set_default_tuning), so draws of a
few hundred primitives cross many batch boundaries, at every kind of position: inside an
instance, at instance boundaries, between a strip's odd and even triangles, before a fan's or a
loop's last primitive. Each is compared with the same draw in one batch (the batch size set huge)
and, where the primitives are independent, with the same primitives drawn as several small draws.
The scene (blended_draws.py) is order-sensitive: a primitive out of order or a vertex mixed up
changes the bytes.
"""
import numpy as np
import pytest

import softgl
from softgl._core import testing

from blended_draws import VS, BlendedDraws

HUGE = 1 << 24   # one batch for every draw here
SIZE = 48

MODES = ("POINTS", "LINES", "LINE_STRIP", "LINE_LOOP", "TRIANGLES", "TRIANGLE_STRIP", "TRIANGLE_FAN")


@pytest.fixture
def batch_size():
    """A function setting the batch size of the contexts made after it (the default tuning);
    the previous default is back after the test."""
    previous = testing.default_tuning()
    yield lambda size: testing.set_default_tuning(batch_primitives=size)
    testing.set_default_tuning(**previous)


def primitives(mode, count):
    """The vertex numbers of each primitive (ES 3.0 §2.6.1), written out independently of
    pipeline/assemble: lists of `per` vertices, strips sliding by one, fans and loops around 0."""
    if mode == "POINTS":
        return [[i] for i in range(count)]
    if mode == "LINES":
        return [[2 * i, 2 * i + 1] for i in range(count // 2)]
    if mode == "LINE_STRIP":
        return [[i, i + 1] for i in range(count - 1)]
    if mode == "LINE_LOOP":
        return [[i, (i + 1) % count] for i in range(count)] if count >= 2 else []
    if mode == "TRIANGLES":
        return [[3 * i, 3 * i + 1, 3 * i + 2] for i in range(count // 3)]
    if mode == "TRIANGLE_STRIP":
        return [[i, i + 1, i + 2] for i in range(count - 2)]
    return [[0, i + 1, i + 2] for i in range(count - 2)]   # TRIANGLE_FAN


def expected_vertices_shaded(mode, count, instances, batch, ids=None):
    """Vertex shader runs the batches make: an instance whose primitives fit in a batch shades all
    its distinct vertices once (batches of whole instances); a larger one shades, per batch, the
    distinct vertices of the batch's primitives."""
    ids = list(range(count)) if ids is None else list(ids)
    prims = primitives(mode, count)
    if len(prims) <= batch:
        return instances * len(set(ids))
    per_instance = sum(len({ids[v] for prim in prims[b:b + batch] for v in prim})
                       for b in range(0, len(prims), batch))
    return instances * per_instance


class Painter(BlendedDraws):
    size = SIZE


def vertices(rng, n, scale=0.12):
    """n vertices in clusters of three (small triangles), z in [-0.9, 0.9] with ties, colors in
    [0, 1]; a few vertices repeat earlier ones exactly (equal depths: LEQUAL order matters)."""
    centre = np.repeat(rng.uniform(-1.05, 1.05, (n // 3 + 1, 2)), 3, axis=0)[:n]
    xy = centre + rng.uniform(-scale, scale, (n, 2))
    z = np.round(np.repeat(rng.uniform(-0.9, 0.9, n // 3 + 1), 3)[:n], 1)
    pos = np.column_stack([xy, z, np.ones(n)])
    pos[5::17] = pos[1::17][:len(pos[5::17])]
    return pos, rng.uniform(0, 1, (n, 4))


def draw_twice(make, draw, batch, batch_size, threads=(1, 3)):
    """The draw in batches of `batch` primitives and in one batch: (small, reference) results."""
    out = []
    for size in (batch, HUGE):
        batch_size(size)
        for t in threads:
            p = make(t)
            draw(p)
            out.append((size, t, p.result()))
    reference = out[-1][2]
    for size, t, (image, counters) in out:
        assert image == reference[0], f"batches of {size} primitives, {t} threads: bytes differ from one batch"
        for key, value in counters.items():
            # draws_with_rollback: a draw in several batches keeps copies to put back if stopped
            # (docs/reliability.md, "Work budget and Ctrl-C"); one batch need not.
            if key not in ("vertices_shaded", "draws_with_rollback"):
                assert value == reference[1][key], f"batches of {size}, {t} threads: {key}"
    return out[0][2][1], reference[1]


def test_primitive_vertex_range_is_exactly_the_vertices_used():
    for mode in MODES:
        m = getattr(softgl.WebGL2RenderingContext, mode)
        for count in (1, 2, 3, 4, 5, 7, 12):
            prims = primitives(mode, count)
            for p0 in range(len(prims)):
                for p1 in range(p0 + 1, len(prims) + 1):
                    begin, end, and_zero = testing.primitive_vertex_range(m, count, p0, p1)
                    used = {v for prim in prims[p0:p1] for v in prim}
                    listed = set(range(begin, end)) | ({0} if and_zero else set())
                    assert listed == used, (mode, count, p0, p1)
                    assert not (and_zero and begin == 0), (mode, count, p0, p1)


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("indexed", [False, True], ids=["arrays", "elements"])
@pytest.mark.parametrize("instances", [1, 3])
def test_batches_give_the_same_bytes_as_one_batch(mode, indexed, instances, batch_size):
    rng = np.random.default_rng([MODES.index(mode), indexed, instances])
    n = 420
    pos, color = vertices(rng, n)
    offsets = rng.uniform(-0.3, 0.3, (instances, 2)) if instances > 1 else None
    count = 400
    # Indices near their position (primitives stay small), reused and out of order.
    indices = (np.arange(count) + rng.integers(-4, 5, count)) % n
    m = getattr(softgl.WebGL2RenderingContext, mode)
    per_instance = len(primitives(mode, count))

    def make(t):
        p = Painter(t, pos, color, offsets)
        if indexed:
            p.elements(indices)
        return p

    def draw(p):
        if indexed:
            p.gl.drawElementsInstanced(m, count, p.gl.UNSIGNED_SHORT, 0, instances)
        else:
            p.gl.drawArraysInstanced(m, 10, count, instances)

    # Boundaries at odd and even primitives, just inside and outside an instance, and batches of
    # whole instances (per_instance + 1: one instance per batch; 2 * per_instance: two).
    for batch in (1, 2, 37, per_instance - 1, per_instance, per_instance + 1, 2 * per_instance):
        small, reference = draw_twice(make, draw, batch, batch_size)
        assert reference["primitives"] == instances * per_instance
        ids = indices if indexed else None
        assert small["vertices_shaded"] == expected_vertices_shaded(mode, count, instances, batch, ids), batch
    assert reference["vertices_shaded"] == instances * len(set(indices if indexed else range(count)))
    assert reference["primitives_rasterized"] > per_instance // 2


@pytest.mark.parametrize("mode", ["POINTS", "LINES", "TRIANGLES", "LINE_STRIP", "TRIANGLE_STRIP"])
def test_batches_give_the_same_bytes_as_small_draws(mode, batch_size):
    rng = np.random.default_rng(len(mode))
    n = 900
    pos, color = vertices(rng, n)
    m = getattr(softgl.WebGL2RenderingContext, mode)
    batch_size(53)
    p = Painter(2, pos, color)
    p.gl.drawArrays(m, 0, n)
    batched = p.result()
    # The reference: the same primitives as draws of 30 primitives each, in one batch each.
    batch_size(HUGE)
    p = Painter(2, pos, color)
    per = {"TRIANGLES": 3, "LINES": 2, "POINTS": 1}.get(mode)
    step = 30 * (per or 1)
    for first in range(0, n, step):
        count = min(step, n - first)
        if per is None:   # strips overlap by the shared vertices; `first` stays even (windings)
            count = min(step + (2 if mode == "TRIANGLE_STRIP" else 1), n - first)
        p.gl.drawArrays(m, first, count)
    image, counters = p.result()
    assert batched[0] == image
    for key in ("primitives", "primitives_rasterized", "primitives_zero_area", "primitives_outside",
                "quads", "fragments_shaded", "fragments_killed_early", "samples_written", "samples_blended"):
        assert batched[1][key] == counters[key], key


@pytest.mark.parametrize("span", [1_000, 60_000, 300_000], ids=["narrow", "wide", "wider_than_the_table"])
@pytest.mark.parametrize("batch", [37, HUGE])
def test_index_span_gives_the_same_vertices_and_bytes(span, batch, batch_size):
    # list_vertices finds each distinct index's slot in a table over the indices' span, or, when
    # the span is wider than max(2^16, 8 x the indices), in a hash map. The same vertices placed
    # at indices spread over `span` must give the bytes of the compact draw, and the vertex stage
    # must run once per distinct index (per batch).
    rng = np.random.default_rng(span)
    n, count = 420, 400
    pos, color = vertices(rng, n)
    indices = (np.arange(count) + rng.integers(-4, 5, count)) % n
    where = np.sort(rng.choice(span, n, replace=False))
    where[-1] = span - 1   # the span is exactly `span`
    wide_pos, wide_color = np.zeros((span, 4)), np.zeros((span, 4))
    wide_pos[where], wide_color[where] = pos, color
    mode = softgl.WebGL2RenderingContext.TRIANGLE_STRIP
    batch_size(batch)
    results = []
    for p_pos, p_color, p_indices, dtype in ((pos, color, indices, np.uint16),
                                             (wide_pos, wide_color, where[indices], np.uint32)):
        p = Painter(1, p_pos, p_color)
        p.elements(p_indices, dtype)
        p.gl.drawElements(mode, count, p.gl.UNSIGNED_SHORT if dtype == np.uint16 else p.gl.UNSIGNED_INT, 0)
        results.append(p.result())
    (compact, compact_counters), (spread, spread_counters) = results
    assert spread == compact
    assert spread_counters == compact_counters
    assert compact_counters["vertices_shaded"] == expected_vertices_shaded("TRIANGLE_STRIP", count, 1, batch, indices)
    assert compact_counters["primitives_rasterized"] > 100


@pytest.mark.parametrize("mode", ["TRIANGLE_STRIP", "TRIANGLE_FAN", "LINE_STRIP", "LINE_LOOP"])
def test_primitive_restart_in_batches(mode, batch_size):
    rng = np.random.default_rng(5)
    n = 500
    pos, color = vertices(rng, n)
    indices, i = [], 0
    while i < 700:   # runs of 1 to 12 vertices between restart indices, shuffled and reused
        length = int(rng.integers(1, 13))
        indices += [int((i + k * 7) % n) for k in range(length)] + [0xFFFF]
        i += length
    m = getattr(softgl.WebGL2RenderingContext, mode)
    offsets = rng.uniform(-0.2, 0.2, (2, 2))

    def make(t):
        p = Painter(t, pos, color, offsets)
        p.elements(indices)
        return p

    def draw(p):
        p.gl.drawElementsInstanced(m, len(indices), p.gl.UNSIGNED_SHORT, 0, 2)

    for batch in (1, 7, 64, 500):
        _, reference = draw_twice(make, draw, batch, batch_size)
    assert reference["primitives"] > 500


def test_multisampled_and_clipped_in_batches(batch_size):
    rng = np.random.default_rng(9)
    n = 600
    pos, color = vertices(rng, n, scale=0.5)
    pos[:, 3] = rng.uniform(-0.3, 2.0, n)   # behind the eye, near and far: clipped into pieces
    pos[::31, :2] *= 1e5

    def make(t):
        return Painter(t, pos, color, samples=4)

    for mode in ("TRIANGLES", "LINE_STRIP", "POINTS"):
        _, reference = draw_twice(make, lambda p: p.gl.drawArrays(getattr(p.gl, mode), 0, n), 11, batch_size)
        assert reference["primitives_outside"] > 0
    assert reference["primitives_clipped"] + reference["primitives_outside"] > 0


def test_rasterizer_discard_and_no_output_in_batches(batch_size):
    rng = np.random.default_rng(3)
    pos, color = vertices(rng, 300)

    def discard(t):
        p = Painter(t, pos, color)
        p.gl.enable(p.gl.RASTERIZER_DISCARD)
        return p

    def no_output(t):
        p = Painter(t, pos, color)
        p.gl.colorMask(False, False, False, False)
        p.gl.depthMask(False)
        return p

    draw = lambda p: p.gl.drawArrays(p.gl.TRIANGLE_STRIP, 0, 300)
    small, reference = draw_twice(discard, draw, 10, batch_size)
    assert reference["primitives"] == 0 and reference["vertices_shaded"] == 300
    assert small["vertices_shaded"] == expected_vertices_shaded("TRIANGLE_STRIP", 300, 1, 10)
    small, reference = draw_twice(no_output, draw, 10, batch_size)
    assert reference["draws_skipped_no_output"] == 1 and reference["primitives"] == 298
    assert reference["tiles_touched"] == 0 and small["tiles_touched"] == 0


def test_tiles_touched_counts_each_tile_once_per_draw(batch_size):
    # 200 points at the same spot, one tile: batches of 10 make 20 tile passes over that tile.
    pos = np.tile([[0.1, 0.1, 0.0, 1.0]], (200, 1))
    color = np.tile([[0.5, 0.5, 0.5, 1.0]], (200, 1))
    _, reference = draw_twice(lambda t: Painter(t, pos, color),
                              lambda p: p.gl.drawArrays(p.gl.POINTS, 0, 200), 10, batch_size)
    assert reference["tiles_touched"] == 1


def test_blend_lab_sees_one_draw_in_batches(batch_size):
    """The blend lab's hooks: begin_draw once per draw (draw numbers), fragments in primitive
    order with their primitive numbers, and the A-buffer's resolve."""
    rng = np.random.default_rng(21)
    n = 240
    pos, color = vertices(rng, n, scale=0.3)
    results = []
    for size in (7, HUGE):
        batch_size(size)
        p = Painter(2, pos, color)
        gl = p.gl
        gl.enable(gl.getExtension("SOFTGL_introspection").INTROSPECTION_SOFTGL)
        gl.drawArrays(gl.TRIANGLE_STRIP, 0, n)
        gl.drawArrays(gl.TRIANGLES, 0, n)
        log = [gl.fragments(x, y) for y in range(0, SIZE, 3) for x in range(0, SIZE, 3)]
        image, _ = p.result()
        q = Painter(2, pos, color)
        q.gl.depthMask(False)
        ext = q.gl.getExtension("SOFTGL_exact_transparency")
        q.gl.enable(ext.EXACT_TRANSPARENCY_SOFTGL)
        q.gl.drawArrays(q.gl.TRIANGLES, 0, n)
        resolved = ext.resolve()
        results.append((image, log, resolved))
    (image, log, resolved), (ref_image, ref_log, ref_resolved) = results
    assert sum(len(f) for f in ref_log) > 100
    assert {r["draw"] for f in ref_log for r in f} == {0, 1}
    assert image == ref_image and log == ref_log
    assert np.array_equal(resolved, ref_resolved)


def test_uniform_only_fragment_shader_in_batches(batch_size):
    """The uniform-only shortcut (one quad shaded per chunk, its colour copied) across batches."""
    rng = np.random.default_rng(17)
    pos, color = vertices(rng, 600, scale=0.2)
    fs = """#version 300 es
precision highp float;
uniform vec4 uColor;
out vec4 fragColor;
void main() { fragColor = uColor; }
"""

    def make(t):
        p = Painter(t, pos, color)
        prog = softgl.program(p.gl, VS, fs)
        p.gl.useProgram(prog)
        p.gl.uniform4f(p.gl.getUniformLocation(prog, "uColor"), 0.9, 0.3, 0.2, 0.4)
        return p

    for mode in ("TRIANGLES", "TRIANGLE_FAN", "POINTS"):
        _, reference = draw_twice(make, lambda p: p.gl.drawArrays(getattr(p.gl, mode), 0, 600), 13, batch_size)
        assert reference["samples_blended"] > 100


def test_vertex_outputs_written_in_some_lanes_or_none():
    # The vertex stage zeroes only the outputs whose register no instruction writes; the executor
    # writes every lane of the others (a variable written under a branch starts at zero). Flat
    # varyings from the provoking (last) vertex: vA is written only where aPos.x > 0, vB never.
    # Drawn twice with different vertex counts, so the runs reuse their arrays.
    vs = """#version 300 es
    in vec4 aPos;
    flat out vec4 vA;
    flat out vec4 vB;
    void main() {
        if (aPos.x > 0.0) vA = vec4(0.25, 0.5, 0.75, 1.0);
        gl_Position = aPos;
    }"""
    fs = """#version 300 es
    precision highp float;
    flat in vec4 vA;
    flat in vec4 vB;
    out vec4 fragColor;
    void main() { fragColor = vec4(vA.rg, vB.r + vA.b, 1.0 - vB.a); }"""
    size = 16
    gl = softgl.Context(size, size, antialias=False, preserveDrawingBuffer=True)
    prog = softgl.program(gl, vs, fs)
    gl.useProgram(prog)
    gl.bindVertexArray(gl.createVertexArray())

    def quad(x0, x1):   # two triangles; each one's last vertex on the x1 side
        return [[x0, -1, 0, 1], [x0, 1, 0, 1], [x1, -1, 0, 1], [x0, 1, 0, 1], [x1, -1, 0, 1], [x1, 1, 0, 1]]

    expect = np.zeros((size, size, 4), np.uint8)
    expect[..., 3] = 255
    expect[:, size // 2:, :3] = [64, 128, 191]   # 0.25, 0.5, 0.75 of 255, rounded
    for quads in ([(-1, 0), (0, 1)], [(-1, -0.5), (-0.5, 0), (0, 0.5), (0.5, 1)], [(-1, 0), (0, 1)]):
        pos = np.array([v for q in quads for v in quad(*q)], np.float32)
        # the left quads' last vertices are at x <= 0: vA stays zero there
        gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
        gl.bufferData(gl.ARRAY_BUFFER, pos, gl.STATIC_DRAW)
        loc = gl.getAttribLocation(prog, "aPos")
        gl.enableVertexAttribArray(loc)
        gl.vertexAttribPointer(loc, 4, gl.FLOAT, False, 0, 0)
        gl.clearColor(0.5, 0.5, 0.5, 0.5)
        gl.clear(gl.COLOR_BUFFER_BIT)
        gl.drawArrays(gl.TRIANGLES, 0, len(pos))
        image = gl.readPixels(0, 0, size, size, gl.RGBA, gl.UNSIGNED_BYTE)
        np.testing.assert_array_equal(image.reshape(size, size, 4), expect, err_msg=str(quads))
