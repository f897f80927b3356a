"""The executor's shortcuts give the bits of the plain instruction sequence: fused sums of
products (FDot) against the same sums whose products are kept (so they cannot fuse), copy
propagation and skipped inactive lanes against float32 NumPy evaluations of the same steps."""
import numpy as np
import pytest

from conftest import run
from softgl import _core

rng = np.random.default_rng(5)
LANES = 4 * 37


def values(columns):
    v = rng.normal(size=(LANES, columns)).astype(np.float32) * np.float32(1e3) ** rng.integers(-3, 4, size=(LANES, columns))
    v[rng.random((LANES, columns)) < 0.05] = np.float32(np.inf)
    return v.astype(np.float32)


@pytest.mark.parametrize("n", [2, 3, 4])
def test_fused_products_equal_separate_operations(n):
    # o.x: dot() (fuses); o.y: the same sum whose products are also outputs (cannot fuse).
    swz = "xyzw"[:n]
    separate = " + ".join(f"p{k}" for k in range(n))
    fs = f"""#version 300 es
    precision highp float;
    in vec4 a;
    in vec4 b;
    layout(location = 0) out vec4 o;
    layout(location = 1) out vec4 products;
    void main() {{
        {" ".join(f"float p{k} = a.{'xyzw'[k]} * b.{'xyzw'[k]};" for k in range(n))}
        o = vec4(dot(a.{swz}, b.{swz}), {separate}, 0.0, 0.0);
        products = vec4({", ".join(f"p{k}" for k in range(n))}{", 0.0" * (4 - n)});
    }}"""
    a, b = values(4), values(4)
    out = run(fs, "fragment", {"a": a, "b": b}, lanes=LANES)
    np.testing.assert_array_equal(out["o"][:, 0].view(np.uint32), out["o"][:, 1].view(np.uint32))
    # and both are the left-to-right float32 sum of float32 products (NaN lanes: inf - inf)
    expected = a[:, 0] * b[:, 0]
    with np.errstate(invalid="ignore"):
        for k in range(1, n):
            expected = expected + a[:, k] * b[:, k]
    np.testing.assert_array_equal(out["o"][:, 0], expected)


def test_variables_and_libm_calls_under_divergent_control_flow():
    # x is copied into variables inside a branch, read in the branch (propagated) and after it
    # (kept); pow runs under a mask (inactive lanes skipped) and inside a loop with breaks.
    fs = """#version 300 es
    precision highp float;
    in vec4 a;
    out vec4 o;
    void main() {
        float kept = -1.0;
        float acc = 0.0;
        for (int i = 0; i < 4; i++) {
            if (a[i] > 0.0) {
                float x = pow(a[i], 1.5);
                kept = x;
                acc += x * 2.0;
            } else if (a[i] < -1.0) {
                break;
            }
        }
        o = vec4(kept, acc, exp(a.x) , 0.0);
    }"""
    a = rng.uniform(-2, 2, size=(LANES, 4)).astype(np.float32)
    out = run(fs, "fragment", {"a": a}, lanes=LANES)
    kept = np.full(LANES, -1.0, np.float32)
    acc = np.zeros(LANES, np.float32)
    for lane in range(LANES):
        for i in range(4):
            if a[lane, i] > 0:
                x = np.float32(np.power(np.float64(a[lane, i]), 1.5))
                kept[lane] = x
                acc[lane] = np.float32(acc[lane] + np.float32(x * np.float32(2)))
            elif a[lane, i] < -1:
                break
    np.testing.assert_allclose(out["o"][:, 0], kept, rtol=1e-6)    # libm powf vs float64 pow rounded
    np.testing.assert_allclose(out["o"][:, 1], acc, rtol=4e-6)
    np.testing.assert_allclose(out["o"][:, 2], np.exp(a[:, 0].astype(np.float64)), rtol=4e-7)
    np.testing.assert_array_equal(out["o"][:, 0] == -1.0, kept == -1.0)


