"""The specialised per-fragment colour kernels (cpp/softgl/pipeline/fragment_ops.h) give exactly the
bytes of the reference blend_unorm8 (docs/architecture.md, "Numeric rules": a fast path must equal
the float path).

Every source/destination factor pair and equation goes through the dispatcher (most fall back to
the reference itself); the specialised ones (blending off / ONE,ZERO; SRC_ALPHA,
ONE_MINUS_SRC_ALPHA; ONE,ONE) are checked exhaustively over all 256 destination values in every
channel against a dense set of source values: every float that rounds to a different unorm8
boundary neighbourhood, out-of-range values, -0, NaN and infinities, with every colour mask, with
and without destination alpha, per pixel and in the lane kernels at every instruction-set level.
The lanes' float -> unorm8 conversion (an integer form in the AVX2 kernel, an FMA in the AVX-512
one) is also checked on its own against float_to_unorm8 over a dense sweep of float bit patterns
(a one-off run over every float in [0, 1] and every 32-bit pattern found no difference for the
integer form; the AVX-512 form is checked on every float in [0, 1] each run).
"""
import itertools

import numpy as np
import pytest

import softgl
from softgl import _core

e = lambda n: getattr(softgl, n)
FACTORS = ["ZERO", "ONE", "SRC_COLOR", "ONE_MINUS_SRC_COLOR", "DST_COLOR", "ONE_MINUS_DST_COLOR",
           "SRC_ALPHA", "ONE_MINUS_SRC_ALPHA", "DST_ALPHA", "ONE_MINUS_DST_ALPHA",
           "CONSTANT_COLOR", "ONE_MINUS_CONSTANT_COLOR", "CONSTANT_ALPHA",
           "ONE_MINUS_CONSTANT_ALPHA", "SRC_ALPHA_SATURATE"]
SPECIAL = {"plain": ("ONE", "ZERO"), "alpha_over": ("SRC_ALPHA", "ONE_MINUS_SRC_ALPHA"),
           "additive": ("ONE", "ONE")}


def sources():
    """Source channel values: around every k/255 and (k+0.5)/255, plus specials."""
    k = np.arange(256, dtype=np.float64)
    centres = np.concatenate([k / 255, (k + 0.5) / 255]).astype(np.float32)
    near = [np.nextafter(centres, np.float32(-1)), centres, np.nextafter(centres, np.float32(2))]
    special = np.array([0.0, -0.0, 1.0, -1e-30, 1e-45, 1.0000001, 0.99999994, 2.0, -2.0,
                        np.inf, -np.inf, np.nan, 1e30, -1e30], np.float32)
    rng = np.random.default_rng(7)
    return np.concatenate(near + [special, rng.uniform(-0.2, 1.2, 2000).astype(np.float32)])


def check(funcs, eqs, mask, has_alpha, src, dst, constant=(0.1, 0.5, 0.9, 0.3)):
    fe = [e(funcs[0]), e(funcs[1]), e(funcs[2]), e(funcs[3]), e(eqs[0]), e(eqs[1])]
    want = _core.testing.blend_unorm8(fe, constant, mask, has_alpha, src, dst)
    got, kernel = _core.testing.fragment_ops_write(fe, constant, mask, has_alpha, src, dst, False)
    lanes, _ = _core.testing.fragment_ops_write(fe, constant, mask, has_alpha, src, dst, True)
    np.testing.assert_array_equal(got, want)
    np.testing.assert_array_equal(lanes, want)
    # Every instruction-set level of the lane kernel (scalar twin, SSE2, AVX2 where the CPU has
    # it) gives the same bytes; the draw runs the best one.
    for level in range(_core.testing.simd_level() + 1):
        at, _ = _core.testing.fragment_ops_write(fe, constant, mask, has_alpha, src, dst, True, level)
        np.testing.assert_array_equal(at, want, err_msg=f"simd level {level}")
    return kernel


