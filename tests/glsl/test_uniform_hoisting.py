"""Values that depend only on uniforms and constants are computed once, before the lanes (the
executor's prologue, glsl/executor.cpp order_prologue): the bits each lane gets must be the ones it
computed itself (hoist=False, where only the leading uniform loads run first), at every SIMD level
and batch size, inside unrolled loops and branches, with NaN and infinite uniforms, and match
float32 steps done by NumPy or float64 formulas."""
import numpy as np
import pytest

from softgl import _core

LANES = 4 * 37
rng = np.random.default_rng(18)

SPOT_FS = """#version 300 es
precision highp float;
const int numLights = 3;
uniform vec3 uLightDir[numLights];
uniform vec3 uLightColor[numLights];
uniform float uCutoff;
uniform float uExponent;
in vec3 vPos;
layout(location = 0) out vec4 o;
layout(location = 1) out vec4 p;
void main() {
  vec3 c = vec3(0.0);
  float q = 0.0;
  for (int i = 0; i < numLights; i++) {
    vec3 d = normalize(uLightDir[i]);          // uniform only: hoisted
    float s = dot(normalize(vPos), d);
    if (s > cos(uCutoff)) {                      // cos of a uniform: hoisted
      c += uLightColor[i] * uLightColor[i].x * pow(max(s, 0.0), uExponent);
      q += pow(uExponent, 0.5) * float(i + 1);   // inside the branch, uniform only: hoisted
    }
  }
  o = vec4(c, q);
  p = vec4(uCutoff / uExponent, sqrt(uExponent) + 1.0, uLightDir[0].x * uLightDir[1].y, exp2(uCutoff));
}
"""


def spot_uniforms(special=None):
    u = {
        "uLightDir": np.array([[0.3, -1.0, 0.2], [-0.5, -0.8, 0.1], [0.0, 0.0, 0.0]], np.float32),
        "uLightColor": np.array([[0.9, 0.4, 0.2], [0.1, 0.8, 0.3], [0.5, 0.5, 1.0]], np.float32),
        "uCutoff": np.float32(0.7),
        "uExponent": np.float32(12.0),
    }
    if special is not None:
        u.update(special)
    return u


def spot_inputs():
    v = rng.normal(size=(LANES, 3)).astype(np.float32)
    v[:, 1] = -np.abs(v[:, 1])   # mostly towards the lights: both sides of the branch are taken
    return {"vPos": v}


def bits(out):
    return {k: v.view(np.uint32).copy() for k, v in out.items() if k in ("o", "p")}


SPECIALS = [None, {"uExponent": np.float32(np.nan)}, {"uExponent": np.float32(np.inf)},
            {"uCutoff": np.float32(-np.inf)}, {"uLightDir": np.array([[np.inf, 1, 0], [np.nan, 0, 0], [0, 0, 0]], np.float32)},
            {"uExponent": np.float32(0.0), "uCutoff": np.float32(np.nan)}]


def test_uniform_only_values_are_in_the_prologue():
    ops = _core.glsl_executor_prologue(SPOT_FS, "fragment")
    assert "load.uniform" in ops
    assert ops.count("fnormalize") == 3   # normalize(uLightDir[i])
    assert ops.count("fcos") == 3 and ops.count("fpow") == 3 and "fexp2" in ops
    # Nothing reading a varying is hoisted: the prologue's ops are all before the lanes' code.
    body = _core.glsl_executor_ops(SPOT_FS, "fragment")[len(ops):]
    assert body.count("fpow") == 3   # pow(max(s, 0), uExponent) per light stays per lane


@pytest.mark.parametrize("special", range(len(SPECIALS)))
@pytest.mark.parametrize("simd", _core.glsl_simd_levels())
@pytest.mark.parametrize("batch", [4, 20, 128])
def test_hoisted_values_give_the_lanes_own_bits(special, simd, batch):
    inputs, uniforms = spot_inputs(), spot_uniforms(SPECIALS[special])
    hoisted = _core.glsl_run(SPOT_FS, "fragment", 2, inputs, uniforms, LANES, {}, batch, 2, simd, True)
    reference = _core.glsl_run(SPOT_FS, "fragment", 2, inputs, uniforms, LANES, {}, batch, 1, "portable", False)
    for k, v in bits(reference).items():
        np.testing.assert_array_equal(bits(hoisted)[k], v, err_msg=k)