@pytest.mark.parametrize("share", [0.0, 1 / 148, 0.1, 0.25, 0.3, 0.5, 1.0])
def test_vector_math_under_a_branch_equals_every_lane(share):
    # pow, exp2, log2, sin under an `if` taken by `share` of the lanes: the executor computes only
    # the active lanes, packed together (vector_math). An active lane's bits are those of the
    # same call with every lane active (o1, from a copy of the inputs so the two calls stay
    # apart), at every SIMD level, and near the float64 value.
    fs = """#version 300 es
    precision highp float;
    in vec4 a;
    in vec4 b;
    in float taken;
    layout(location = 0) out vec4 o0;
    layout(location = 1) out vec4 o1;
    void main() {
        vec4 r = vec4(-7.0);
        if (taken > 0.5) r = vec4(pow(a.x, a.y), exp2(a.z), log2(a.x), sin(a.w));
        o0 = r;
        o1 = vec4(pow(b.x, b.y), exp2(b.z), log2(b.x), sin(b.w));
    }"""
    lanes = 4 * 37   # a batch of 128 lanes and one of 20
    a = np.column_stack([rng.uniform(0.01, 8, lanes), rng.uniform(-6, 6, lanes), rng.uniform(-20, 20, lanes),
                         rng.uniform(-9, 9, lanes)]).astype(np.float32)
    taken = np.zeros(lanes, np.float32)
    taken[rng.permutation(lanes)[:int(round(share * lanes))]] = 1.0
    on = taken > 0.5
    x = a.astype(np.float64)
    expected = np.column_stack([x[:, 0] ** x[:, 1], 2 ** x[:, 2], np.log2(x[:, 0]), np.sin(x[:, 3])])
    for level in _core.glsl_simd_levels():
        out = _core.glsl_run(fs, "fragment", 2, {"a": a, "b": a.copy(), "taken": taken}, {}, lanes, {}, 128, 1, level)
        o0, o1 = out["o0"], out["o1"]
        np.testing.assert_array_equal(o0[on].view(np.uint32), o1[on].view(np.uint32), err_msg=level)
        assert np.all(o0[~on] == -7.0), level
        np.testing.assert_allclose(o1, expected, rtol=2e-6, atol=1e-7, err_msg=level)


def _f32_bits_equal(actual, expected, msg=""):
    # Same value, NaNs where expected has them (payloads aside), the sign of zeros included.
    actual, expected = np.asarray(actual, np.float32), np.asarray(expected, np.float32)
    nan = np.isnan(expected)
    np.testing.assert_array_equal(np.isnan(actual), nan, err_msg=msg)
    np.testing.assert_array_equal(actual[~nan].view(np.uint32), expected[~nan].view(np.uint32), err_msg=msg)


@pytest.mark.parametrize("n", [2, 3, 4])
def test_fused_normalize_equals_its_steps(n):
    # normalize(v) runs as one FNormalize pass (FDot of v with itself, sqrt, a division per
    # component). Its bits are the float32 steps' (squares summed left to right, sqrt, divide),
    # those of the same steps written out so that they cannot fuse (the length is also an
    # output), at every SIMD level; and within 2 ulps of the float64 normalisation.
    swz = "xyzw"[:n]
    fs = f"""#version 300 es
    precision highp float;
    in vec4 a;
    layout(location = 0) out vec4 fused;
    layout(location = 1) out vec4 steps;
    layout(location = 2) out float len;
    void main() {{
        fused = vec4(0.0);
        fused.{swz} = normalize(a.{swz});
        len = length(a.{swz});
        steps = vec4(0.0);
        steps.{swz} = a.{swz} / len;
    }}"""
    assert "fnormalize" in _core.glsl_executor_ops(fs, "fragment")
    a = rng.normal(size=(LANES, 4)).astype(np.float32) * np.float32(10.0) ** rng.integers(-15, 16, size=(LANES, 1)).astype(np.float32)
    a[0, :] = 0.0                       # 0 / 0: NaN
    a[1, :n] = [3.0, 4.0, 12.0, 84.0][:n]   # exact lengths (5, 13, 85)
    a[2, 0] = np.inf                    # inf / inf: NaN; the others 0
    a[3, :] = np.float32(1e-30)         # squares underflow to denormals / 0
    x = a[:, :n]
    with np.errstate(invalid="ignore", divide="ignore", over="ignore", under="ignore"):
        total = x[:, 0] * x[:, 0]
        for k in range(1, n):
            total = total + x[:, k] * x[:, k]
        expected = x / np.sqrt(total)[:, None]
        exact = x.astype(np.float64) / np.sqrt(np.sum(x.astype(np.float64) ** 2, axis=1))[:, None]
    for level in _core.glsl_simd_levels():
        out = _core.glsl_run(fs, "fragment", 2, {"a": a}, {}, LANES, {}, 128, 1, level)
        _f32_bits_equal(out["fused"][:, :n], expected, level)
        _f32_bits_equal(out["fused"][:, :n], out["steps"][:, :n], level)
    normal = np.isfinite(exact).all(axis=1) & (np.abs(x) > 1e-18).any(axis=1) & (np.abs(x) < 1e18).all(axis=1)
    got = out["fused"][normal, :n].astype(np.float64)
    assert np.all(np.abs(got - exact[normal]) <= 2 * np.spacing(np.abs(exact[normal]).astype(np.float32)))
    np.testing.assert_array_equal(out["fused"][1, :n], (np.array([3, 4, 12, 84][:n]) / [5, 13, 85][n - 2]).astype(np.float32))