@pytest.mark.parametrize("name", sorted(SPECIAL))
@pytest.mark.parametrize("has_alpha", [True, False])
def test_specialised_kernels_equal_the_reference_exhaustively(name, has_alpha):
    sf, df = SPECIAL[name]
    s = sources()
    rng = np.random.default_rng(11)
    n = len(s)
    # Every source value in every channel, with every destination byte in every channel.
    src = np.stack([s, rng.permutation(s), rng.permutation(s), rng.permutation(s)], axis=1)
    src = np.concatenate([src, np.repeat(src[:, ::-1], 1, axis=0)])
    for rep in range(4):
        dst = np.stack([(np.arange(len(src)) * (c + 1) + 37 * rep + c) % 256 for c in range(4)],
                       axis=1).astype(np.uint8)
        for mask in [(True,) * 4, (True, False, True, False), (False, False, False, True)]:
            kernel = check((sf, df, sf, df), ("FUNC_ADD", "FUNC_ADD"), mask, has_alpha, src, dst)
            assert kernel == {"plain": 0, "alpha_over": 1, "additive": 2}[name]
    # All 256 destination values against every alpha at 1/255 steps (the full table for the
    # alpha-weighted kernels' rgb channels).
    a = (np.arange(256) / 255).astype(np.float32)
    d, al = np.meshgrid(np.arange(256), np.arange(256))
    src = np.stack([al.ravel() / 255, 1 - al.ravel() / 255, np.full(al.size, 0.5), al.ravel() / 255],
                   axis=1).astype(np.float32)
    dst = np.stack([d.ravel(), 255 - d.ravel(), d.ravel(), d.ravel()[::-1]], axis=1).astype(np.uint8)
    check((sf, df, sf, df), ("FUNC_ADD", "FUNC_ADD"), (True,) * 4, has_alpha, src, dst)


def test_the_machine_runs_the_best_kernels_it_has():
    flags = open("/proc/cpuinfo").read() if __import__("os").path.exists("/proc/cpuinfo") else ""
    if all(f" {f}" in flags for f in ("avx512f", "avx512bw", "avx512dq", "avx512vl")):
        assert _core.testing.simd_level() == 3
    elif " avx2" in flags:
        assert _core.testing.simd_level() == 2


def test_every_factor_and_equation_dispatches_to_an_equal_kernel():
    rng = np.random.default_rng(3)
    src = rng.uniform(-0.25, 1.25, (67, 4)).astype(np.float32)   # odd count: SIMD tail too
    dst = rng.integers(0, 256, (67, 4)).astype(np.uint8)
    eqs = ["FUNC_ADD", "FUNC_SUBTRACT", "FUNC_REVERSE_SUBTRACT", "MIN", "MAX"]
    for sf, df in itertools.product(FACTORS, FACTORS):
        for eq in ("FUNC_ADD", eqs[hash((sf, df)) % len(eqs)]):
            check((sf, df, sf, df), (eq, eq), (True,) * 4, True, src, dst)
    # Separate alpha factors/equations must not be mistaken for a specialised kernel.
    check(("SRC_ALPHA", "ONE_MINUS_SRC_ALPHA", "ONE", "ZERO"), ("FUNC_ADD", "FUNC_ADD"), (True,) * 4, True, src, dst)
    check(("ONE", "ONE", "ONE", "ONE"), ("FUNC_ADD", "MAX"), (True,) * 4, True, src, dst)


F32_ONE = 0x3F800000   # bit pattern of 1.0f; every float in [0, 1] is a pattern 0..F32_ONE


def bits_of(x):
    return int(np.float32(x).view(np.uint32))


