"""Unrolled counted loops (glsl/lower.cpp, "loop unrolling"): a for loop with an int index and a
constant start, bound and step is lowered as copies of its body with the index a constant. Each
unrolled shader is compared bit for bit with a twin whose bound is a uniform of the same value
(a loop the lowering cannot unroll), at every SIMD level, and the IR shows which one was unrolled."""
import numpy as np
import pytest

from softgl import _core

SIMD = _core.glsl_simd_levels()

HEADER = """#version 300 es
precision highp float; precision highp int;
uniform int uN;
uniform int uM;
uniform vec3 uL[3];
uniform float uW[5];
in vec4 a;
out vec4 o;
"""

rng = np.random.default_rng(18)
A = rng.uniform(-2, 2, (37, 4)).astype(np.float32)
UNIFORMS = {"uL": rng.uniform(-1, 1, 9).astype(np.float32), "uW": rng.uniform(-1, 1, 5).astype(np.float32)}


def ir(source):
    return _core.glsl_ir(HEADER + source, "fragment", 2)


def run(source, simd, **ints):
    uniforms = dict(UNIFORMS, **ints)
    return _core.glsl_run(HEADER + source, "fragment", 2, {"a": A}, uniforms, A.shape[0], {}, 128, simd=simd)["o"]


def assert_unrolled_like_loop(constant_source, uniform_source, ints):
    assert "endloop" not in ir(constant_source)
    assert "endloop" in ir(uniform_source)
    for simd in SIMD:
        unrolled, looped = run(constant_source, simd, **ints), run(uniform_source, simd, **ints)
        assert unrolled.tobytes() == looped.tobytes(), simd


BODY = """void main() {
    vec4 s = a;
    for (int i = START; i CMP BOUND; STEP) {
        float f = float(i);
        s.x = s.x * 1.0001 + sin(f * a.y) / (a.z * a.z + f + 1.0);
        s.y += uW[i] * exp2(a.w * 0.25) - uL[i].y * f;
        s.z = fract(s.z * 3.7 + uL[i + 1].x);
        s.w += float(i * i - 2 * i) * a.x + float(i.x) * 0.5 + float(ivec2(i).y);
    }
    o = s;
}"""


@pytest.mark.parametrize("start,cmp,bound,step", [
    (0, "<", 0, "i++"), (0, "<", 1, "i++"), (0, "<", 3, "i++"), (1, "<", 5, "i++"), (0, "<=", 4, "i++"),
    (4, ">=", 0, "i--"), (0, "<", 5, "i += 2"), (4, ">", -1, "i -= 3"), (-2, "!=", 3, "i++"), (0, "<", 16, "i++"),
])
def test_unrolled_loop_gives_the_loops_bits(start, cmp, bound, step):
    # Indices outside uW/uL (negative, past the end, i + 1) are clamped the same way in both.
    src = BODY.replace("START", str(start)).replace("CMP", cmp).replace("STEP", step)
    assert_unrolled_like_loop(src.replace("BOUND", str(bound)), src.replace("BOUND", "uN"), {"uN": bound})


def test_nested_loops_and_local_arrays():
    src = """void main() {
        float w[5];
        for (int i = 0; i < 5; i++) w[i] = a.x * float(i) + uW[4 - i];
        vec4 s = vec4(0.0);
        for (int i = 0; i < OUTER; i++) {
            for (int j = 0; j < 4; j++) {
                s.x += w[i + j] * uL[j].z - float(i * 4 + j);
                s.y = s.y * a.y + w[j];
            }
            s.z += uL[i].x * w[4 - i] + uL[-i + 2].y + w[i * 2 - 1];
        }
        s.w = w[2];
        o = s;
    }"""
    assert "load.indexed" not in ir(src.replace("OUTER", "3")) and "load.uniform.indexed" not in ir(src.replace("OUTER", "3"))
    assert_unrolled_like_loop(src.replace("OUTER", "3"), src.replace("OUTER", "uN"), {"uN": 3})


