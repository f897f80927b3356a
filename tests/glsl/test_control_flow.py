import numpy as np

from conftest import run

HEADER = """#version 300 es
precision highp float; precision highp int;
in vec4 a;
out vec4 o;
"""

rng = np.random.default_rng(3)


def frag(body, a, lanes=None):
    return run(HEADER + body, "fragment", {"a": a.astype(np.float32)}, lanes=lanes or a.shape[0])


def test_if_else_divergent():
    a = rng.uniform(-1, 1, (16, 4))
    out = frag("void main() { if (a.x > 0.0) { o = vec4(1.0); } else if (a.y > 0.0) { o = vec4(2.0); } else { o = vec4(3.0); } }", a)
    expected = np.where(a[:, 0] > 0, 1, np.where(a[:, 1] > 0, 2, 3))
    np.testing.assert_array_equal(out["o"][:, 0], expected.astype(np.float32))


def test_loops_break_continue_per_lane():
    a = np.zeros((8, 4)); a[:, 0] = np.arange(8)
    body = """void main() {
        float s = 0.0;
        for (int i = 0; i < 20; i++) {
            if (float(i) > a.x) break;
            if (i % 2 == 1) continue;
            s += float(i);
        }
        int k = 0; float w = 0.0;
        while (k < int(a.x)) { w += 2.0; k++; }
        int d = 0;
        do { d++; } while (d < 3);
        o = vec4(s, w, float(d), 0.0);
    }"""
    out = frag(body, a)
    for lane in range(8):
        n = int(a[lane, 0])
        assert out["o"][lane, 0] == sum(i for i in range(0, n + 1) if i % 2 == 0)
        assert out["o"][lane, 1] == 2 * n
        assert out["o"][lane, 2] == 3


def test_early_return_from_function_and_main():
    a = rng.uniform(-1, 1, (16, 4))
    body = """float f(float x) { if (x < 0.0) return -1.0; for (int i = 0; i < 4; i++) { if (i == 2) return float(i) * x; } return 9.0; }
    void main() {
        o = vec4(f(a.x), 0.0, 0.0, 0.0);
        if (a.y > 0.5) return;
        o.y = 7.0;
    }"""
    out = frag(body, a)
    np.testing.assert_array_equal(out["o"][:, 0], np.where(a[:, 0] < 0, -1, 2 * a[:, 0].astype(np.float32)))
    np.testing.assert_array_equal(out["o"][:, 1], np.where(a[:, 1] > 0.5, 0, 7))


def test_discard_mask():
    a = rng.uniform(-1, 1, (16, 4))
    out = frag("void main() { o = vec4(1.0); if (a.z < 0.0) discard; o = vec4(2.0); }", a)
    np.testing.assert_array_equal(out["discarded"], a[:, 2].astype(np.float32) < 0)
    np.testing.assert_array_equal(out["o"][~out["discarded"], 0], 2)


def test_switch_with_fallthrough_and_default():
    a = np.zeros((8, 4)); a[:, 0] = np.arange(8)
    body = """void main() {
        float r = 0.0;
        switch (int(a.x)) {
            case 0: r = 10.0; break;
            case 1:
            case 2: r = 20.0;
            case 3: r += 1.0; break;
            default: r = -1.0;
        }
        o = vec4(r);
    }"""
    out = frag(body, a)
    np.testing.assert_array_equal(out["o"][:, 0], [10, 21, 21, 1, -1, -1, -1, -1])


def test_out_inout_parameters_and_arrays():
    a = rng.uniform(-1, 1, (8, 4))
    body = """void split(in vec4 v, out float s, inout float acc) { s = v.x + v.y; acc += s; }
    void main() {
        float arr[4];
        for (int i = 0; i < 4; i++) arr[i] = a[i] * float(i);
        float s; float acc = 1.0;
        split(a, s, acc);
        int j = int(a.w > 0.0) + 1;
        o = vec4(s, acc, arr[j], arr.length());
    }"""
    out = frag(body, a)
    A = a.astype(np.float32)
    np.testing.assert_array_equal(out["o"][:, 0], A[:, 0] + A[:, 1])
    np.testing.assert_array_equal(out["o"][:, 1], 1 + (A[:, 0] + A[:, 1]))
    j = (A[:, 3] > 0).astype(int) + 1
    np.testing.assert_array_equal(out["o"][:, 2], A[np.arange(8), j] * j)
    assert np.all(out["o"][:, 3] == 4)


def test_structs_and_short_circuit():
    a = rng.uniform(-1, 1, (8, 4))
    body = """struct Light { vec3 color; float power; };
    float counter = 0.0;
    bool bump() { counter += 1.0; return true; }
    void main() {
        Light l = Light(a.xyz, 2.0);
        Light m = l;
        m.power *= 3.0;
        bool t = a.x > 0.0 && bump();
        o = vec4(m.color * m.power, counter + (t ? 10.0 : 0.0));
    }"""
    out = frag(body, a)
    A = a.astype(np.float32)
    np.testing.assert_array_equal(out["o"][:, :3], A[:, :3] * 6)
    np.testing.assert_array_equal(out["o"][:, 3], np.where(A[:, 0] > 0, 11, 0))


def test_results_independent_of_batch_and_lane_count():
    src = HEADER + """void main() {
        float s = 0.0;
        for (int i = 0; i < 8; i++) { if (a.x * float(i) > 2.0) break; s += sin(a.y * float(i)); }
        if (a.z < -0.5) discard;
        o = vec4(s, dFdx(a.x), dFdy(a.y), pow(abs(a.w), 0.3));
    }"""
    a = rng.uniform(-1, 1, (200, 4)).astype(np.float32)
    ref = run(src, "fragment", {"a": a}, lanes=200, batch=128)
    for batch in (4, 8, 36, 256):
        out = run(src, "fragment", {"a": a}, lanes=200, batch=batch)
        np.testing.assert_array_equal(out["o"][~out["discarded"]], ref["o"][~ref["discarded"]])
    sub = run(src, "fragment", {"a": a[:40]}, lanes=40)
    np.testing.assert_array_equal(sub["o"][~sub["discarded"]], ref["o"][:40][~ref["discarded"][:40]])


def test_infinite_loop_is_reported_not_hung():
    import pytest
    src = "void main() { float x = 0.0; while (a.x < 2.0) { x += 1.0; } o = vec4(x); }"
    with pytest.raises(RuntimeError, match="work budget exhausted"):
        frag(src, np.zeros((4, 4)))