PAIR_FIRST = {"+": np.add, "-": np.subtract, "*": np.multiply, "/": np.divide}
PAIR_SECOND = {"+": np.add, "-": np.subtract, "*": np.multiply,
               "max": lambda x, y: np.where(x < y, y, x),      # GLSL max(x, y) = x < y ? y : x (builtin_math.h)
               "min": lambda x, y: np.where(y < x, y, x)}


@pytest.mark.parametrize("first", list(PAIR_FIRST))
@pytest.mark.parametrize("second", list(PAIR_SECOND))
def test_fused_pairs_equal_their_steps(first, second):
    # t = a.x op1 a.y read once by the next operation (t op2 b.x, or b.y op2 t): one FPair pass.
    # Its bits are the two float32 roundings in order (NumPy), at every SIMD level.
    def second_src(x, y):
        return f"{second}({x}, {y})" if second in ("max", "min") else f"{x} {second} {y}"
    fs = f"""#version 300 es
    precision highp float;
    in vec4 a;
    in vec4 b;
    out vec4 o;
    void main() {{
        o = vec4({second_src(f"(a.x {first} a.y)", "b.x")}, {second_src("b.y", f"(a.z {first} a.w)")}, 0.0, 0.0);
    }}"""
    assert _core.glsl_executor_ops(fs, "fragment").count("fpair") == 2
    a, b = values(4), values(4)
    b[:8, :2] = 0.0
    a[8:12] = 0.0                      # 0 / 0, 0 * inf: NaN
    f1, f2 = PAIR_FIRST[first], PAIR_SECOND[second]
    with np.errstate(invalid="ignore", divide="ignore", over="ignore", under="ignore"):
        expected_x = f2(f1(a[:, 0], a[:, 1]), b[:, 0])
        expected_y = f2(b[:, 1], f1(a[:, 2], a[:, 3]))
    for level in _core.glsl_simd_levels():
        out = _core.glsl_run(fs, "fragment", 2, {"a": a, "b": b}, {}, LANES, {}, 128, 1, level)
        _f32_bits_equal(out["o"][:, 0], expected_x, level)
        _f32_bits_equal(out["o"][:, 1], expected_y, level)


def test_operations_write_the_variable_their_move_copied_to():
    # `c += x`, `c -= x`, `c *= x`, `c /= x` before any control flow: the lowering's temporary and
    # Mov become one operation writing c (reading c in the same lane first). The bits are the
    # float32 steps in order, at every SIMD level; after a branch the Movs stay, with the same bits.
    body = """
        vec4 c = a * 0.5;
        c += b;
        c -= a.wzyx;
        c *= b.yxwz;
        c /= a + 3.0;
        c += b * 0.25;
        o = c;"""
    fs = f"""#version 300 es
    precision highp float;
    in vec4 a;
    in vec4 b;
    out vec4 o;
    void main() {{ {body} }}"""
    branched = fs.replace("void main() {", "void main() { if (a.x > 1e30) { o = vec4(7.0); return; }")
    fused_movs = _core.glsl_executor_ops(fs, "fragment").count("mov")
    kept_movs = _core.glsl_executor_ops(branched, "fragment").count("mov")
    assert fused_movs < kept_movs - 12, (fused_movs, kept_movs)   # six vec4 Movs gone
    a, b = values(4), values(4)
    a[:, :][np.abs(a) > 1e29] = 2.0
    with np.errstate(invalid="ignore", divide="ignore", over="ignore", under="ignore"):
        c = a * np.float32(0.5)
        c = c + b
        c = c - a[:, ::-1]
        c = c * b[:, [1, 0, 3, 2]]
        c = c / (a + np.float32(3.0))
        c = c + b * np.float32(0.25)
    for source in (fs, branched):
        for level in _core.glsl_simd_levels():
            out = _core.glsl_run(source, "fragment", 2, {"a": a, "b": b}, {}, LANES, {}, 128, 1, level)
            for k in range(4):
                _f32_bits_equal(out["o"][:, k], c[:, k], level)


def test_a_variable_read_between_operation_and_move_keeps_the_move():
    # c is read (into d) after `c + b` is computed and before the Mov stores it: writing c early
    # would give d the new value.
    fs = """#version 300 es
    precision highp float;
    in vec4 a;
    in vec4 b;
    out vec4 o;
    void main() {
        vec4 c = a;
        vec4 d;
        vec4 t = c + b;
        d = c * 2.0;
        c = t;
        o = c + d * 3.0;
    }"""
    a, b = values(4), values(4)
    with np.errstate(invalid="ignore", over="ignore"):
        expected = (a + b) + (a * np.float32(2.0)) * np.float32(3.0)
    for level in _core.glsl_simd_levels():
        out = _core.glsl_run(fs, "fragment", 2, {"a": a, "b": b}, {}, LANES, {}, 128, 1, level)
        for k in range(4):
            _f32_bits_equal(out["o"][:, k], expected[:, k], level)