@pytest.mark.parametrize("in_place", [False, True])
@pytest.mark.parametrize("level", range(_core.testing.simd_level() + 1))
def test_lane_conversion_equals_float_to_unorm8(level, in_place):
    # in_place: through write_color_quads_at (Tuning::blend_in_place), whose AVX2 level converts
    # by an FMA of its own.
    def mismatches(*args):
        return _core.testing.unorm8_conversion_mismatches(*args, in_place=in_place)
    # Every 29th float in [0, 1] (each exponent, each mantissa residue class over the sweep).
    assert mismatches(level, 0, F32_ONE, 29) == 0
    # Every float within 64 ulps of each rounding boundary (k + 0.5) / 255 and each k / 255,
    # where an inexact conversion would go wrong first.
    for k in range(256):
        for centre in ((k + 0.5) / 255, k / 255):
            b = bits_of(min(centre, 1.0))
            assert mismatches(level, max(b - 64, 0), b + 64) == 0, (k, centre)
    # Around every power of two (exponent steps change the integer form's shift) and the
    # subnormals, where the shift count passes 32.
    for e in range(-149, 2):
        b = bits_of(2.0 ** e)
        assert mismatches(level, max(b - 64, 0), b + 64) == 0, e
    # Outside [0, 1]: negatives, -0, values above 1, infinities and NaNs clamp first.
    assert mismatches(level, F32_ONE, 0xFFFFFFFF, 4099) == 0
    assert mismatches(level, 0x7F7FFFF0, 0x80000010) == 0   # largest floats, inf, NaN, -0
    assert mismatches(level, 0xFF7FFFF0, 0xFFFFFFFF) == 0   # -inf, negative NaNs


@pytest.mark.skipif(_core.testing.simd_level() < 3, reason="the AVX-512 kernels need AVX-512 F+BW+DQ+VL")
def test_avx512_conversion_every_float_in_0_1():
    # The AVX-512 lanes convert with an FMA into the integer range of floats (fragment_ops.cpp,
    # unorm8_pixels_ps16): checked on every float in [0, 1], about 1.07e9 values.
    assert _core.testing.unorm8_conversion_mismatches(3, 0, F32_ONE) == 0


@pytest.mark.skipif(_core.testing.simd_level() < 2, reason="the in-place AVX2 kernel needs AVX2")
def test_in_place_avx2_conversion_every_float_in_0_1():
    # write_color_quads_at's AVX2 level converts with an FMA into the integer range of floats
    # (fragment_ops.cpp, blend8_fma), as the AVX-512 lanes do: every float in [0, 1].
    assert _core.testing.unorm8_conversion_mismatches(2, 0, F32_ONE, in_place=True) == 0


def test_lane_kernels_every_tail_length():
    # n = 1..40 lanes: the SIMD kernels' full blocks (4, 8, 16 lanes) and every tail after them.
    rng = np.random.default_rng(5)
    s = sources()
    for n in range(1, 41):
        src = rng.choice(s, (n, 4)).astype(np.float32)
        dst = rng.integers(0, 256, (n, 4)).astype(np.uint8)
        for name, (sf, df) in SPECIAL.items():
            for mask in [(True,) * 4, (False, True, True, False)]:
                check((sf, df, sf, df), ("FUNC_ADD", "FUNC_ADD"), mask, n % 2 == 0, src, dst)
                # One colour in every lane (a shader that reads only uniforms): the AVX-512
                # kernel's table path, and the same colour but for one lane.
                uniform = np.repeat(src[:1], n, axis=0)
                check((sf, df, sf, df), ("FUNC_ADD", "FUNC_ADD"), mask, n % 2 == 0, uniform, dst)
                uniform[n - 1, n % 4] = np.nextafter(uniform[n - 1, n % 4], np.float32(2))
                check((sf, df, sf, df), ("FUNC_ADD", "FUNC_ADD"), mask, n % 2 == 0, uniform, dst)


@pytest.mark.parametrize("name", sorted(SPECIAL))
def test_one_colour_in_every_lane_over_every_destination(name):
    # The same colour in every lane over all 256 destination values of every channel: colours
    # at every rounding boundary neighbourhood and the specials (-0, NaN, inf, out of range), one
    # after another (the AVX-512 kernel keeps the last colour's table per thread).
    sf, df = SPECIAL[name]
    s = sources()
    rng = np.random.default_rng(13)
    colours = np.concatenate([np.stack([s[:-2000]] * 4, axis=1)[::7],
                              rng.permutation(s)[:4 * 150].reshape(150, 4)]).astype(np.float32)
    d = np.arange(256)
    dst = np.stack([d, d[::-1], (d * 7) % 256, (d * 13 + 5) % 256], axis=1).astype(np.uint8)
    for i, colour in enumerate(colours):
        src = np.repeat(colour[None], 256, axis=0)
        mask = [(True,) * 4, (True, False, True, True), (False, False, False, True)][i % 3]
        check((sf, df, sf, df), ("FUNC_ADD", "FUNC_ADD"), mask, i % 2 == 0, src, dst)
        check((sf, df, sf, df), ("FUNC_ADD", "FUNC_ADD"), mask, i % 2 == 1, src[:37], dst[100:137])


