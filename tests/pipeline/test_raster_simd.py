"""pipeline/raster's SIMD partial-block kernels (AVX2, AVX-512) against the scalar path: the same
quads in the same order with the same coverage, and the same block statistics, bit for bit. The
scalar path itself is checked against a brute-force evaluation of the edge functions."""
import zlib

import numpy as np
import pytest

from softgl import _core

T = _core.testing
LEVELS = range(1, T.simd_level() + 1)
SUB = 256
# Standard sample positions in 1/256 pixel (raster.cpp's table).
OFFSETS = {
    1: [(128, 128)],
    2: [(192, 192), (64, 64)],
    4: [(96, 32), (224, 96), (32, 160), (160, 224)],
    8: [(144, 80), (112, 176), (208, 144), (80, 48), (48, 208), (16, 112), (176, 240), (240, 16)],
    16: [(144, 144), (112, 80), (80, 160), (192, 112), (48, 96), (160, 208), (208, 176), (176, 48),
         (96, 224), (128, 16), (64, 32), (32, 192), (0, 128), (240, 64), (224, 240), (16, 0)],
}


def polygon_edges(xs, ys):
    """Edges (a, b, c) of the convex polygon through the fixed-point vertices, counter-clockwise,
    with the tie rule folded into c (setup.cpp make_edge)."""
    n = len(xs)
    area2 = sum(xs[i] * ys[(i + 1) % n] - xs[(i + 1) % n] * ys[i] for i in range(n))
    order = list(range(n)) if area2 > 0 else list(range(n))[::-1]
    edges = []
    for i in range(n):
        j, k = order[i], order[(i + 1) % n]
        a, b = ys[j] - ys[k], xs[k] - xs[j]
        included = a > 0 or (a == 0 and b > 0)
        edges.append((a, b, -(a * xs[j] + b * ys[j]) - (0 if included else 1)))
    return edges


def rasterize(level, edges, bbox, tile, samples):
    quads, stats = T.rasterize_edges(level, np.array(edges, np.int64), bbox, tile, samples)
    return quads, stats


def brute_force(edges, bbox, tile, samples):
    """{(x, y): sample mask} of every pixel of bbox ∩ tile with a covered sample."""
    x0, y0 = max(bbox[0], tile[0]), max(bbox[1], tile[1])
    x1, y1 = min(bbox[2], tile[2]), min(bbox[3], tile[3])
    out = {}
    if x0 >= x1 or y0 >= y1:
        return out
    px, py = np.meshgrid(np.arange(x0, x1, dtype=np.int64), np.arange(y0, y1, dtype=np.int64))
    mask = np.zeros(px.shape, np.uint64)
    for s, (ox, oy) in enumerate(OFFSETS[samples]):
        inside = np.ones(px.shape, bool)
        for a, b, c in edges:
            inside &= a * (px * SUB + ox) + b * (py * SUB + oy) + c >= 0
        mask |= inside.astype(np.uint64) << np.uint64(s)
    for yy, xx in zip(*np.nonzero(mask)):
        out[(int(px[yy, xx]), int(py[yy, xx]))] = int(mask[yy, xx])
    return out


def block_counts(edges, bbox, tile, samples):
    """(rejected, accepted, partial) by testing every 8x8 block of bbox ∩ tile, one by one: each
    edge's extremes over the rectangle spanned by the block's (clipped) samples."""
    x0, y0 = max(bbox[0], tile[0]), max(bbox[1], tile[1])
    x1, y1 = min(bbox[2], tile[2]), min(bbox[3], tile[3])
    if x0 >= x1 or y0 >= y1:
        return 0, 0, 0
    ox = [o[0] for o in OFFSETS[samples]]
    oy = [o[1] for o in OFFSETS[samples]]
    counts = [0, 0, 0]
    for by in range(y0 & ~7, y1, 8):
        for bx in range(x0 & ~7, x1, 8):
            cx0, cx1, cy0, cy1 = max(bx, x0), min(bx + 8, x1), max(by, y0), min(by + 8, y1)
            xs = (cx0 * SUB + min(ox), (cx1 - 1) * SUB + max(ox))
            ys = (cy0 * SUB + min(oy), (cy1 - 1) * SUB + max(oy))
            values = [[a * x + b * y + c for x in xs for y in ys] for a, b, c in edges]
            if any(max(v) < 0 for v in values):
                counts[0] += 1
            elif all(min(v) >= 0 for v in values):
                counts[1] += 1
            else:
                counts[2] += 1
    return tuple(counts)


def signed(v):
    return v - (1 << 64) if v >= 1 << 63 else v


def decode(quads):
    out = {}
    for x, y, cov in quads.tolist():
        x, y = signed(x), signed(y)
        for j in range(4):
            m = (cov >> (16 * j)) & 0xFFFF
            if m:
                out[(x + (j & 1), y + (j >> 1))] = m
    return out


