"""The diamond-exit rule's major-axis span of a width-1 segment (ES 3.0 §3.5.1), as setup computes
it (pipeline/setup.cpp: diamond_exit_span): from the two end points for |slope| != 1, column by
column for |slope| = 1 or on request ("scan"). Checked against the independent exact-rational
reference (diamond_reference.py) on end points chosen to hit the rule's ties (pixel centres, pixel
borders, diamond boundaries, half pixels), and against the column scan on many random segments up
to the guard band. Then lines drawn through a context (vertices projected by the vectorised
project_vertices, Setup::line's common case, or clipped) at every SIMD level against the
coverage probe (each end projected by itself)."""
import numpy as np
import pytest

import softgl
from softgl import _core
from softgl.testing import tuned
from diamond_reference import diamond_exit_fragments

T = _core.testing
LEVELS = ["scalar", "sse2", "avx2", "avx512"][:T.simd_level() + 1]


def reference_span(a, b):
    """(produced, first, last) from the rational reference's fragments: the segment is moved by
    whole pixels into a small grid (which moves every fragment by the same pixels)."""
    ox = min(a[0], b[0]) // 256 - 3
    oy = min(a[1], b[1]) // 256 - 3
    sa = (a[0] - 256 * ox, a[1] - 256 * oy)
    sb = (b[0] - 256 * ox, b[1] - 256 * oy)
    w = max(sa[0], sb[0]) // 256 + 4
    h = max(sa[1], sb[1]) // 256 + 4
    mask = diamond_exit_fragments(sa, sb, w, h)
    x_major = abs(b[0] - a[0]) >= abs(b[1] - a[1])
    cols = np.nonzero(mask.sum(axis=0 if x_major else 1))[0]
    if not len(cols):
        return (0, 0, 0)
    off = ox if x_major else oy
    return (1, int(cols[0]) + off, int(cols[-1]) + off)


def spans(segments, method="auto"):
    return T.diamond_exit_spans(np.asarray(segments, np.int64).reshape(-1, 4), method)


def tie_points(rng, n, lo, hi):
    """Fixed-point points on the rule's critical positions: pixel centres (128), borders (0),
    diamond corners and sides (+-64, +-128 around a centre), half pixels, and 1/256 off them."""
    base = rng.integers(lo, hi, (n, 2)) * 256
    offsets = np.array([0, 128, 64, 192, 1, 127, 129, 255, 96, 160])
    return base + rng.choice(offsets, (n, 2)) + rng.choice([-1, 0, 0, 0, 1], (n, 2)) * (rng.random((n, 2)) < 0.2)


def segment_sets():
    rng = np.random.default_rng(2024)
    sets = {}
    a = tie_points(rng, 300, 2, 9)
    b = tie_points(rng, 300, 2, 9)
    sets["ties"] = np.concatenate([a, b], 1)
    # Short segments: both ends near one diamond.
    a = tie_points(rng, 200, 4, 6)
    sets["short"] = np.concatenate([a, a + rng.integers(-300, 301, (200, 2))], 1)
    # Slopes of exactly +-1 and near it (the scan's case and its neighbours).
    a = tie_points(rng, 150, 3, 8)
    d = rng.integers(1, 900, 150)
    s = rng.choice([-1, 1], (150, 2))
    nudge = rng.choice([-1, 0, 1], 150)
    sets["diagonal"] = np.stack([a[:, 0], a[:, 1], a[:, 0] + s[:, 0] * d, a[:, 1] + s[:, 1] * (d + nudge)], 1)
    # Axis-parallel segments on centres and borders.
    a = tie_points(rng, 150, 3, 8)
    d = rng.integers(-1200, 1201, 150)
    horizontal = rng.random(150) < 0.5
    sets["axis"] = np.stack([a[:, 0], a[:, 1], a[:, 0] + np.where(horizontal, d, 0),
                             a[:, 1] + np.where(horizontal, 0, d)], 1)
    # Random 1/256 positions, a few pixels long.
    a = rng.integers(512, 2560, (200, 2))
    sets["random"] = np.concatenate([a, a + rng.integers(-1500, 1501, (200, 2))], 1)
    for k, v in sets.items():
        sets[k] = v[~((v[:, 0] == v[:, 2]) & (v[:, 1] == v[:, 3]))]
    return sets


SETS = segment_sets()


@pytest.mark.parametrize("kind", sorted(SETS))
def test_span_matches_the_rational_reference(kind):
    segs = SETS[kind]
    got = spans(segs)
    for seg, g in zip(segs, got):
        a, b = (int(seg[0]), int(seg[1])), (int(seg[2]), int(seg[3]))
        assert tuple(int(v) for v in g) == reference_span(a, b), (a, b)