@pytest.mark.parametrize("name", ["alpha_over", "additive"])
def test_one_colour_under_changing_colour_masks(name):
    # The AVX-512 kernel keeps a table per recent colour (per thread, built at the colour's second
    # call in a row of misses): a table made while the colour mask left a channel out must still
    # blend that channel when a later call with the same colour writes it.
    sf, df = SPECIAL[name]
    src = np.repeat(np.array([[0.3, 0.6, 0.9, 0.5]], np.float32), 256, axis=0)
    d = np.arange(256)
    dst = np.stack([d, d[::-1], (d * 7) % 256, (d * 13 + 5) % 256], axis=1).astype(np.uint8)
    some, every = (True, False, True, False), (True,) * 4
    for mask in [some, some, some, every, every, some, every]:
        check((sf, df, sf, df), ("FUNC_ADD", "FUNC_ADD"), mask, True, src, dst)


@pytest.mark.parametrize("name", ["alpha_over", "additive"])
def test_colours_in_turns_keep_their_own_tables(name):
    # A lit box's faces: a few colours in turns, more of them than the kernel keeps tables for and
    # fewer, each call a different lane count and destination; every call's bytes are the
    # reference's.
    sf, df = SPECIAL[name]
    rng = np.random.default_rng(29)
    palette = rng.uniform(-0.1, 1.1, (7, 4)).astype(np.float32)
    palette[6] = palette[5]
    palette[6][3] = 1 - palette[5][3]   # another's colour but for alpha
    palette[4] = palette[3]
    palette[4][1] = np.nextafter(palette[3][1], np.float32(-1))   # another's but one ulp in green
    for turn in range(120):
        k = int(rng.integers(0, 3 if turn < 40 else 7))
        n = int(rng.integers(1, 300))
        src = np.repeat(palette[k][None], n, axis=0)
        dst = rng.integers(0, 256, (n, 4)).astype(np.uint8)
        check((sf, df, sf, df), ("FUNC_ADD", "FUNC_ADD"), (True,) * 4, turn % 5 != 0, src, dst)


def test_results_at_the_ends_of_the_range_over_many_alphas():
    # The SIMD kernels skip the clamp after SRC_ALPHA, ONE_MINUS_SRC_ALPHA (the result is at most
    # just above 1). Sources 1, just below 1 and 0 (the largest and smallest results) against
    # every 4099th float in [0, 1] as alpha and every float within 4096 ulps of 0 and 1, with
    # destination 255 and varied bytes.
    a = np.concatenate([np.arange(0, F32_ONE + 1, 4099, dtype=np.uint32).view(np.float32),
                        np.arange(F32_ONE - 4096, F32_ONE + 1, dtype=np.uint32).view(np.float32),
                        np.arange(0, 4096, dtype=np.uint32).view(np.float32)])
    rng = np.random.default_rng(17)
    for s in (1.0, 0.99999994, 0.0):
        src = np.stack([np.full(a.size, s, np.float32)] * 3 + [a], axis=1)
        for name in ("alpha_over", "additive"):
            sf, df = SPECIAL[name]
            dst = np.stack([np.full(a.size, 255), (np.arange(a.size) * 7) % 256,
                            rng.integers(0, 256, a.size), np.arange(a.size) % 256], axis=1).astype(np.uint8)
            check((sf, df, sf, df), ("FUNC_ADD", "FUNC_ADD"), (True,) * 4, True, src, dst)
