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
