"""Varying interpolation (cpp/softgl/pipeline/interpolate.h).

1. Every instruction-set level (scalar, SSE2, AVX2, AVX-512 where the CPU has them) gives the bits
   of the header's float32 formula, evaluated independently here with numpy, lane by lane:

       planes moved in float64 to the base pixel's centre, then rounded to float32 (c, a, b)
       dx, dy = pixel - base (exact)
       q   = 1 / ((Q.c + Q.a dx) + Q.b dy)
       l_k = ((L_k.c + L_k.a dx) + L_k.b dy) q                  k = 1, 2
       out = (v_0 + l_1 d_1) + l_2 d_2                          (lines: two terms)
       d_k = v_k - v_0, or 0 where v_k == v_0 (infinities too)

   So does the pixel-by-pixel form (gathered single pixels), at every level, count and order.
   The SIMD levels compute q once per primitive when Q is constant (all vertices have the same w)
   and skip the multiply when that q is 1; the cases include such planes, with c of both signs,
   and c = +-0 (infinite q), where the shortcut must not be taken.
2. The values are accurate: against the exact perspective-correct value (float64, from the
   vertices' screen positions and w, not from softgl's planes) the error stays within a few float
   ulps of the vertex values' magnitude, and a value equal at every vertex comes out exactly.
"""
import numpy as np
import pytest

from softgl import _core

SUB = 256
f32 = np.float32


