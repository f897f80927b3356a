"""The single-sample early depth test (cpp/softgl/pipeline/early_depth.h) gives the same
survivors, kill count and depth buffer at every instruction-set level (scalar through the
definitions depth_at / depth_word / compare; AVX2 a quad at a time where the CPU has it, also at
the AVX-512 level), and
those equal an independent float64 evaluation here: ES 3.0 §4.1.6 with the window depth
z = clamp((c + a*fx + b*fy) + offset) stored as floor(z * (2^24 - 1) + 0.5) (NaN -> 0).

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


def reference(plane, offset, ox, oy, sample, func, write, quads, depth):
    depth = depth.copy()
    survived = np.zeros((len(quads), 4), np.uint16)
    killed = 0
    for i, (qx, qy, cov) in enumerate(quads):
        for j in range(4):
            if not (int(cov) >> (16 * j)) & 1:
                continue
            x, y = qx + (j & 1), qy + (j >> 1)
            fx = float(x * SUB + sample[0] - ox) * (1.0 / SUB)
            fy = float(y * SUB + sample[1] - oy) * (1.0 / SUB)
            z = word(np.float64((plane[2] + plane[0] * fx) + plane[1] * fy) + offset)
            if passes(func, z, depth[y, x]):
                if write:
                    depth[y, x] = z
                survived[i, j] = 1
            else:
                killed += 1
    return survived, killed, depth


def random_quads(rng, n):
    quads = []
    for _ in range(n):
        x, y = 2 * rng.integers(0, (W + 1) // 2), 2 * rng.integers(0, (H + 1) // 2)
        cov = 0
        for j in range(4):
            inside = x + (j & 1) < W and y + (j >> 1) < H
            if inside and rng.random() < 0.8:
                cov |= 1 << (16 * j)
        quads.append((x, y, cov))
    return np.array(quads, np.int64)


def check(rng, func, write, plane, offset=0.0, quads=None, origin=None):
    ox, oy = (int(v) for v in rng.integers(-40 * SUB, 40 * SUB, 2)) if origin is None else origin
    sample = (128, 128) if rng.random() < 0.7 else tuple(int(v) for v in rng.integers(0, SUB, 2))
    quads = random_quads(rng, int(rng.integers(1, 40))) if quads is None else quads
    depth = rng.integers(0, 1 << 24, (H, W)).astype(np.uint32)
    depth[rng.random((H, W)) < 0.05] = 0xFFFFFFFF   # beyond 24 bits: the comparison is unsigned
    # Some stored values equal to the incoming word, so EQUAL and friends see ties.
    _, _, exact = reference(plane, offset, ox, oy, sample, "ALWAYS", True, quads, depth)
    ties = rng.random((H, W)) < 0.3
    depth[ties] = exact[ties]
    want = reference(plane, offset, ox, oy, sample, func, write, quads, depth)
    for level in range(_core.testing.simd_level() + 1):
        got = _core.testing.early_depth_test(level, plane, offset, ox, oy, sample, getattr(softgl, func), write,
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