def test_hoisted_values_match_independent_expectations():
    inputs, u = spot_inputs(), spot_uniforms()
    out = _core.glsl_run(SPOT_FS, "fragment", 2, inputs, u, LANES, {}, 128, 1, "", True)
    e, c = u["uExponent"], u["uCutoff"]
    # p: one correctly rounded float32 operation each (NumPy float32 does the same), exp2 in float64.
    p = out["p"]
    assert p[:, 0].view(np.uint32).tolist() == [np.float32(c / e).view(np.uint32)] * LANES
    assert p[:, 1].tolist() == [float(np.float32(np.sqrt(e)) + np.float32(1.0))] * LANES
    assert p[:, 2].tolist() == [float(u["uLightDir"][0, 0] * u["uLightDir"][1, 1])] * LANES
    np.testing.assert_allclose(p[:, 3], 2.0 ** np.float64(c), rtol=2e-7)
    # o in float64 from the formula (the third light's direction normalises 0/0: NaN, never lit).
    d = u["uLightDir"].astype(np.float64)
    n = inputs["vPos"].astype(np.float64)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    col = np.zeros((LANES, 3))
    q = np.zeros(LANES)
    for i in range(2):
        s = n @ (d[i] / np.linalg.norm(d[i]))
        lit = s > np.cos(np.float64(c))
        col += lit[:, None] * (u["uLightColor"][i].astype(np.float64) * float(u["uLightColor"][i, 0])) * \
            (np.maximum(s, 0.0) ** float(e))[:, None]
        q += lit * np.sqrt(float(e)) * (i + 1)
    near_edge = np.abs(n @ (d[0] / np.linalg.norm(d[0])) - np.cos(c)) < 1e-5
    near_edge |= np.abs(n @ (d[1] / np.linalg.norm(d[1])) - np.cos(c)) < 1e-5
    ok = ~near_edge
    assert ok.sum() > LANES // 2 and q[ok].min() == 0 < q[ok].max()   # lanes on both sides of the branches
    np.testing.assert_allclose(out["o"][ok, :3], col[ok], rtol=1e-5, atol=1e-7)
    np.testing.assert_allclose(out["o"][ok, 3], q[ok], rtol=1e-6)


def test_nothing_lane_dependent_is_hoisted():
    # Derivatives, texture lookups, indexed loads of variables and values read from varyings or
    # variables written under a mask stay in the lanes' code.
    fs = """#version 300 es
    precision highp float;
    uniform float u;
    uniform sampler2D t;
    in float a;
    out vec4 o;
    void main() {
        float arr[3] = float[3](u, u * 2.0, u * 3.0);
        float v = u;
        if (a > 0.0) v = u * 4.0;
        o = vec4(dFdx(u * 5.0), texture(t, vec2(u)).x, arr[int(a) & 1], v * 6.0);
    }"""
    ops = _core.glsl_executor_prologue(fs, "fragment")
    assert "dfdx" not in ops and "texture" not in ops and "load.indexed" not in ops
    a = np.array([1.0, -1.0, 0.0, 2.0] * 5, np.float32)
    tex = {0: np.full((2, 2, 4), 0.25, np.float32)}
    for simd in _core.glsl_simd_levels():
        h = _core.glsl_run(fs, "fragment", 2, {"a": a}, {"u": np.float32(1.5), "t": 0}, 20, tex, 8, 1, simd, True)
        r = _core.glsl_run(fs, "fragment", 2, {"a": a}, {"u": np.float32(1.5), "t": 0}, 20, tex, 8, 1, simd, False)
        np.testing.assert_array_equal(h["o"].view(np.uint32), r["o"].view(np.uint32))
    # dFdx of a uniform value is 0; v * 6 is 36 where a > 0, else 9
    assert h["o"][:, 0].tolist() == [0.0] * 20
    assert h["o"][:, 3].tolist() == [36.0 if x > 0 else 9.0 for x in a]


def test_integer_division_by_zero_hoisted_out_of_an_untaken_branch_is_harmless():
    fs = """#version 300 es
    precision highp float;
    precision highp int;
    uniform int n;
    uniform int d;
    in float a;
    out vec4 o;
    void main() {
        int q = 7;
        if (d != 0 && a > 100.0) q = n / d + n % d;   // never taken; n / d is hoisted
        int r = (n / (d + 1)) * 3;                     // INT_MIN / -1 when d = -2, n = INT_MIN
        o = vec4(float(q), float(r), 0.0, 1.0);
    }"""
    a = np.zeros(8, np.float32)
    for n, d in [(5, 0), (-2**31, -1), (-2**31, -2)]:
        h = _core.glsl_run(fs, "fragment", 2, {"a": a}, {"n": n, "d": d}, 8, {}, 4, 1, "", True)
        r = _core.glsl_run(fs, "fragment", 2, {"a": a}, {"n": n, "d": d}, 8, {}, 4, 1, "", False)
        np.testing.assert_array_equal(h["o"].view(np.uint32), r["o"].view(np.uint32))
        assert h["o"][:, 0].tolist() == [7.0] * 8