def reference(planes, ox, oy, quads, values, base):
    bx, by = base
    offset = lambda b, o: np.float64(b * SUB + SUB // 2 - o) * (1.0 / SUB)
    tx, ty = offset(bx, ox), offset(by, oy)
    rows = [1, 2] if len(values) == 3 else [1]
    with np.errstate(all="ignore"):
        def plane(k):
            a, b, c = planes[k]
            return f32(a), f32(b), f32((c + a * tx) + b * ty)
        wrap = lambda v: (v.astype(np.int64) + 2**31) % 2**32 - 2**31
        dx = wrap(quads[:, 0:1] + np.array([0, 1, 0, 1]) - bx).ravel().astype(f32)
        dy = wrap(quads[:, 1:2] + np.array([0, 0, 1, 1]) - by).ravel().astype(f32)

        def ev(k):
            a, b, c = plane(k)
            return (c + a * dx) + b * dy
        q = f32(1) / ev(3)
        v = values.astype(f32)
        d = [np.where(v[k] == v[0], f32(0), v[k] - v[0]) for k in range(len(values))]
        s = v[0][:, None] + (ev(rows[0]) * q)[None, :] * d[1][:, None]
        if len(values) == 3:
            s = s + (ev(rows[1]) * q)[None, :] * d[2][:, None]
        return s.astype(f32)


def interpolate(level, planes, ox, oy, quads, values, base=(0, 0)):
    return _core.testing.interpolate_varyings(level, planes, ox, oy, quads, values, base[0], base[1])


def same_bits(got, want, msg):
    nan = np.isnan(want)
    np.testing.assert_array_equal(np.isnan(got), nan, err_msg=msg)
    np.testing.assert_array_equal(got.view(np.uint32)[~nan], want.view(np.uint32)[~nan], err_msg=msg)


def check(planes, ox, oy, quads, values, base=(0, 0)):
    planes = np.asarray(planes, np.float64)
    quads = np.asarray(quads, np.int32)
    values = np.asarray(values, f32)
    want = reference(planes, ox, oy, quads, values, base)
    levels = range(_core.testing.simd_level() + 1)
    got = [interpolate(level, planes, ox, oy, quads, values, base) for level in levels]
    for level, g in zip(levels, got):
        same_bits(g, want, f"simd level {level}")
    # Pixel by pixel (interpolate_pixels_at): each pixel the bits of its lane in the quads, for
    # every count (the SIMD tails) and in any order.
    pixels = quad_pixels(quads)
    order = np.random.default_rng(len(pixels)).permutation(len(pixels))
    for level in levels:
        for m in sorted({len(pixels), max(len(pixels) - 1, 0), min(len(pixels), 9), min(len(pixels), 3)}):
            g = _core.testing.interpolate_pixels(level, planes, ox, oy, pixels[:m], values, base[0], base[1])
            same_bits(g, want[:, :m], f"pixels, simd level {level}, {m} pixels")
        g = _core.testing.interpolate_pixels(level, planes, ox, oy, pixels[order], values, base[0], base[1])
        same_bits(g, want[:, order], f"shuffled pixels, simd level {level}")


def quad_pixels(quads):
    """The pixels of the quads in lane order (lane 4*i + j: pixel j of quad i), (4n, 2) int32 with
    int32 wrapping as the lanes compute it."""
    dx, dy = np.array([0, 1, 0, 1]), np.array([0, 0, 1, 1])
    x = (quads[:, 0:1].astype(np.int64) + dx).ravel()
    y = (quads[:, 1:2].astype(np.int64) + dy).ravel()
    wrap = lambda v: ((v + 2**31) % 2**32 - 2**31).astype(np.int32)
    return np.stack([wrap(x), wrap(y)], 1)


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
    values = rng.normal(0, 10, (vertices, 7)).astype(f32)
    return planes, ox, oy, quads, values


def tile_base(quads):
    # The pipeline's base: the 64x64 tile corner of the quads.
    return tuple(int(v) for v in (np.asarray(quads)[0] // 64) * 64)


@pytest.mark.parametrize("vertices", [3, 2])
@pytest.mark.parametrize("constant_w", [False, True])
def test_levels_match_the_float32_formula(vertices, constant_w):
    rng = np.random.default_rng(5 + vertices + 10 * constant_w)
    for n in [1, 2, 3, 4, 5, 17, 32]:
        for _ in range(20):
            planes, ox, oy, quads, values = random_case(rng, n, vertices, constant_w)
            check(planes, ox, oy, quads, values, tile_base(quads))
            check(planes, ox, oy, quads, values, tuple(int(v) for v in rng.integers(-3000, 3000, 2)))


@pytest.mark.parametrize("c", [0.0, -0.0, 1e-300, -1e-300, 1e-40, 1e300, np.inf, -np.inf, np.nan])
@pytest.mark.parametrize("vertices", [3, 2])
def test_constant_inv_w_extremes(c, vertices):
    # +-0 (also 1e-300 and 1e-40, which round to float +-0 or a denormal): q is +-inf or huge in
    # every lane (the sign from c + 0*dx + 0*dy); inf and NaN: q is 0 or NaN.
    rng = np.random.default_rng(9)
    planes, ox, oy, quads, values = random_case(rng, 9, vertices, True, inv_w_c=c)
    check(planes, ox, oy, quads, values, tile_base(quads))


def test_negative_zero_values_give_positive_zero():
    # d = -0 - -0 = +0 and -0 + l * (+0) = +0: all-negative-zero values give +0, at every level.
    planes = np.array([[0, 0, 0.25], [0, 0, 0.25], [0, 0, 0.5], [0, 0, 1.0]])
    values = np.full((3, 2), -0.0, f32)
    out = interpolate(0, planes, 0, 0, np.array([[0, 0]]), values)
    assert not np.signbit(out).any()
    check(planes, 0, 0, [[0, 0], [4, 6]], values)


def raster_quads(n, start=0):
    # 8x8-pixel blocks of 4x4 quads, row by row, blocks left to right then up: the rasterizer's order.
    blocks = [(bx, by) for by in range(-16, 48, 8) for bx in range(-24, 40, 8)]
    quads = [(bx + qx, by + qy) for bx, by in blocks for qy in range(0, 8, 2) for qx in range(0, 8, 2)]
    return quads[start:start + n]


@pytest.mark.parametrize("vertices", [3, 2])
@pytest.mark.parametrize("constant_w", [False, True])
def test_every_run_length(vertices, constant_w):
    # AVX2 takes quads two at a time and AVX-512 four at a time: every remainder, starting mid-row
    # so that groups straddle rows and blocks.
    rng = np.random.default_rng(40 + vertices + 10 * constant_w)
    for n in list(range(1, 18)) + [31, 33, 63, 65, 97]:
        for start in (0, 1, 3):
            planes, ox, oy, _, values = random_case(rng, 1, vertices, constant_w)
            check(planes, ox, oy, raster_quads(n, start), values, (-64, 0))


SPECIAL = np.array([np.nan, np.inf, -np.inf, 1e-45, -1e-40, 1.17e-38, 3.4e38, -3.4e38, -0.0, 0.0, 1.0, -2.5], f32)


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
            check(planes, ox, oy, raster_quads(n, int(rng.integers(0, 8))), values, (0, -64))


@pytest.mark.parametrize("vertices", [3, 2])
@pytest.mark.parametrize("constant_w", [False, True])
def test_extreme_planes_and_offsets(vertices, constant_w):
    # Bases near 2^40 pixels from the origin, quads far from the base (offsets beyond float's exact
    # integers, wrapping int32), denormal, huge and non-finite plane coefficients: every lane must
    # still round the same way.
    rng = np.random.default_rng(80 + vertices + 10 * constant_w)
    for scale in (1e-310, 1e-3, 1e150, 1e300):
        for _ in range(4):
            planes, _, _, _, values = random_case(rng, 1, vertices, constant_w)
            planes[:3, :2] *= scale
            if not constant_w:
                planes[3, :2] *= scale
            ox, oy = (int(v) for v in rng.integers(-(1 << 48), 1 << 48, 2))
            quads = rng.integers(-(1 << 29), 1 << 29, (int(rng.integers(1, 12)), 2)) * 2
            base = tuple(int(v) for v in rng.integers(-(1 << 30), 1 << 30, 2))
            check(planes, ox, oy, quads, values, base)
    planes, ox, oy, quads, values = random_case(rng, 7, vertices, constant_w)
    for k, a, v in [(1, 0, np.nan), (1, 1, np.inf), (3, 0, np.inf), (3, 1, -np.inf), (3, 2, np.nan)]:
        p = planes.copy()
        p[k, a] = v
        check(p, ox, oy, quads, values, tile_base(quads))


@pytest.mark.parametrize("inv_w_c", [1.0, 2.0, 0.5, 3.0, -1.0])
@pytest.mark.parametrize("vertices", [3, 2])
def test_constant_w_every_word_count(inv_w_c, vertices):
    # w = 1 at every vertex (2D draws) gives q = 1 exactly, which the SIMD levels do not multiply
    # by; other constant w give q = 2, 0.5 (exact), 1/3 (rounded) and -1. 1 to 9 words.
    rng = np.random.default_rng(100 + vertices + int(10 * inv_w_c))
    for words in range(1, 10):
        for n, start in ((1, 0), (7, 3), (32, 0), (33, 1)):
            planes, ox, oy, _, _ = random_case(rng, 1, vertices, True, inv_w_c=inv_w_c)
            values = rng.normal(0, 10, (vertices, words)).astype(f32)
            check(planes, ox, oy, raster_quads(n, start), values, (-24, -16))


@pytest.mark.parametrize("vertices", [3, 2])
@pytest.mark.parametrize("constant_w", [False, True])
def test_small_word_counts(vertices, constant_w):
    # AVX2 holds the vertex values of up to eight words (a loop per count 1..8, the general loop
    # from 9): each count, with perspective and constant w, even and odd quad counts
    # (an odd count's last quad stores half a register), starting mid-row.
    rng = np.random.default_rng(140 + vertices + 10 * constant_w)
    for words in range(1, 10):
        for n, start in ((1, 0), (2, 1), (5, 3), (16, 0), (31, 2), (64, 0)):
            planes, ox, oy, _, _ = random_case(rng, 1, vertices, constant_w)
            values = rng.normal(0, 10, (vertices, words)).astype(f32)
            check(planes, ox, oy, raster_quads(n, start), values, (-24, -16))


@pytest.mark.parametrize("vertices", [3, 2])
def test_unit_w_special_weights_and_values(vertices):
    # q = 1: the weights are the plane values themselves, so they must keep -0, infinities, NaN and
    # denormals exactly as l * 1 would. When two NaNs of different bits meet, which one a sum keeps
    # depends on the compiler's operand order, so NaN bits are not compared (only NaN-ness).
    rng = np.random.default_rng(120 + vertices)
    special = [0.0, -0.0, 1e-310, -4e-320, 1e-300, 1e-42, 1e300, np.inf, -np.inf, 1.0, -3.5]
    finite_values = SPECIAL[np.isfinite(SPECIAL)]
    not_nan_values = SPECIAL[~np.isnan(SPECIAL)]
    for it in range(80):
        planes, ox, oy, _, _ = random_case(rng, 1, vertices, True, inv_w_c=1.0)
        words = int(rng.integers(1, 10))
        if it % 2:
            planes[1:vertices + 1] = rng.choice(special, (vertices, 3))
            values = rng.choice(not_nan_values, (vertices, words))
        else:
            planes[int(rng.integers(1, vertices + 1)), int(rng.integers(0, 3))] = np.nan
            values = rng.choice(finite_values, (vertices, words))
        quads = raster_quads(int(rng.integers(1, 20)), int(rng.integers(0, 8)))
        check(planes, ox, oy, quads, values, (-24, -16))
    # Zero weights whose sign follows the offsets' (c = -0, a = b = +0: -0 + (+-0) + (+-0)).
    planes = np.array([[0.0, 0.0, -0.0]] * 3 + [[0.0, 0.0, 1.0]])
    values = np.array([[-0.0, 1e-45], [-1e-40, 3.4e38], [-2.5, 1.0]][:vertices], f32)
    check(planes, -300, 500, [[-2, -2], [0, 0], [2, 4]], values, (0, 0))


# ---- accuracy against the exact value -------------------------------------------------------

def triangle_planes(X, Y, w, origin):
    """Planes (a, b, c) per pixel of l_k / w_k (k = 0, 1, 2) and of 1 / w, in float64, from the
    vertices' window positions (pixels) and clip w, relative to `origin` (pixels)."""
    M = np.array([[X[0], X[1], X[2]], [Y[0], Y[1], Y[2]], [1, 1, 1]], np.float64)
    inv = np.linalg.inv(M)          # row k: the screen-linear barycentric l_k = inv[k] . (x, y, 1)
    planes = np.zeros((4, 3))
    for k in range(3):
        a, b, c = inv[k] / w[k]
        planes[k] = (a, b, c + a * origin[0] + b * origin[1])
    planes[3] = planes[:3].sum(axis=0)
    return planes


def exact_values(X, Y, w, values, quads):
    x = (quads[:, 0:1] + np.array([0, 1, 0, 1])).ravel() + 0.5
    y = (quads[:, 1:2] + np.array([0, 0, 1, 1])).ravel() + 0.5
    M = np.array([[X[0], X[1], X[2]], [Y[0], Y[1], Y[2]], [1, 1, 1]], np.float64)
    lam = np.linalg.solve(M, np.stack([x, y, np.ones_like(x)]))      # screen barycentrics (3, lanes)
    persp = lam / np.asarray(w, np.float64)[:, None]
    persp /= persp.sum(axis=0)
    return values.astype(np.float64).T @ persp, persp


def error_scale(planes, ox, oy, quads, values, base):
    """Per lane, the magnitude the float32 rounding errors of the formula scale with: |v_0| plus,
    for each weighted difference, |d_k| times the magnitudes of l_k's terms (the plane's terms
    times |q|, and q's own terms relative to its value), from float64 planes."""
    tx = (base[0] * SUB + SUB // 2 - ox) / SUB
    ty = (base[1] * SUB + SUB // 2 - oy) / SUB
    dx = (quads[:, 0:1] + np.array([0, 1, 0, 1]) - base[0]).ravel()
    dy = (quads[:, 1:2] + np.array([0, 0, 1, 1]) - base[1]).ravel()
    def terms(k):
        a, b, c = planes[k]
        c = (c + a * tx) + b * ty
        return c + a * dx + b * dy, np.abs(c) + np.abs(a * dx) + np.abs(b * dy)
    pw, tw = terms(3)
    v = values.astype(np.float64)
    m = np.abs(v[0])[:, None] + 0 * dx
    for k in (1, 2):
        pk, tk = terms(k)
        m = m + np.abs(v[k] - v[0])[:, None] * (tk / np.abs(pw) + np.abs(pk / pw) * tw / np.abs(pw))[None, :]
    return m


@pytest.mark.parametrize("perspective", [False, True])
def test_error_against_the_exact_value(perspective):
    # Random triangles on a 2048^2 screen (slivers included; w from 0.2 to 20 when perspective),
    # values of mixed magnitude, pixels inside the triangle. Each of the formula's roundings is at
    # most half an ulp of its operands' magnitude, so the error stays within a few ulps of
    # error_scale; a value equal at every vertex comes out exactly.
    rng = np.random.default_rng(7 + perspective)
    worst = 0.0
    for _ in range(60):
        X, Y = rng.uniform(0, 2048, 3), rng.uniform(0, 2048, 3)
        w = rng.uniform(0.2, 20, 3) if perspective else np.full(3, rng.uniform(0.5, 2))
        ox, oy = np.floor(X[0] * SUB) / SUB, np.floor(Y[0] * SUB) / SUB
        planes = triangle_planes(X, Y, w, (ox, oy))
        values = (rng.normal(0, 1, (3, 6)) * np.array([1, 1e-3, 1e3, 255, 1, 1])).astype(f32)
        values[:, 5] = values[0, 5]                                      # a constant word
        for _ in range(4):   # a 64x64 tile around a point of the triangle, as the pipeline bases it
            lam = rng.dirichlet(np.ones(3))
            base = (int(lam @ X) // 64 * 64, int(lam @ Y) // 64 * 64)
            quads = np.array(base) + rng.integers(0, 32, (200, 2)) * 2
            want, persp = exact_values(X, Y, w, values, quads)
            inside = (persp >= 0).all(axis=0)
            got = interpolate(_core.testing.simd_level(), planes, int(ox * SUB), int(oy * SUB), quads, values,
                              base).astype(np.float64)
            scale = error_scale(planes, ox * SUB, oy * SUB, quads, values, base) * 2.0**-24
            err = np.abs(got - want)[:, inside] / scale[:, inside]
            worst = max(worst, float(err.max(initial=0)))
            np.testing.assert_array_equal(got[5], np.float64(values[0, 5]))   # exact, every lane
    assert worst <= 4, f"worst error {worst:.2f} ulps of error_scale"
    assert worst > 0.1    # the comparison saw rounding at all


@pytest.mark.parametrize("vertices", [3, 2])
@pytest.mark.parametrize("constant_w", [False, True])
def test_value_equal_at_every_vertex_is_exact(vertices, constant_w):
    # Infinities and float extremes included (inf - inf would make a NaN): d_k = 0, out = v_0.
    rng = np.random.default_rng(140 + vertices + 10 * constant_w)
    word = np.array([np.inf, -np.inf, 3.4e38, -1e-45, 0.1, 1 / 3, 255.0], f32)
    for n in (1, 5, 16):
        planes, ox, oy, quads, _ = random_case(rng, n, vertices, constant_w)
        planes[3, 2] = abs(planes[3, 2])
        values = np.repeat(word[None, :], vertices, axis=0)
        for level in range(_core.testing.simd_level() + 1):
            out = interpolate(level, planes, ox, oy, quads, values, tile_base(quads))
            np.testing.assert_array_equal(out, np.repeat(word[:, None], 4 * n, axis=1), err_msg=f"level {level}")
        check(planes, ox, oy, quads, values, tile_base(quads))
