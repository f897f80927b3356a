"""The early depth test (cpp/softgl/pipeline/early_depth.h) gives the same survivors, kill count
and depth buffer at every instruction-set level (scalar through the definitions depth_at /
depth_word / compare; one sample per pixel: AVX2 and AVX-512 rows of up to four side-by-side
quads, a lone quad at a time; four samples: AVX2 a pixel's samples, AVX-512 a quad's pixel row), and those
equal an independent float64 evaluation here: ES 3.0 §4.1.6 with the window depth
z = clamp((c + a*fx + b*fy) + offset) at each sample's position, stored as
floor(z * (2^24 - 1) + 0.5) (NaN -> 0).

Buffers have odd sizes, so quads on the right and top border have pixels outside the buffer
(never covered): the kernels must neither read nor write them.
"""
import numpy as np
import pytest

import softgl
from softgl import _core

SUB = 256
FUNCS = ["NEVER", "LESS", "EQUAL", "LEQUAL", "GREATER", "NOTEQUAL", "GEQUAL", "ALWAYS"]
W, H = 37, 29


def word(z):
    with np.errstate(invalid="ignore"):
        z = np.where(z < 0, 0.0, np.where(z > 1, 1.0, z))   # depth_at's clamp (NaN stays)
        d = np.where(np.isnan(z), 0.0, np.clip(z, 0.0, 1.0))
    return np.floor(d * 16777215.0 + 0.5).astype(np.uint32)


def passes(func, z, stored):
    z, stored = int(z), int(stored)
    return {"NEVER": False, "LESS": z < stored, "EQUAL": z == stored, "LEQUAL": z <= stored,
            "GREATER": z > stored, "NOTEQUAL": z != stored, "GEQUAL": z >= stored, "ALWAYS": True}[func]


def reference(plane, offset, ox, oy, samples, func, write, quads, depth):
    # depth (h, w, len(samples)); survived: the passing samples' mask per pixel.
    depth = depth.copy()
    survived = np.zeros((len(quads), 4), np.uint16)
    killed = 0
    for i, (qx, qy, cov) in enumerate(quads):
        for j in range(4):
            x, y = qx + (j & 1), qy + (j >> 1)
            for s, (sx, sy) in enumerate(samples):
                if not (int(cov) >> (16 * j + s)) & 1:
                    continue
                fx = float(x * SUB + sx - ox) * (1.0 / SUB)
                fy = float(y * SUB + sy - oy) * (1.0 / SUB)
                z = word(np.float64((plane[2] + plane[0] * fx) + plane[1] * fy) + offset)
                if passes(func, z, depth[y, x, s]):
                    if write:
                        depth[y, x, s] = z
                    survived[i, j] |= 1 << s
                else:
                    killed += 1
    return survived, killed, depth