def random_case(rng, kind):
    """(edges, bbox, tile): a primitive around a random 64x64 tile, the bbox its pixel bounds clipped
    to a random scissor-like rectangle."""
    tx, ty = (int(v) * 64 for v in rng.integers(-2000, 2000, 2))
    if kind == "huge":            # far vertices (29-bit coordinates), edges through the tile
        tx, ty = (int(v) * 64 for v in rng.integers(-16000, 16000, 2))
        cx, cy = (tx + 32) * SUB, (ty + 32) * SUB
        lim = (1 << 28) - 1
        xs = [int(np.clip(cx + rng.integers(-40 * SUB, 40 * SUB), -lim, lim))] + \
             [int(v) for v in rng.integers(-lim, lim, 2)]
        ys = [int(np.clip(cy + rng.integers(-40 * SUB, 40 * SUB), -lim, lim))] + \
             [int(v) for v in rng.integers(-lim, lim, 2)]
    else:
        size = {"small": 14, "sliver": 40, "tiny": 3, "big": 90, "quad": 30, "band": 30}[kind]
        cx, cy = (tx + int(rng.integers(-8, 72))) * SUB, (ty + int(rng.integers(-8, 72))) * SUB
        if kind == "band":         # a single-sample line's 2 band edges, its bbox the major extent
            hx, hy = (int(v) for v in rng.integers(1, size * SUB, 2))
            h = int(rng.integers(1, 4)) * SUB // 2
            xs, ys = [cx - hx, cx + hx, cx + hx, cx - hx], [cy - hy - h, cy + hy - h, cy + hy + h, cy - hy + h]
            if rng.random() < 0.5:
                xs, ys = ys, xs
            edges = polygon_edges(xs, ys)[0::2]   # both sides parallel to the segment
        elif kind == "quad":         # a line-like parallelogram or an axis-aligned rectangle (points)
            hx, hy = (int(v) for v in rng.integers(1, size * SUB, 2))
            if rng.random() < 0.5:
                xs, ys = [cx - hx, cx + hx, cx + hx, cx - hx], [cy - hy, cy - hy, cy + hy, cy + hy]
            else:
                w = int(rng.integers(1, 3 * SUB))
                xs, ys = [cx - hx, cx + hx, cx + hx, cx - hx], [cy - hy, cy + hy - w, cy + hy, cy - hy + w]
                if rng.random() < 0.5:
                    xs, ys = ys, xs
        else:
            xs = [cx + int(v) for v in rng.integers(-size * SUB, size * SUB, 3)]
            ys = [cy + int(v) for v in rng.integers(-size * SUB, size * SUB, 3)]
            if kind == "sliver":   # sub-pixel thin: the third vertex just off the first edge
                t = rng.random()
                xs[2] = int(xs[0] + t * (xs[1] - xs[0])) + int(rng.integers(-40, 40))
                ys[2] = int(ys[0] + t * (ys[1] - ys[0])) + int(rng.integers(-40, 40))
        if rng.random() < 0.3:     # on the 1/16 grid: ties at sample positions
            xs, ys = [x & ~15 for x in xs], [y & ~15 for y in ys]
    if kind != "band":
        edges = polygon_edges(xs, ys)
    bbox = [min(xs) // SUB, min(ys) // SUB, max(xs) // SUB + 1, max(ys) // SUB + 1]
    if rng.random() < 0.5:         # scissor: odd rectangles
        sx, sy = tx + int(rng.integers(-3, 40)), ty + int(rng.integers(-3, 40))
        sw, sh = (int(v) for v in rng.integers(1, 40, 2))
        bbox = [max(bbox[0], sx), max(bbox[1], sy), min(bbox[2], sx + sw), min(bbox[3], sy + sh)]
    bbox = [max(bbox[0], tx - 100), max(bbox[1], ty - 100), min(bbox[2], tx + 164), min(bbox[3], ty + 164)]
    if rng.random() < 0.2:         # a wider tile, not on the block grid
        return edges, bbox, [tx - 6, ty - 2, tx + 132, ty + 66]
    return edges, bbox, [tx, ty, tx + 64, ty + 64]


@pytest.mark.skipif(T.simd_level() < 2, reason="no AVX2 on this CPU")
@pytest.mark.parametrize("samples", [1, 2, 4, 8, 16])
@pytest.mark.parametrize("kind", ["small", "tiny", "sliver", "big", "quad", "band", "huge"])
def test_simd_levels_match_scalar(kind, samples):
    rng = np.random.default_rng(zlib.crc32(f"{kind}{samples}".encode()))
    n = 300 if samples == 1 else 60
    checked = 0
    for _ in range(n):
        edges, bbox, tile = random_case(rng, kind)
        ref_quads, ref_stats = rasterize(0, edges, bbox, tile, samples)
        for level in LEVELS:
            quads, stats = rasterize(level, edges, bbox, tile, samples)
            assert stats == ref_stats, (level, edges, bbox, tile)
            np.testing.assert_array_equal(quads, ref_quads, err_msg=str((level, edges, bbox, tile)))
        checked += len(ref_quads) > 0
    assert checked > n // 10    # the cases do cover pixels


@pytest.mark.parametrize("samples", [1, 4, 16])
@pytest.mark.parametrize("kind", ["small", "sliver", "quad", "band", "huge", "big"])
def test_scalar_matches_brute_force(kind, samples):
    rng = np.random.default_rng(zlib.crc32(f"bf{kind}{samples}".encode()))
    for _ in range(40):
        edges, bbox, tile = random_case(rng, kind)
        quads, (rejected, accepted, partial, nquads) = rasterize(0, edges, bbox, tile, samples)
        assert nquads == len(quads)
        assert (rejected, accepted, partial) == block_counts(edges, bbox, tile, samples)
        assert decode(quads) == brute_force(edges, bbox, tile, samples)
        # Blocks bottom-up then left-right, quads likewise; no quad twice.
        keys = [(signed(y) // 8, signed(x) // 8, signed(y), signed(x)) for x, y, _ in quads.tolist()]
        assert keys == sorted(keys) and len(set(keys)) == len(keys)
