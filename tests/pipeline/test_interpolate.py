"""Varying interpolation (cpp/softgl/pipeline/interpolate.h) gives the same bits at every
instruction-set level (scalar, SSE2, AVX2 and AVX-512 where the CPU has them), and those bits are the header's
float64 formula evaluated independently here with numpy, lane by lane:

    fx, fy = pixel centre - origin (pixels)
    q   = 1 / (inv_w.c + inv_w.a * fx + inv_w.b * fy)
    w_k = (weight_k.c + weight_k.a * fx + weight_k.b * fy) * q
    out = float32(((0 + w_0 v_0) + w_1 v_1) + w_2 v_2)            (lines: two terms)

The SIMD levels compute q once per primitive when inv_w is constant (all vertices have the same
w); the cases below include such planes, with c of both signs, and c = +-0 (infinite q), where
that shortcut must not be taken.
"""
import numpy as np
import pytest

from softgl import _core

SUB = 256


def reference(planes, ox, oy, quads, values):
    x = (quads[:, 0:1] + np.array([0, 1, 0, 1])).ravel().astype(np.int64)
    y = (quads[:, 1:2] + np.array([0, 0, 1, 1])).ravel().astype(np.int64)
    fx = (x * SUB + SUB // 2 - ox).astype(np.float64) * (1.0 / SUB)
    fy = (y * SUB + SUB // 2 - oy).astype(np.float64) * (1.0 / SUB)
    ev = lambda k: (planes[k, 2] + planes[k, 0] * fx) + planes[k, 1] * fy
    with np.errstate(all="ignore"):
        q = 1.0 / ev(3)
        w = [ev(k) * q for k in range(len(values))]
        v = values.astype(np.float64)
        s = (0.0 + w[0][None, :] * v[0][:, None]) + w[1][None, :] * v[1][:, None]
        if len(values) == 3:
            s = s + w[2][None, :] * v[2][:, None]
        return s.astype(np.float32)


def same_bits(got, want, msg):
    nan = np.isnan(want)
    np.testing.assert_array_equal(np.isnan(got), nan, err_msg=msg)
    np.testing.assert_array_equal(got.view(np.uint32)[~nan], want.view(np.uint32)[~nan], err_msg=msg)


def check(planes, ox, oy, quads, values):
    planes = np.asarray(planes, np.float64)
    quads = np.asarray(quads, np.int32)
    values = np.asarray(values, np.float32)
    want = reference(planes, ox, oy, quads, values)
    levels = range(_core.testing.simd_level() + 1)
    got = [_core.testing.interpolate_varyings(level, planes, ox, oy, quads, values) for level in levels]
    for level, g in zip(levels, got):
        same_bits(g, want, f"simd level {level}")
        np.testing.assert_array_equal(g.view(np.uint32), got[0].view(np.uint32))


def random_case(rng, n, vertices, constant_w, inv_w_c=None):
    planes = rng.normal(0, 1, (4, 3)) * np.array([1e-2, 1e-2, 1.0])
    if constant_w:
        planes[3, :2] = 0.0
        planes[3, 2] = rng.uniform(0.05, 3.0) * rng.choice([-1, 1]) if inv_w_c is None else inv_w_c
    else:
        planes[3, 2] = rng.uniform(0.5, 2.0)
        planes[3, :2] = rng.normal(0, 1e-3, 2)
    quads = rng.integers(-2000, 2000, (n, 2)) * 2
    ox, oy = (int(v) for v in rng.integers(-2000 * SUB, 2000 * SUB, 2))
    values = rng.normal(0, 10, (vertices, 7)).astype(np.float32)
    return planes, ox, oy, quads, values


@pytest.mark.parametrize("vertices", [3, 2])
@pytest.mark.parametrize("constant_w", [False, True])
def test_levels_match_the_float64_formula(vertices, constant_w):
    rng = np.random.default_rng(5 + vertices + 10 * constant_w)
    for n in [1, 2, 3, 17, 32]:
        for _ in range(20):
            check(*random_case(rng, n, vertices, constant_w))


@pytest.mark.parametrize("c", [0.0, -0.0, 1e-300, -1e-300, 1e300, np.inf, -np.inf, np.nan])
@pytest.mark.parametrize("vertices", [3, 2])
def test_constant_inv_w_extremes(c, vertices):
    # +-0: q is +-inf in every lane (the sign from c + 0*fx + 0*fy); inf and NaN: q is 0 or NaN.
    rng = np.random.default_rng(9)
    check(*random_case(rng, 9, vertices, True, inv_w_c=c))


def test_negative_zero_values_give_positive_zero():
    # The sum starts from +0: (0 + w*(-0)) is +0, so all-negative-zero values give +0, not -0.
    planes = np.array([[0, 0, 0.25], [0, 0, 0.25], [0, 0, 0.5], [0, 0, 1.0]])
    values = np.full((3, 2), -0.0, np.float32)
    out = _core.testing.interpolate_varyings(0, planes, 0, 0, np.array([[0, 0]]), values)
    assert not np.signbit(out).any()
    check(planes, 0, 0, [[0, 0], [4, 6]], values)


@pytest.mark.parametrize("vertices", [3, 2])
@pytest.mark.parametrize("constant_w", [False, True])
def test_quads_in_raster_order(vertices, constant_w):
    # The AVX2 level reuses per-row and per-column partial terms between quads: quads of 8x8 blocks
    # row by row (rows and columns repeating, within and across runs of 32 quads), then columns 16
    # apart (sharing a table slot) and negative coordinates, alternating rows.
    rng = np.random.default_rng(21 + vertices + 10 * constant_w)
    blocks = [(bx, by) for by in (-8, 0, 8) for bx in (-16, -8, 0, 8)]
    raster = [(bx + qx, by + qy) for bx, by in blocks for qy in range(0, 8, 2) for qx in range(0, 8, 2)]
    colliding = [(x, y) for y in (-6, 4, -6, 4) for x in (-34, -18, -2, 14, 30, -2, -34)]
    for quads in (raster, colliding, colliding + raster[:40] + colliding):
        for _ in range(5):
            planes, ox, oy, _, values = random_case(rng, 1, vertices, constant_w)
            check(planes, ox, oy, quads, values)


def raster_quads(n, start=0):
    # 8x8-pixel blocks of 4x4 quads, row by row, blocks left to right then up: the rasterizer's order.
    blocks = [(bx, by) for by in range(-16, 48, 8) for bx in range(-24, 40, 8)]
    quads = [(bx + qx, by + qy) for bx, by in blocks for qy in range(0, 8, 2) for qx in range(0, 8, 2)]
    return quads[start:start + n]


@pytest.mark.parametrize("vertices", [3, 2])
@pytest.mark.parametrize("constant_w", [False, True])
def test_every_run_length(vertices, constant_w):
    # The AVX-512 level takes quads two at a time in runs of 32: odd counts leave a lone last quad
    # (in every run), and starting mid-row makes pairs straddle rows and blocks.
    rng = np.random.default_rng(40 + vertices + 10 * constant_w)
    for n in list(range(1, 18)) + [31, 33, 63, 65, 97]:
        for start in (0, 1, 3):
            planes, ox, oy, _, values = random_case(rng, 1, vertices, constant_w)
            check(planes, ox, oy, raster_quads(n, start), values)


SPECIAL = np.array([np.nan, np.inf, -np.inf, 1e-45, -1e-40, 1.17e-38, 3.4e38, -3.4e38, -0.0, 0.0, 1.0, -2.5],
                   np.float32)


@pytest.mark.parametrize("vertices", [3, 2])
@pytest.mark.parametrize("constant_w", [False, True])
def test_special_vertex_values(vertices, constant_w):
    # NaN, infinities, denormals and float extremes as vertex values, one of them per vertex and
    # word, so sums meet inf - inf, 0 * inf and overflow in every lane position.
    rng = np.random.default_rng(60 + vertices + 10 * constant_w)
    for n in (1, 2, 5, 16):
        for _ in range(6):
            planes, ox, oy, _, _ = random_case(rng, 1, vertices, constant_w)
            values = rng.choice(SPECIAL, (vertices, 9))
            check(planes, ox, oy, raster_quads(n, int(rng.integers(0, 8))), values)


@pytest.mark.parametrize("vertices", [3, 2])
@pytest.mark.parametrize("constant_w", [False, True])
def test_extreme_planes_and_offsets(vertices, constant_w):
    # Pixel offsets near 2^40 pixels (far beyond float precision of the terms), denormal and huge
    # plane coefficients, and non-finite ones: every lane must still round the same way.
    rng = np.random.default_rng(80 + vertices + 10 * constant_w)
    for scale in (1e-310, 1e-3, 1e150, 1e300):
        for _ in range(4):
            planes, _, _, _, values = random_case(rng, 1, vertices, constant_w)
            planes[:vertices, :2] *= scale
            if not constant_w:
                planes[3, :2] *= scale
            ox, oy = (int(v) for v in rng.integers(-(1 << 48), 1 << 48, 2))
            quads = rng.integers(-(1 << 29), 1 << 29, (int(rng.integers(1, 12)), 2)) * 2
            check(planes, ox, oy, quads, values)
    planes, ox, oy, quads, values = random_case(rng, 7, vertices, constant_w)
    for k, a, v in [(0, 0, np.nan), (1, 1, np.inf), (3, 0, np.inf), (3, 1, -np.inf), (3, 2, np.nan)]:
        p = planes.copy()
        p[k, a] = v
        check(p, ox, oy, quads, values)


@pytest.mark.parametrize("inv_w_c", [1.0, 2.0, 0.5, 3.0, -1.0])
@pytest.mark.parametrize("vertices", [3, 2])
def test_constant_w_every_word_count(inv_w_c, vertices):
    # w = 1 at every vertex (2D draws) gives q = 1 exactly, which the AVX-512 level does not
    # multiply by; other constant w give q = 2, 0.5 (exact), 1/3 (rounded) and -1. 1 to 9 words.
    rng = np.random.default_rng(100 + vertices + int(10 * inv_w_c))
    for words in range(1, 10):
        for n, start in ((1, 0), (7, 3), (32, 0), (33, 1)):
            planes, ox, oy, _, _ = random_case(rng, 1, vertices, True, inv_w_c=inv_w_c)
            values = rng.normal(0, 10, (vertices, words)).astype(np.float32)
            check(planes, ox, oy, raster_quads(n, start), values)


@pytest.mark.parametrize("vertices", [3, 2])
def test_unit_w_special_weights_and_values(vertices):
    # q = 1: the weights are the plane values themselves, so they must keep -0, infinities, NaN and
    # denormals exactly as e * 1 would. When two NaNs of different bits meet, which one a sum keeps
    # depends on the compiler's operand order (the levels may differ), so each case has one kind of
    # NaN: the default NaN of inf - inf and 0 * inf, or one NaN input coefficient with finite values.
    rng = np.random.default_rng(120 + vertices)
    special = [0.0, -0.0, 1e-310, -4e-320, 1e-300, 1e300, np.inf, -np.inf, 1.0, -3.5]
    finite_values = SPECIAL[np.isfinite(SPECIAL)]
    not_nan_values = SPECIAL[~np.isnan(SPECIAL)]
    for it in range(80):
        planes, ox, oy, _, _ = random_case(rng, 1, vertices, True, inv_w_c=1.0)
        words = int(rng.integers(1, 10))
        if it % 2:
            planes[:vertices] = rng.choice(special, (vertices, 3))
            values = rng.choice(not_nan_values, (vertices, words))
        else:
            planes[int(rng.integers(0, vertices)), int(rng.integers(0, 3))] = np.nan
            values = rng.choice(finite_values, (vertices, words))
        quads = raster_quads(int(rng.integers(1, 20)), int(rng.integers(0, 8)))
        check(planes, ox, oy, quads, values)
    # Zero weights whose sign follows the offsets' (c = -0, a = b = +0: -0 + (+-0) + (+-0)).
    planes = np.array([[0.0, 0.0, -0.0]] * 3 + [[0.0, 0.0, 1.0]])
    values = np.array([[-0.0, 1e-45], [-1e-40, 3.4e38], [-2.5, 1.0]][:vertices], np.float32)
    check(planes, -300, 500, [[-2, -2], [0, 0], [2, 4]], values)