def random_quads(rng, n, samples=1):
    # Pixels covered with probability 0.8; of a covered pixel with several samples, each sample
    # with probability 0.8 (bits above the sample count stay clear, as the rasterizer leaves them).
    quads = []
    for _ in range(n):
        x, y = 2 * rng.integers(0, (W + 1) // 2), 2 * rng.integers(0, (H + 1) // 2)
        cov = 0
        for j in range(4):
            inside = x + (j & 1) < W and y + (j >> 1) < H
            if inside and rng.random() < 0.8:
                bits = 1 if samples == 1 else sum(1 << s for s in range(samples) if rng.random() < 0.8)
                cov |= bits << (16 * j)
        quads.append((x, y, cov - (1 << 64) if cov >> 63 else cov))   # the coverage's 64 bits as int64
    return np.array(quads, np.int64).reshape(-1, 3)


def random_stored(rng, exact):
    # Random words, some beyond 24 bits (the comparison is unsigned), 30% equal to the incoming
    # word so EQUAL and friends see ties.
    depth = rng.integers(0, 1 << 24, exact.shape).astype(np.uint32)
    depth[rng.random(exact.shape) < 0.05] = 0xFFFFFFFF
    ties = rng.random(exact.shape) < 0.3
    depth[ties] = exact[ties]
    return depth


# The 4x pattern as the rasterizer samples it (D3D's standard positions, 1/256 pixel).
PATTERN_4X = [(96, 32), (224, 96), (32, 160), (160, 224)]


def random_samples(rng, count):
    # One sample: the pixel centre or anywhere; four: mostly the 4x pattern; else anywhere.
    if count == 4 and rng.random() < 0.7:
        return PATTERN_4X
    if count == 1 and rng.random() < 0.7:
        return [(128, 128)]
    return [tuple(int(v) for v in rng.integers(0, SUB, 2)) for _ in range(count)]


def check(rng, func, write, plane, offset=0.0, quads=None, origin=None, size=(W, H), stored=random_stored, samples=1):
    ox, oy = (int(v) for v in rng.integers(-40 * SUB, 40 * SUB, 2)) if origin is None else origin
    positions = random_samples(rng, samples)
    quads = random_quads(rng, int(rng.integers(1, 40)), samples) if quads is None else quads
    depth = np.zeros(size[::-1] + (samples,), np.uint32)
    _, _, exact = reference(plane, offset, ox, oy, positions, "ALWAYS", True, quads, depth)
    depth = stored(rng, exact)
    want = reference(plane, offset, ox, oy, positions, func, write, quads, depth)
    for level in range(_core.testing.simd_level() + 1):
        got = _core.testing.early_depth_test(level, plane, offset, ox, oy, positions, getattr(softgl, func), write,
                                             quads, depth)
        np.testing.assert_array_equal(got[0], want[0], err_msg=f"survived, simd level {level}")
        assert got[1] == want[1], f"killed, simd level {level}"
        np.testing.assert_array_equal(got[2], want[2], err_msg=f"depth buffer, simd level {level}")


@pytest.mark.parametrize("func", FUNCS)
@pytest.mark.parametrize("write", [True, False])
def test_levels_match_the_float64_definition(func, write):
    rng = np.random.default_rng(FUNCS.index(func) + 10 * write)
    for _ in range(15):
        # Depth planes crossing 0 and 1 inside the buffer: both clamps are exercised.
        plane = (rng.normal(0, 0.05), rng.normal(0, 0.05), rng.uniform(-0.5, 1.5))
        check(rng, func, write, plane, offset=float(rng.choice([0.0, 1e-7, -3e-3])))


@pytest.mark.parametrize("c", [np.nan, np.inf, -np.inf, -0.0, 0.0, 1.0])
def test_special_depths(c):
    # NaN depth is stored as 0; +-inf clamp to 1 and 0; -0 is 0.
    rng = np.random.default_rng(3)
    for func in FUNCS:
        check(rng, func, True, (0.0, 0.0, c))


def raster_quads(rng, n, start):
    # Distinct quads in raster order (rows of the buffer's quads), partly covered at random, some
    # not at all; pixels outside the buffer never.
    quads = random_quads(rng, 0).tolist()
    for y in range(0, H + 1, 2):
        for x in range(0, W + 1, 2):
            cov = 0
            for j in range(4):
                if x + (j & 1) < W and y + (j >> 1) < H and rng.random() < 0.85:
                    cov |= 1 << (16 * j)
            quads.append((x, y, cov))
    return np.array(quads[start:start + n], np.int64).reshape(-1, 3)


@pytest.mark.parametrize("func", ["LESS", "EQUAL", "GEQUAL"])
def test_every_run_length(func):
    # Every count 1..17 of distinct quads in raster order, starting at a row's start, mid-row and
    # near the buffer's top border (a kernel taking several quads at once must handle every tail).
    rng = np.random.default_rng(30 + FUNCS.index(func))
    for n in range(1, 18):
        for start in (0, 1, 18 * 7 - 3):
            plane = (rng.normal(0, 0.05), rng.normal(0, 0.05), rng.uniform(-0.2, 1.2))
            check(rng, func, True, plane, quads=raster_quads(rng, n, start))


@pytest.mark.parametrize("func", ["LESS", "GEQUAL"])
def test_rows_left_and_revisited(func):
    # Runs of quads on one row, then another row, then the first again (as a block's quad rows and
    # the next block's follow each other): a kernel that keeps a row's terms between quads must
    # take them afresh whenever the row changes, including back to an earlier one.
    rng = np.random.default_rng(90 + FUNCS.index(func))
    for _ in range(8):
        rows = [int(y) for y in 2 * rng.integers(0, (H + 1) // 2, 4)]
        quads = []
        for y in (rows[0], rows[1], rows[0], rows[2], rows[3], rows[2], rows[0]):
            for x in 2 * rng.choice((W + 1) // 2, int(rng.integers(1, 6)), replace=False):
                cov = sum(1 << (16 * j) for j in range(4)
                          if x + (j & 1) < W and y + (j >> 1) < H and rng.random() < 0.9)
                quads.append((int(x), y, cov))
        plane = (rng.normal(0, 0.05), rng.normal(0, 0.05), rng.uniform(0, 1))
        check(rng, func, True, plane, quads=np.array(quads, np.int64).reshape(-1, 3))


@pytest.mark.parametrize("func", ["LESS", "ALWAYS", "NOTEQUAL"])
def test_repeated_quads(func):
    # Not from one primitive, but allowed: a quad tested again right after itself sees its own
    # writes, as in pixel order (a kernel testing neighbouring quads at once must not read early).
    rng = np.random.default_rng(50 + FUNCS.index(func))
    for _ in range(10):
        quads = np.repeat(random_quads(rng, int(rng.integers(1, 9))), rng.integers(1, 4), axis=0)
        plane = (rng.normal(0, 0.05), rng.normal(0, 0.05), rng.uniform(0, 1))
        check(rng, func, True, plane, offset=float(rng.choice([0.0, -1e-3])), quads=quads)


def test_huge_offsets():
    # Plane origins far from the pixels (2^40 pixels): the offsets lose precision the same way.
    rng = np.random.default_rng(70)
    for func in FUNCS:
        for _ in range(3):
            plane = (rng.normal(0, 1e-12), rng.normal(0, 1e-12), rng.uniform(0, 1))
            origin = tuple(int(v) for v in rng.integers(-(1 << 48), 1 << 48, 2))
            check(rng, func, True, plane, origin=origin)


def full_quad_rows(rng, size, rows):
    # Runs of fully covered quads along quad-rows, as the rasterizer emits covered blocks: each
    # row (y, x0, count) is `count` quads at x0, x0 + 2, ... Some quads lose a pixel (a broken run).
    w, h = size
    quads = []
    for y, x0, count in rows:
        for x in range(x0, x0 + 2 * count, 2):
            cov = 0
            for j in range(4):
                if x + (j & 1) < w and y + (j >> 1) < h:
                    cov |= 1 << (16 * j)
            if rng.random() < 0.08:
                cov &= ~(1 << (16 * int(rng.integers(0, 4))))
            quads.append((x, y, cov))
    return np.array(quads, np.int64).reshape(-1, 3)


def stored_by_region(rng, exact):
    # Every 8x2 pixel region (a row of four quads) of the stored buffer below, equal to or above
    # the incoming words, random, or a per-pixel mix: whole runs pass, fail or split.
    depth = exact.astype(np.int64)
    h, w = exact.shape[:2]
    for y in range(0, h, 2):
        for x in range(0, w, 8):
            region = (slice(y, y + 2), slice(x, x + 8))
            mode = rng.integers(0, 5)
            if mode < 3:
                depth[region] += int(mode) - 1
            elif mode == 3:
                depth[region] = rng.integers(0, 1 << 24, depth[region].shape)
            else:
                depth[region] += rng.integers(-1, 2, depth[region].shape)
    return np.clip(depth, 0, 0xFFFFFFFF).astype(np.uint32)


@pytest.mark.parametrize("func", FUNCS)
@pytest.mark.parametrize("write", [True, False])
def test_runs_of_full_quads(func, write):
    # Rows of 1..20 side-by-side full quads (a 43x21 buffer: the last quad of a row and the top
    # quad-row stick out), starting at any even x, also several rows in a row and rows that repeat.
    size = (43, 21)
    rng = np.random.default_rng(90 + FUNCS.index(func) + 10 * write)
    for count in range(1, 21):
        x0 = 2 * int(rng.integers(0, 23 - count))
        rows = [(2 * int(rng.integers(0, 11)), x0, count)]
        if rng.random() < 0.5:   # the next quad-row, or the same row again (it sees its own writes)
            rows.append((rows[0][0] + 2 * int(rng.integers(0, 2)) if rows[0][0] < 20 else 0, x0, count))
        plane = (rng.normal(0, 0.05), rng.normal(0, 0.05), rng.uniform(-0.2, 1.2))
        stored = stored_by_region if rng.random() < 0.7 else random_stored
        check(rng, func, write, plane, offset=float(rng.choice([0.0, -1e-3])), quads=full_quad_rows(rng, size, rows),
              size=size, stored=stored)


@pytest.mark.parametrize("c", [np.nan, np.inf, -np.inf, -0.0, 0.5, 2.0])
def test_runs_of_full_quads_special_planes(c):
    # Flat planes (a = b = 0) and planes that are NaN or infinite across whole runs, and steep
    # ones clamped to 0 and 1 inside a run.
    size = (43, 21)
    rng = np.random.default_rng(110)
    rows = [(y, 0, 22) for y in range(0, 22, 2)]
    for func in FUNCS:
        for plane in [(0.0, 0.0, c), (c, 0.0, 0.5), (0.0, c, 0.5), (0.3, -0.2, c if np.isfinite(c) else 0.5)]:
            check(rng, func, True, plane, quads=full_quad_rows(rng, size, rows), size=size, stored=stored_by_region)


def test_runs_of_full_quads_huge_offsets():
    rng = np.random.default_rng(120)
    size = (43, 21)
    for func in FUNCS:
        plane = (rng.normal(0, 1e-12), rng.normal(0, 1e-12), rng.uniform(0, 1))
        origin = tuple(int(v) for v in rng.integers(-(1 << 48), 1 << 48, 2))
        rows = [(2 * int(rng.integers(0, 11)), 2 * int(rng.integers(0, 10)), int(rng.integers(1, 12))) for _ in range(4)]
        check(rng, func, True, plane, origin=origin, quads=full_quad_rows(rng, size, rows), size=size,
              stored=stored_by_region)


@pytest.mark.parametrize("func", ["LESS", "EQUAL", "GEQUAL", "NOTEQUAL"])
def test_flat_planes(func):
    # Flat planes (a and b zeros of either sign) give every pixel one word; with any offset, any
    # sample position, plane origins near and far, whole runs and scattered quads, and the
    # stored words around that word (ties, one above, one below).
    size = (43, 21)
    rng = np.random.default_rng(130 + FUNCS.index(func))
    rows = [(y, 0, 22) for y in range(0, 22, 2)]
    for c in [0.0, -0.0, 5e-324, 1e-9, 0.3, 0.5 / 16777215, 1 - 1e-17, 1.0, 1.5, np.nan, np.inf, -np.inf, -0.25]:
        for offset in [0.0, -0.0, 1e-7, -3e-3, 2.0]:
            a, b = (float(v) for v in rng.choice([0.0, -0.0], 2))
            origin = None if rng.random() < 0.7 else tuple(int(v) for v in rng.integers(-(1 << 48), 1 << 48, 2))
            quads = full_quad_rows(rng, size, rows) if rng.random() < 0.6 else None
            check(rng, func, bool(rng.random() < 0.8), (a, b, c), offset=offset, quads=quads, origin=origin,
                  size=size if quads is not None else (W, H), stored=stored_by_region if quads is not None else random_stored)


def test_almost_runs():
    # Four quads that are nearly a row of full side-by-side quads: one quad shifted by a quad in
    # x or y, or missing sample 0 of one pixel while its other samples' bits are set, next to
    # runs whose quads carry such extra sample bits. Every pixel still gets its own word.
    size = (43, 21)
    rng = np.random.default_rng(140)
    for func in FUNCS:
        for _ in range(12):
            x0, y0 = 2 * int(rng.integers(0, 16)), 2 * int(rng.integers(0, 9))
            quads = [[x0 + 2 * q, y0, 0] for q in range(4)]
            for quad in quads:
                for j in range(4):
                    quad[2] |= (int(rng.integers(0, 1 << 15)) | 1) << (16 * j)   # sample 0 and others
            q, kind = int(rng.integers(0, 4)), int(rng.integers(0, 4))
            if kind == 0:   # a gap before the last quad, or after the first
                if q == 0 and x0 >= 2:
                    quads[0][0] -= 2
                else:
                    quads[3][0] += 2
            elif kind == 1:
                quads[q][1] += 2
            elif kind == 2:
                quads[q][2] &= ~(1 << (16 * int(rng.integers(0, 4))))
            quads = np.array([qd for qd in quads if qd[0] + 1 < size[0] and qd[1] + 1 < size[1]], np.int64).reshape(-1, 3)
            plane = (rng.normal(0, 0.05), rng.normal(0, 0.05), rng.uniform(-0.2, 1.2))
            check(rng, func, True, plane, quads=quads, size=size, stored=stored_by_region)


@pytest.mark.parametrize("func", FUNCS)
@pytest.mark.parametrize("write", [True, False])
@pytest.mark.parametrize("samples", [4, 2, 8, 16])
def test_multisample_levels_match_the_float64_definition(func, write, samples):
    # Every covered sample of a pixel tested at its own position (MSAA 4x has its own AVX-512
    # kernel; other counts run the scalar level), with partial sample masks and repeated quads.
    rng = np.random.default_rng(200 + FUNCS.index(func) + 10 * write + samples)
    for _ in range(8 if samples == 4 else 2):
        plane = (rng.normal(0, 0.05), rng.normal(0, 0.05), rng.uniform(-0.5, 1.5))
        quads = random_quads(rng, int(rng.integers(1, 40)), samples)
        if rng.random() < 0.3:
            quads = np.repeat(quads, rng.integers(1, 3), axis=0)
        check(rng, func, write, plane, offset=float(rng.choice([0.0, 1e-7, -3e-3])), quads=quads, samples=samples)


@pytest.mark.parametrize("c", [np.nan, np.inf, -np.inf, -0.0, 0.0, 1.0])
def test_multisample_special_depths_and_huge_offsets(c):
    rng = np.random.default_rng(240)
    for func in FUNCS:
        check(rng, func, True, (0.0, 0.0, c), samples=4)
        check(rng, func, True, (0.3, -0.2, c), samples=4)
        plane = (rng.normal(0, 1e-12), rng.normal(0, 1e-12), rng.uniform(0, 1))
        origin = tuple(int(v) for v in rng.integers(-(1 << 48), 1 << 48, 2))
        check(rng, func, True, plane, origin=origin, samples=4)


@pytest.mark.parametrize("func", ["LESS", "LEQUAL", "GREATER", "NOTEQUAL"])
@pytest.mark.parametrize("write", [True, False])
def test_partly_covered_runs(func, write):
    # Runs of 2..4 side-by-side quads with pixels left out (the rows of small primitives), ending
    # at the buffer's right and top border (their outside pixels are never covered and must be
    # neither read nor written), pixels whose sample 0 is clear but other sample bits are set
    # (uncovered with one sample), then a lone quad or another run on the next quad-row: each
    # run's entries of `survived` and no others.
    size = (43, 21)
    rng = np.random.default_rng(150 + FUNCS.index(func) + 10 * write)
    for _ in range(40):
        quads = []
        for _ in range(int(rng.integers(1, 5))):
            count = int(rng.integers(1, 5))
            y = 2 * int(rng.integers(0, 11))
            x0 = 2 * int(rng.integers(0, 22 - count + 1)) if rng.random() < 0.6 else 44 - 2 * count
            for x in range(x0, x0 + 2 * count, 2):
                cov = 0
                for j in range(4):
                    if x + (j & 1) < size[0] and y + (j >> 1) < size[1] and rng.random() < 0.6:
                        cov |= 1 << (16 * j)
                    if rng.random() < 0.2:
                        cov |= int(rng.integers(1, 1 << 15)) << (16 * j + 1)   # bits above sample 0
                quads.append((x, y, cov - (1 << 64) if cov >> 63 else cov))
        plane = (rng.normal(0, 0.05), rng.normal(0, 0.05), rng.uniform(-0.2, 1.2))
        check(rng, func, write, plane, quads=np.array(quads, np.int64).reshape(-1, 3), size=size,
              stored=stored_by_region if rng.random() < 0.7 else random_stored)