def test_end_points_on_diamond_boundaries_in_every_direction():
    """An end exactly on a diamond's corner or side, the other end in each of 16 directions at
    several lengths (slopes below, at and above 1): the eps perturbation decides."""
    c = (10 * 256 + 128, 10 * 256 + 128)
    ends = [(c[0] + dx, c[1] + dy) for dx, dy in
            [(128, 0), (-128, 0), (0, 128), (0, -128), (64, 64), (-64, 64), (64, -64), (-64, -64),
             (0, 0), (128, 1), (-127, 0), (1, -127)]]
    dirs = [(1, 0), (0, 1), (-1, 0), (0, -1), (1, 1), (1, -1), (-1, 1), (-1, -1),
            (2, 1), (1, 2), (-2, 1), (1, -2), (3, -2), (-2, -3), (5, 4), (-4, 5)]
    segs = []
    for p in ends:
        for dx, dy in dirs:
            for length in (1, 64, 128, 200, 256, 384, 700):
                q = (p[0] + dx * length, p[1] + dy * length)
                segs += [(*p, *q), (*q, *p)]
    got = spans(segs)
    for seg, g in zip(segs, got):
        a, b = (seg[0], seg[1]), (seg[2], seg[3])
        assert tuple(int(v) for v in g) == reference_span(a, b), (a, b)


@pytest.mark.parametrize("grid", [1, 16, 64, 128, 256])
def test_span_from_the_ends_equals_the_column_scan(grid):
    """Many segments, on grids that make ties frequent, long and short, up to the guard band."""
    rng = np.random.default_rng(grid)
    parts = []
    for scale in (2048, 20000, 1 << 28):
        s = rng.integers(-scale, scale, (40000, 4)) // grid * grid
        s[:, 2:] = np.clip(s[:, :2] + (s[:, 2:] - s[:, :2]) // rng.choice([1, 64, 4096], (40000, 1)), -scale, scale)
        parts.append(s)
    segs = np.concatenate(parts)
    segs = segs[~((segs[:, 0] == segs[:, 2]) & (segs[:, 1] == segs[:, 3]))]
    auto, scan = spans(segs), spans(segs, "scan")
    bad = np.nonzero((auto != scan).any(axis=1))[0]
    assert len(bad) == 0, (segs[bad[:5]].tolist(), auto[bad[:5]].tolist(), scan[bad[:5]].tolist())


def test_the_hook_refuses_bad_segments():
    with pytest.raises(ValueError):
        spans([[5, 5, 5, 5]])
    with pytest.raises(ValueError):
        spans([[0, 0, 1 << 40, 0]])


# ---- Lines through a context: the draw path at every SIMD level ----

W, H = 72, 40
VS = "#version 300 es\nin vec4 aPos;\nvoid main() { gl_Position = aPos; }\n"
FS = "#version 300 es\nprecision highp float;\nout vec4 o;\nvoid main() { o = vec4(1.0); }\n"


def line_positions(seed):
    """Clip-space ends: most inside (the projected common case, on half pixels and pixel centres
    too), some crossing the near plane or w = 0 and some far beyond the guard band (clipped)."""
    rng = np.random.default_rng(seed)
    n = 400
    xy = rng.uniform(-4, np.array([W + 4, H + 4]), (n, 2, 2))
    xy[: n // 4] = np.round(xy[: n // 4] * 2) / 2          # half pixels and pixel borders
    xy[n // 4: n // 2] = np.floor(xy[n // 4: n // 2]) + 0.5   # pixel centres
    w = rng.uniform(0.5, 3, (n, 2))
    clip = np.empty((n, 2, 4))
    clip[..., 0] = (2 * xy[..., 0] / W - 1) * w
    clip[..., 1] = (2 * xy[..., 1] / H - 1) * w
    clip[..., 2] = rng.uniform(-0.9, 0.9, (n, 2)) * w
    clip[..., 3] = w
    k = rng.random(n) < 0.08                               # through the near plane
    clip[k, 1, 2] = -2 * clip[k, 1, 3]
    k = rng.random(n) < 0.05                               # an end behind the eye
    clip[k, 0, 3] = -clip[k, 0, 3]
    k = rng.random(n) < 0.05                               # beyond the guard band
    clip[k, 1, 0] *= 3e6
    return clip.reshape(-1, 4).astype(np.float32)


def draw_lines(positions, simd, threads):
    """Per pixel, how many of the lines (one draw each) wrote it."""
    gl = softgl.Context(W, H, threads=threads, antialias=False)
    prog = softgl.program(gl, VS, FS)
    gl.useProgram(prog)
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.bufferData(gl.ARRAY_BUFFER, positions, gl.STATIC_DRAW)
    gl.enableVertexAttribArray(0)
    gl.vertexAttribPointer(0, 4, gl.FLOAT, False, 0, 0)
    gl.clearColor(0, 0, 0, 0)
    counts = np.zeros((H, W), np.int64)
    with tuned(gl, simd=simd):
        for first in range(0, len(positions), 2):
            gl.clear(gl.COLOR_BUFFER_BIT)
            gl.drawArrays(gl.LINES, first, 2)
            px = np.asarray(gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE)).reshape(H, W, 4)
            counts += px[..., 0] > 0
    return counts


@pytest.mark.parametrize("simd", LEVELS)
def test_lines_drawn_at_every_simd_level_match_the_probe(simd):
    pos = line_positions(3)
    n = len(pos) // 2
    expected = np.zeros((H, W), np.int64)
    for i in range(n):
        expected += _core.raster_coverage(W, H, pos[2 * i: 2 * i + 2], primitive="lines")["count"][..., 0] > 0
    for threads in (1, 2):
        got = draw_lines(pos, simd, threads)
        np.testing.assert_array_equal(got, expected, err_msg=f"{simd} threads={threads}")
