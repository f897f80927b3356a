"""Blending into RGBA8 against the ES 3.0 §4.1.7 formulas evaluated in float64.

Every source/destination factor (15, incl. SRC_ALPHA_SATURATE and the constants) crossed with
every equation, on random colors including out-of-range shader outputs. softgl computes in
float32; the result must equal the float64 reference within one step of 1/255 and exactly for
the overwhelming majority of pixels.
"""
import itertools

import numpy as np
import pytest

import softgl
from softgl import _core

FACTORS = ["ZERO", "ONE", "SRC_COLOR", "ONE_MINUS_SRC_COLOR", "DST_COLOR", "ONE_MINUS_DST_COLOR",
           "SRC_ALPHA", "ONE_MINUS_SRC_ALPHA", "DST_ALPHA", "ONE_MINUS_DST_ALPHA",
           "CONSTANT_COLOR", "ONE_MINUS_CONSTANT_COLOR", "CONSTANT_ALPHA",
           "ONE_MINUS_CONSTANT_ALPHA", "SRC_ALPHA_SATURATE"]
EQUATIONS = ["FUNC_ADD", "FUNC_SUBTRACT", "FUNC_REVERSE_SUBTRACT", "MIN", "MAX"]


def factor64(name, s, d, k):
    one = np.ones_like(s[:, :1])
    table = {
        "ZERO": 0 * s, "ONE": one + 0 * s, "SRC_COLOR": s, "ONE_MINUS_SRC_COLOR": 1 - s,
        "DST_COLOR": d, "ONE_MINUS_DST_COLOR": 1 - d,
        "SRC_ALPHA": s[:, 3:4] + 0 * s, "ONE_MINUS_SRC_ALPHA": 1 - s[:, 3:4] + 0 * s,
        "DST_ALPHA": d[:, 3:4] + 0 * s, "ONE_MINUS_DST_ALPHA": 1 - d[:, 3:4] + 0 * s,
        "CONSTANT_COLOR": k + 0 * s, "ONE_MINUS_CONSTANT_COLOR": 1 - k + 0 * s,
        "CONSTANT_ALPHA": k[3] + 0 * s, "ONE_MINUS_CONSTANT_ALPHA": 1 - k[3] + 0 * s,
    }
    if name == "SRC_ALPHA_SATURATE":
        f = np.minimum(s[:, 3:4], 1 - d[:, 3:4]) + 0 * s
        f[:, 3] = 1
        return f
    return table[name]


def blend64(src, dst, sf, df, sfa, dfa, eq, eqa, k, has_alpha=True):
    s = np.clip(src.astype(np.float64), 0, 1)
    d = dst.astype(np.float64) / 255
    if not has_alpha:
        d[:, 3] = 1
    k = np.clip(np.asarray(k, np.float64), 0, 1)
    S = factor64(sf, s, d, k).copy()   # copies: SRC_COLOR and DST_COLOR return s and d themselves
    D = factor64(df, s, d, k).copy()
    S[:, 3] = factor64(sfa, s, d, k)[:, 3]
    D[:, 3] = factor64(dfa, s, d, k)[:, 3]
    out = np.empty_like(s)
    for ch, e in ((slice(0, 3), eq), (slice(3, 4), eqa)):
        a, b, fa, fb = s[:, ch], d[:, ch], S[:, ch], D[:, ch]
        out[:, ch] = {"FUNC_ADD": a * fa + b * fb, "FUNC_SUBTRACT": a * fa - b * fb,
                      "FUNC_REVERSE_SUBTRACT": b * fb - a * fa, "MIN": np.minimum(a, b),
                      "MAX": np.maximum(a, b)}[e]
    return np.floor(np.clip(out, 0, 1) * 255 + 0.5).astype(np.int64)


def run(src, dst, sf, df, sfa, dfa, eq, eqa, k, mask=(True,) * 4, has_alpha=True):
    e = lambda n: getattr(softgl, n)
    return _core.testing.blend_unorm8([e(sf), e(df), e(sfa), e(dfa), e(eq), e(eqa)], k, mask,
                                      has_alpha, src, dst).astype(np.int64)


@pytest.fixture(scope="module")
def colors():
    rng = np.random.default_rng(1234)
    src = rng.uniform(-0.25, 1.25, (512, 4)).astype(np.float32)   # shader outputs may leave [0, 1]
    dst = rng.integers(0, 256, (512, 4)).astype(np.uint8)
    return src, dst


def test_every_factor_pair_and_equation(colors):
    src, dst = colors
    k = (0.3, 0.8, 0.1, 0.6)
    exact = total = 0
    for sf, df, eq in itertools.product(FACTORS, FACTORS, EQUATIONS):
        got = run(src, dst, sf, df, sf, df, eq, eq, k)
        want = blend64(src, dst, sf, df, sf, df, eq, eq, k)
        diff = np.abs(got - want)
        assert diff.max() <= 1, (sf, df, eq)
        exact += int((diff == 0).sum())
        total += diff.size
    # The rest differ by one step where float32 lands on the other side of a rounding tie.
    assert exact / total > 0.998, exact / total


def test_separate_rgb_and_alpha(colors):
    src, dst = colors
    k = (1.5, -1, 0.25, 0.75)    # the constant color is clamped before use (ES 3.0 §4.1.7)
    got = run(src, dst, "SRC_ALPHA", "ONE_MINUS_SRC_ALPHA", "ONE", "ZERO",
              "FUNC_ADD", "FUNC_REVERSE_SUBTRACT", k)
    want = blend64(src, dst, "SRC_ALPHA", "ONE_MINUS_SRC_ALPHA", "ONE", "ZERO",
                   "FUNC_ADD", "FUNC_REVERSE_SUBTRACT", k)
    assert np.abs(got - want).max() <= 1


def test_hand_computed_interpolative_blend():
    # 0.5 * (1, 0, 0) + 0.5 * (0, 0, 255)/255 = (0.5, 0, 0.5) -> 128 (round half up of 127.5)
    got = run(np.array([[1, 0, 0, 0.5]], np.float32), np.array([[0, 0, 255, 255]], np.uint8),
              "SRC_ALPHA", "ONE_MINUS_SRC_ALPHA", "SRC_ALPHA", "ONE_MINUS_SRC_ALPHA",
              "FUNC_ADD", "FUNC_ADD", (0, 0, 0, 0))
    assert got.tolist() == [[128, 0, 128, 191]]   # alpha: 0.25 + 0.5 = 0.75 -> 191.25 -> 191


def test_color_mask_and_missing_alpha(colors):
    src, dst = colors
    got = run(src, dst, "ONE", "ONE", "ONE", "ONE", "FUNC_ADD", "FUNC_ADD", (0, 0, 0, 0),
              mask=(False, True, False, True))
    assert np.array_equal(got[:, [0, 2]], dst[:, [0, 2]])
    # alpha:false: DST_ALPHA reads 1 and alpha is never written.
    got = run(src, dst, "DST_ALPHA", "ZERO", "ONE", "ZERO", "FUNC_ADD", "FUNC_ADD", (0, 0, 0, 0),
              has_alpha=False)
    want = np.floor(np.clip(src[:, :3].astype(np.float64), 0, 1) * 255 + 0.5)
    assert np.abs(got[:, :3] - want).max() <= 1
    assert np.array_equal(got[:, 3], dst[:, 3])
