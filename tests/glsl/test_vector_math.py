"""softgl's own exp2, exp, log2, log, pow, sin and cos (cpp/softgl/core/vector_math.h) through
shaders, against NumPy float64 on dense sweeps: the error in ulps of the float result (the spacing
of floats at the float64 value), the GLSL ES 3.00 §4.5.1 highp bounds, the special values of the
documented rules, the same bits at every SIMD level, and constant folding equal to run time.

Measured maxima (docs/architecture.md, "Numeric rules"): exp2, exp, pow 0.502 ulp; log2, log 0.5001
ulp; sin, cos 0.5001 ulp over the whole float range. A correctly rounded function would have 0.5."""
import numpy as np
import pytest

from conftest import FRAG_EXPR, run
from softgl import _core

LEVELS = _core.glsl_simd_levels()
rng = np.random.default_rng(18)

# The bound asserted for every function: a hair above correct rounding (docs/architecture.md).
MAX_ULP = 0.502


def glsl(expr, a, b=None, simd=""):
    """expr of a (and b) elementwise, each a flat float32 array (padded to vec4 lanes)."""
    n = a.size
    lanes = -(-n // 4)
    pad = lambda v: np.concatenate([v, np.ones(lanes * 4 - n, np.float32)]).reshape(lanes, 4)
    inputs = {"a": pad(a), "b": pad(a if b is None else b), "c": pad(a)}
    out = _core.glsl_run(FRAG_EXPR.format(expr=expr), "fragment", 2, inputs, {}, lanes, {}, 128, 1, simd)["o"]
    return out.reshape(-1)[:n]


def ulps(got, exact):
    """|got - exact| in units of the float spacing at exact (finite results within float range)."""
    spacing = np.spacing(np.abs(exact).astype(np.float32)).astype(np.float64)
    return np.abs(got.astype(np.float64) - exact) / spacing


def log_uniform(lo_exp, hi_exp, n, signed=False):
    v = np.exp2(rng.uniform(lo_exp, hi_exp, n))
    if signed:
        v *= rng.choice([-1.0, 1.0], n)
    return v.astype(np.float32)


N = 1_000_000
SWEEPS = {
    # name: (glsl, float64 reference, argument sweep)
    "exp2": ("exp2(a)", np.exp2, lambda: np.concatenate([rng.uniform(-150, 128, N), rng.uniform(-1, 1, N // 4)])),
    "exp": ("exp(a)", np.exp, lambda: np.concatenate([rng.uniform(-104, 88.7, N), rng.uniform(-1, 1, N // 4)])),
    "log2": ("log2(a)", np.log2, lambda: np.concatenate([log_uniform(-149, 128, N), rng.uniform(0.5, 2.0, N // 4)])),
    "log": ("log(a)", np.log, lambda: np.concatenate([log_uniform(-149, 128, N), rng.uniform(0.5, 2.0, N // 4)])),
    "sin": ("sin(a)", np.sin, lambda: np.concatenate([rng.uniform(-np.pi, np.pi, N), rng.uniform(-1e4, 1e4, N // 4),
                                                      log_uniform(-20, 128, N // 4, signed=True)])),
    "cos": ("cos(a)", np.cos, lambda: np.concatenate([rng.uniform(-np.pi, np.pi, N), rng.uniform(-1e4, 1e4, N // 4),
                                                      log_uniform(-20, 128, N // 4, signed=True)])),
}


@pytest.mark.parametrize("name", list(SWEEPS))
def test_one_argument_functions_within_half_an_ulp(name):
    expr, ref, sweep = SWEEPS[name]
    x = sweep().astype(np.float32)
    got = glsl(expr, x)
    exact = ref(x.astype(np.float64))
    inside = np.abs(exact) < np.finfo(np.float32).max
    err = ulps(got[inside], exact[inside])
    assert err.max() <= MAX_ULP, f"{name}({x[inside][np.argmax(err)]!r}) is {err.max():.4f} ulp off"
    # Beyond the float range: inf (exp2, exp overflow).
    assert np.all(got[~inside] == np.inf)
    # GLSL ES 3.00 §4.5.1 highp, which the bound above implies: checked as the spec words them.
    x64 = x.astype(np.float64)
    if name in ("sin", "cos"):
        pi = np.abs(x64) <= np.pi
        assert np.abs(got[pi] - exact[pi]).max() <= 2.0 ** -11
    if name in ("exp2", "exp"):
        assert np.all(err <= 3 + 2 * np.abs(x64[inside]))
    if name in ("log2", "log"):
        near_one = (x64 >= 0.5) & (x64 <= 2.0)
        assert np.abs(got[near_one] - exact[near_one]).max() <= 2.0 ** -21
        assert ulps(got[~near_one], exact[~near_one]).max() <= 3


def test_pow_within_half_an_ulp():
    # x over many binades, y such that x^y stays mostly within the float range, and the ranges
    # shaders use (x in [0, 1], y up to a few hundred: specular exponents).
    x = np.concatenate([log_uniform(-40, 40, N), rng.uniform(0, 1, N // 2)]).astype(np.float32)
    y = np.concatenate([rng.uniform(-3, 3, N), rng.uniform(0, 300, N // 2)]).astype(np.float32)
    got = glsl("pow(a, b)", x, y)
    exact = np.power(x.astype(np.float64), y.astype(np.float64))
    finite = (exact < np.finfo(np.float32).max) & (exact > 0)
    err = ulps(got[finite], exact[finite])
    k = np.argmax(err)
    assert err.max() <= MAX_ULP, f"pow({x[finite][k]!r}, {y[finite][k]!r}) is {err.max():.4f} ulp off"
    assert np.all(got[exact >= np.finfo(np.float32).max] == np.inf)
    assert np.all(got[exact == 0] == 0)
    # Exact where the value is a float: powers of two, integer powers, y = 1.
    xs = rng.uniform(0.01, 100, 4096).astype(np.float32)
    np.testing.assert_array_equal(glsl("pow(a, b)", xs, np.ones_like(xs)), xs)
    two = np.full(64, 2, np.float32)
    e = np.arange(-32, 32).astype(np.float32)
    np.testing.assert_array_equal(glsl("pow(a, b)", two, e), np.exp2(e))
    np.testing.assert_array_equal(glsl("pow(a, b)", np.float32([3, 10, 7, 1.5]), np.float32([4, 2, 3, 2])),
                                  np.float32([81, 100, 343, 2.25]))


INF, NAN = np.inf, np.nan
SPECIAL = [
    # expression, a, b, expected (the rules in core/vector_math.h and docs/architecture.md)
    ("exp2(a)", [0.0, -0.0, INF, -INF, 128.0, -149.0, -150.0, 1e-45, NAN], None,
     [1, 1, INF, 0, INF, 2.0 ** -149, 0, 1, NAN]),
    ("exp(a)", [0.0, INF, -INF, 89.0, -104.0, NAN], None, [1, INF, 0, INF, 0, NAN]),
    ("log2(a)", [1.0, 0.0, -0.0, -1.0, INF, -INF, 2.0 ** -149, 2.0 ** 127, 0.5, NAN], None,
     [0, -INF, -INF, NAN, INF, NAN, -149, 127, -1, NAN]),
    ("log(a)", [1.0, 0.0, -0.0, -1.0, INF, NAN], None, [0, -INF, -INF, NAN, INF, NAN]),
    ("sin(a)", [0.0, -0.0, 1e-40, -1e-40, INF, -INF, NAN], None, [0, -0.0, 1e-40, -1e-40, NAN, NAN, NAN]),
    ("cos(a)", [0.0, -0.0, 1e-40, INF, -INF, NAN], None, [1, 1, 1, NAN, NAN, NAN]),
    # pow = exp2(b * log2(a)) also where ES 3.00 §8.2 leaves it undefined.
    ("pow(a, b)", [0.0, 0.0, 0.0, -0.0, -2.0, -8.0, 1.0, 1.0, INF, INF, 2.0, 0.5, NAN, 1.0, NAN],
     [2.0, 0.0, -1.0, -1.0, 2.0, 1 / 3, INF, NAN, 0.0, -1.0, INF, INF, 0.0, 0.0, 1.0],
     [0, NAN, INF, INF, NAN, NAN, NAN, NAN, NAN, 0, INF, 0, NAN, 1, NAN]),
]


@pytest.mark.parametrize("expr,a,b,expected", SPECIAL, ids=[s[0] for s in SPECIAL])
def test_special_values(expr, a, b, expected):
    a = np.float32(a)
    got = glsl(expr, a, None if b is None else np.float32(b))
    expected = np.float32(expected)
    np.testing.assert_array_equal(np.isnan(got), np.isnan(expected), err_msg=f"{expr} NaN at {a}")
    ok = ~np.isnan(expected)
    np.testing.assert_array_equal(got[ok].view(np.uint32), expected[ok].view(np.uint32), err_msg=f"{expr} at {a[ok]}")


ALL = ["exp2(a)", "exp(a)", "log2(a)", "log(a)", "sin(a)", "cos(a)", "pow(a, b)"]
LEVEL_VALUES = np.float32([0.0, -0.0, 1e-45, -1e-40, 1.0, -1.0, 0.5, 2.0, 3.0e38, -3.0e38, INF, -INF, NAN,
                           -NAN, 2.0 ** 25, -(2.0 ** 25), 1e30, 127.9, -149.5, 88.7, 3.14159265, 1.5707964])


@pytest.mark.skipif(len(LEVELS) < 2, reason="this CPU runs only the portable level")
@pytest.mark.parametrize("expr", ALL)
@pytest.mark.parametrize("count", [1, 3, 4, 7, 8, 9, 15, 16, 17, 33, 130, 4099])
def test_same_bits_at_every_level(expr, count):
    # Counts around the vector widths and the blocks of 8 and 16 lanes (core/vector_math.h
    # map_lanes); every bit, NaNs included (their bits are defined, see pow).
    r = np.random.default_rng(count)
    a = np.where(r.random(count) < 0.3, r.choice(LEVEL_VALUES, count),
                 r.normal(size=count) * r.choice([0.01, 1.0, 100.0, 1e6], count)).astype(np.float32)
    b = np.where(r.random(count) < 0.3, r.choice(LEVEL_VALUES, count), r.normal(size=count) * 4).astype(np.float32)
    if expr.startswith("pow"):
        a = np.abs(a)
    outs = {level: glsl(expr, a, b, simd=level).view(np.uint32) for level in LEVELS}
    first = outs[LEVELS[0]]
    for level, out in outs.items():
        np.testing.assert_array_equal(out, first, err_msg=f"{expr} at {level} vs {LEVELS[0]}")


def test_constant_folding_gives_run_time_bits():
    # Constant expressions fold on the IR with the executor itself (glsl/optimize.cpp), so a
    # folded pow(2.0, 0.5) has run time's bits; here over ordinary values (test_hostile_sources
    # covers the special ones).
    r = np.random.default_rng(5)
    xs = np.float32(np.concatenate([r.uniform(0.01, 10, 24), [2.0, 1e30, -1e30, 2.0 ** 26]]))
    ys = np.float32(r.uniform(-4, 4, xs.size))
    for expr in ALL:
        literal = lambda v: f"{float(v):.9e}"   # 10 significant digits: the float exactly
        calls = [expr.replace("a", literal(x)).replace("b", literal(y)) for x, y in zip(xs, ys)]
        source = ("#version 300 es\nprecision highp float;\nin float lane;\nout vec4 o;\n"
                  f"const float table[{len(calls)}] = float[{len(calls)}]({', '.join(calls)});\n"
                  "void main() { o = vec4(table[int(lane)]); }")
        folded = run(source, "fragment", {"lane": np.arange(xs.size, dtype=np.float32)}, lanes=xs.size)["o"][:, 0]
        at_run_time = glsl(expr, xs, ys)
        np.testing.assert_array_equal(folded.view(np.uint32), at_run_time.view(np.uint32), err_msg=expr)


def test_inside_a_branch_only_active_lanes_change():
    # Under a condition the executor packs the active lanes together before computing (executor.cpp
    # vector_math); each lane's value must be the one computed without the condition.
    r = np.random.default_rng(9)
    n = 4 * 301
    a = r.uniform(-3, 3, n).astype(np.float32)
    b = r.uniform(-3, 3, n).astype(np.float32)
    c = r.uniform(-1, 1, n).astype(np.float32)
    pad = lambda v: v.reshape(-1, 4)
    body = "vec4(pow(abs(a.x), b.y), sin(a.y) + cos(b.z), exp2(a.z) * exp(b.w), log2(abs(a.w)) + log(abs(b.x)))"
    source = FRAG_EXPR.replace("void main() {{ o = {expr}; }}",
                               "void main() {{ o = vec4(-7.0); if (c.x > {t}) o = {expr}; }}")
    inputs = {"a": pad(a), "b": pad(b), "c": pad(c)}
    full = _core.glsl_run(FRAG_EXPR.format(expr=body), "fragment", 2, inputs, {}, n // 4)["o"]
    for threshold in (-2.0, 0.0, 0.6, 0.95):
        out = _core.glsl_run(source.format(expr=body, t=threshold), "fragment", 2, inputs, {}, n // 4)["o"]
        taken = pad(c)[:, 0] > threshold
        np.testing.assert_array_equal(out[taken].view(np.uint32), full[taken].view(np.uint32))
        np.testing.assert_array_equal(out[~taken], -7.0)