def test_long_index_chain_in_an_unrolled_loop():
    # An index expression nested too deep to be evaluated while lowering stays a dynamic index.
    chain = "i" + " + 1 - 1" * 12
    src = "void main() { float s = 0.0; for (int i = 0; i < 3; i++) s += uW[" + chain + "]; o = vec4(s); }"
    assert_unrolled_like_loop(src, src.replace("i < 3", "i < uN"), {"uN": 3})


def test_spot_lights_loop_matches_float64():
    # Three lights (like benchmarks/ordinary.py spot_plane): an independent float64 evaluation.
    src = """void main() {
        vec3 c = vec3(0.04);
        for (int i = 0; i < 3; i++) {
            vec3 l = normalize(uL[i] - a.xyz);
            c += uW[i] * max(dot(l, vec3(0.0, 0.0, 1.0)), 0.0) * vec3(1.0, 0.5, 0.25);
        }
        o = vec4(c, 1.0);
    }"""
    assert "endloop" not in ir(src) and "load.uniform.indexed" not in ir(src)
    light = UNIFORMS["uL"].astype(np.float64).reshape(3, 3)
    weight = UNIFORMS["uW"].astype(np.float64)
    p = A[:, :3].astype(np.float64)
    c = np.full((A.shape[0], 3), 0.04)
    for i in range(3):
        l = light[i] - p
        l /= np.linalg.norm(l, axis=1, keepdims=True)
        c += weight[i] * np.maximum(l[:, 2], 0.0)[:, None] * np.array([1.0, 0.5, 0.25])
    for simd in SIMD:
        np.testing.assert_allclose(run(src, simd)[:, :3], c, rtol=2e-6, atol=2e-6)


@pytest.mark.parametrize("loop", [
    "for (int i = 0; i < 4; i++) { if (float(i) > a.x) break; s += uW[i]; }",
    "for (int i = 0; i < 4; i++) { if (float(i) > a.x) continue; s += uW[i]; }",
    "for (int i = 0; i < 4; i++) { if (float(i) > a.x) discard; s += uW[i]; }",
    "for (int i = 0; i < 4; i++) { switch (i) { case 1: s += 1.0; break; default: s += uW[i]; } }",
    "for (int i = 0; i < 4; i++) { float t; if (a.y > 0.0) t = uW[i]; s += t; }",   # t keeps the last trip's value
    "for (int i = 0; i < uM; i++) { s += uW[i]; }",
    "for (int i = 0; i < 400; i++) { s += uW[i / 100]; }",
    "for (int i = 0; i < 12; i++) { for (int j = 0; j < 12; j++) { s += uW[i / 3] * float(j); } }",
    "for (float f = 0.0; f < 4.0; f += 1.0) { s += f * a.y; }",
])
def test_loops_that_stay_loops(loop):
    src = "void main() { float s = a.x; " + loop + " o = vec4(s); }"
    assert "endloop" in ir(src)
    # Still the same result at every level.
    outs = [run(src, simd, uM=4) for simd in SIMD]
    for out in outs[1:]:
        assert out.tobytes() == outs[0].tobytes()


def test_loop_calling_a_user_function_stays_a_loop():
    # Functions with loops calling each other would multiply their copies.
    src = """float g(float x) { float t = 0.0; for (int j = 0; j < 4; j++) t += x * float(j); return t; }
    void main() { float s = 0.0; for (int i = 0; i < 4; i++) s += g(a.x + float(i)); o = vec4(s); }"""
    assert ir(src).count("endloop") == 1   # main's loop stays; g's (no call) is unrolled
    outs = [run(src, simd).tobytes() for simd in SIMD]
    looped = [run(src.replace("j < 4", "j < uN"), simd, uN=4).tobytes() for simd in SIMD]
    assert outs == looped
