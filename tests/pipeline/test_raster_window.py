"""pipeline/raster's small window (RasterWalk::Any: one sample per pixel, a part of at most 8x8
pixels from an even pixel, every edge's sign at the window's pixel centres at once in int32 lanes)
against the block walk (RasterWalk::Blocks) and against independent references: brute-force edge
functions in Python integers, and hand-worked triangles. Same quads, same order, same coverage,
same block statistics, at every SIMD level."""
import zlib

import numpy as np
import pytest

from softgl import _core

from test_raster_simd import block_counts, brute_force, decode, polygon_edges, random_case, signed

T = _core.testing
LEVELS = range(0, T.simd_level() + 1)
SUB = 256


def rasterize(level, edges, bbox, tile, blocks_only=False, samples=1):
    return T.rasterize_edges(level, np.array(edges, np.int64), bbox, tile, samples, blocks_only=blocks_only)


def walk_taken(edges, bbox, tile):
    """Which walk raster.cpp rasterize_at takes (one sample), restated: 'window' when the clipped
    part fits 8x8 pixels from an even pixel, 'masked' when it meets at most 16 blocks (both only
    when every edge has |a| + |b| < 2^19), else 'blocks'."""
    x0, y0 = max(bbox[0], tile[0]), max(bbox[1], tile[1])
    x1, y1 = min(bbox[2], tile[2]), min(bbox[3], tile[3])
    if x0 >= x1 or y0 >= y1 or not all(abs(a) + abs(b) < 1 << 19 for a, b, _ in edges):
        return "blocks"
    if x1 - (x0 & ~1) <= 8 and y1 - (y0 & ~1) <= 8:
        return "window"
    return "masked" if ((x1 - 1) // 8 - x0 // 8 + 1) * ((y1 - 1) // 8 - y0 // 8 + 1) <= 16 else "blocks"


def takes_window(edges, bbox, tile):
    return walk_taken(edges, bbox, tile) == "window"


def window_case(rng, kind):
    """(edges, bbox, tile) whose clipped part is a few pixels: small triangles anywhere around the
    8x8 block grid, lines' band edges, and long triangles (edge steps near the int32 limit, edge
    values beyond the clamp) seen through a small tile rectangle."""
    tx, ty = (int(v) * 64 for v in rng.integers(-2000, 2000, 2))
    cx, cy = (tx + int(rng.integers(0, 64))) * SUB + int(rng.integers(0, SUB)), \
             (ty + int(rng.integers(0, 64))) * SUB + int(rng.integers(0, SUB))
    tile = [tx, ty, tx + 64, ty + 64]
    if kind == "long":
        reach = int(rng.choice([900, 1020, 1030, 2000])) * SUB   # |a| + |b| around 2^19
        xs = [cx] + [cx + int(v) for v in rng.integers(-reach, reach, 2)]
        ys = [cy] + [cy + int(v) for v in rng.integers(-reach, reach, 2)]
        edges = polygon_edges(xs, ys)
        px, py = cx // SUB + int(rng.integers(-4, 4)), cy // SUB + int(rng.integers(-4, 4))
        bbox = [px, py, px + int(rng.integers(1, 8)), py + int(rng.integers(1, 8))]
        return edges, bbox, tile
    if kind == "band":
        hx, hy = (int(v) for v in rng.integers(1, 3 * SUB, 2))
        h = SUB // 2
        xs, ys = [cx - hx, cx + hx, cx + hx, cx - hx], [cy - hy - h, cy + hy - h, cy + hy + h, cy - hy + h]
        if rng.random() < 0.5:
            xs, ys = ys, xs
        edges = polygon_edges(xs, ys)[0::2]
    elif kind == "point":
        h = int(rng.integers(1, 4)) * SUB // 2
        xs, ys = [cx - h, cx + h, cx + h, cx - h], [cy - h, cy - h, cy + h, cy + h]
        edges = polygon_edges(xs, ys)
    else:
        size = {"tiny": 2, "small": 4, "medium": 14}[kind]
        xs = [cx + int(v) for v in rng.integers(-size * SUB, size * SUB, 3)]
        ys = [cy + int(v) for v in rng.integers(-size * SUB, size * SUB, 3)]
        if rng.random() < 0.4:     # on the 1/16 or 1/2 pixel grid: ties at pixel centres
            g = 15 if rng.random() < 0.5 else 127
            xs, ys = [x & ~g for x in xs], [y & ~g for y in ys]
        edges = polygon_edges(xs, ys)
    bbox = [min(xs) // SUB, min(ys) // SUB, max(xs) // SUB + 1, max(ys) // SUB + 1]
    if rng.random() < 0.3:         # a scissor or tile edge through the part
        sx, sy = bbox[0] + int(rng.integers(-1, 3)), bbox[1] + int(rng.integers(-1, 3))
        bbox = [max(bbox[0], sx), max(bbox[1], sy), bbox[2], bbox[3]]
    if rng.random() < 0.2:
        tile = [bbox[0] + 1, bbox[1], bbox[0] + 40, bbox[1] + 3]
    return edges, bbox, tile


@pytest.mark.parametrize("kind", ["tiny", "small", "band", "point", "long"])
def test_window_matches_block_walk_and_brute_force(kind):
    rng = np.random.default_rng(zlib.crc32(f"window{kind}".encode()))
    taken = covered = 0
    for _ in range(400):
        edges, bbox, tile = window_case(rng, kind)
        ref_quads, ref_stats = rasterize(0, edges, bbox, tile, blocks_only=True)
        assert decode(ref_quads) == brute_force(edges, bbox, tile, 1)
        assert ref_stats[:3] == block_counts(edges, bbox, tile, 1)
        for level in LEVELS:
            for blocks_only in (False, True):
                quads, stats = rasterize(level, edges, bbox, tile, blocks_only)
                assert stats == ref_stats, (level, blocks_only, edges, bbox, tile)
                np.testing.assert_array_equal(quads, ref_quads, err_msg=str((level, blocks_only, edges, bbox, tile)))
        taken += takes_window(edges, bbox, tile)
        covered += len(ref_quads) > 0
    assert taken > 200 and covered > 100   # the cases do take the window and cover pixels


@pytest.mark.parametrize("kind", ["small", "tiny", "sliver", "big", "quad", "band", "huge"])
def test_any_walk_matches_block_walk_on_general_cases(kind):
    rng = np.random.default_rng(zlib.crc32(f"walk{kind}".encode()))
    for _ in range(200):
        edges, bbox, tile = random_case(rng, kind)
        ref = rasterize(0, edges, bbox, tile, blocks_only=True)
        for level in LEVELS:
            quads, stats = rasterize(level, edges, bbox, tile)
            assert stats == ref[1]
            np.testing.assert_array_equal(quads, ref[0])


@pytest.mark.parametrize("kind", ["medium", "long"])
def test_masked_blocks_match_block_walk_and_brute_force(kind):
    rng = np.random.default_rng(zlib.crc32(f"masked{kind}".encode()))
    taken = 0
    for _ in range(300):
        edges, bbox, tile = window_case(rng, kind)
        if kind == "long":   # a bigger part of the long triangles than the window cases
            bbox = [bbox[0] - 7, bbox[1] - 5, bbox[2] + 9, bbox[3] + 6]
        ref_quads, ref_stats = rasterize(0, edges, bbox, tile, blocks_only=True)
        assert decode(ref_quads) == brute_force(edges, bbox, tile, 1)
        assert ref_stats[:3] == block_counts(edges, bbox, tile, 1)
        for level in LEVELS:
            quads, stats = rasterize(level, edges, bbox, tile)
            assert stats == ref_stats, (level, edges, bbox, tile)
            np.testing.assert_array_equal(quads, ref_quads, err_msg=str((level, edges, bbox, tile)))
        taken += walk_taken(edges, bbox, tile) == "masked"
    assert taken > 100


def triangle(vertices):
    xs = [x * SUB for x, _ in vertices]
    ys = [y * SUB for _, y in vertices]
    return polygon_edges(xs, ys)


@pytest.mark.parametrize("level", LEVELS)
def test_hand_worked_triangle_across_four_blocks(level):
    # The right triangle (6, 6), (10, 6), (6, 10): the centre (6 + i + 1/2, 6 + j + 1/2) is inside
    # when i + j < 3, and on the hypotenuse when i + j == 3. That edge runs up-left (from (10, 6)
    # to (6, 10)): not a left or bottom edge, so the centres on it are out. Covered: i + j <= 2.
    # Blocks: (0, 0) holds (6..7, 6..7), all covered: accepted; (8, 0) holds (8, 6) of its
    # (8..9, 6..7): partial; (0, 8) holds (6, 8): partial; (8, 8) has i + j >= 4 everywhere,
    # outside the hypotenuse: rejected.
    edges = triangle([(6, 6), (10, 6), (6, 10)])
    quads, stats = rasterize(level, edges, [6, 6, 10, 10], [0, 0, 64, 64])
    assert [(signed(x), signed(y), c) for x, y, c in quads.tolist()] == [
        (6, 6, 0x0001_0001_0001_0001), (8, 6, 0x1), (6, 8, 0x1)]
    assert stats == (1, 1, 2, 3)


@pytest.mark.parametrize("level", LEVELS)
def test_hand_worked_ties_on_left_and_bottom_edges(level):
    # The triangle (1, 1), (1, 5), (5, 1) wound clockwise: setup's counter-clockwise order is
    # (1, 1), (5, 1), (1, 5). Its vertical edge x = 1 and horizontal edge y = 1 have no centre on
    # them; move it by half a pixel to put centres on both: (1.5, 1.5), (5.5, 1.5), (1.5, 5.5).
    # The vertical edge runs down (left edge: included), the horizontal one runs right (bottom
    # edge: included), the hypotenuse x + y = 7 runs up-left (excluded). Centres (x + 1/2, y + 1/2)
    # for x, y >= 1 with x + y + 1 < 7: x + y <= 5.
    xs = [384, 1408, 384]
    ys = [384, 384, 1408]
    edges = polygon_edges(xs, ys)
    quads, stats = rasterize(level, edges, [1, 1, 6, 6], [0, 0, 64, 64])
    got = decode(quads)
    want = {(x, y): 1 for x in range(1, 6) for y in range(1, 6) if x + y <= 5}
    assert got == want
    assert stats[3] == len(quads) and stats[:3] == (0, 0, 1)


@pytest.mark.parametrize("level", LEVELS)
def test_hand_worked_triangle_over_nine_blocks(level):
    # The right triangle (0, 0), (20, 0), (0, 20) meets 3x3 blocks (the masked walk). The centre
    # (x + 1/2, y + 1/2) is inside when x + y < 19; x + y == 19 lies on the up-left hypotenuse,
    # excluded. Per block, the smallest and largest x + y: (0, 0) 0..14, accepted (16 full quads,
    # rows bottom-up); (8, 0), (0, 8) 8..22, (16, 0), (0, 16) 16..26, (8, 8) 16..30: partial;
    # (16, 8), (8, 16) 24.., (16, 16) 32..: rejected. Quads (2i, 2j) with a covered pixel: i + j <= 9,
    # 55 of them.
    edges = triangle([(0, 0), (20, 0), (0, 20)])
    quads, stats = rasterize(level, edges, [0, 0, 20, 20], [0, 0, 64, 64])
    assert decode(quads) == {(x, y): 1 for x in range(20) for y in range(20) if x + y <= 18}
    assert stats == (3, 1, 5, 55)
    first = [(signed(x), signed(y), c) for x, y, c in quads[:16].tolist()]
    assert first == [(x, y, 0x0001_0001_0001_0001) for y in range(0, 8, 2) for x in range(0, 8, 2)]
