"""Preprocessor, precision, diagnostics (exact line numbers) and link errors."""
import numpy as np
import pytest

from conftest import compile_errors, compile_ok, run
from softgl import _core

FS_100 = "precision mediump float;\nvoid main() {{ gl_FragColor = vec4({}); }}\n"


def value_of(expr, prelude="", version=1):
    src = prelude + "\nprecision highp float;\nvoid main() { gl_FragColor = vec4(float(" + expr + ")); }\n"
    return run(src, "fragment", version=version)["gl_FragColor"][0, 0]


def test_error_format_and_line_numbers():
    log = compile_errors("precision mediump float;\nvoid main() {\n  float x = 1;\n  gl_FragColor = vec4(y);\n}\n", "fragment", 1)
    lines = log.strip().split("\n")
    assert lines[0].startswith("ERROR: 0:3: ") and "cannot convert" in lines[0]
    assert lines[1].startswith("ERROR: 0:4: ") and "'y' : undeclared identifier" in lines[1]


def test_syntax_error_line():
    log = compile_errors("void main() {\n\n  gl_Position = vec4(1.0)\n}\n", "vertex")
    assert log.startswith("ERROR: 0:4: '}' : syntax error")


def test_precision_defaults():
    log = compile_errors("void main() { gl_FragColor = vec4(1.0); float x = 2.0; }", "fragment", 1)
    assert "No precision specified for (float)" in log
    compile_ok("void main() { float x = 2.0; gl_Position = vec4(x); }", "vertex", 1)  # vertex: highp default
    compile_ok("void main() { gl_FragColor = vec4(1.0); }", "fragment", 1)  # literals need no precision
    log = compile_errors("#version 300 es\nout highp vec4 o;\nuniform sampler3D s;\nvoid main() { o = vec4(1.0); }", "fragment")
    assert "ERROR: 0:3:" in log and "sampler3D" in log
    compile_ok("precision highp float;\nvoid main() { gl_FragColor = vec4(1.0); }", "fragment", 1)
    compile_ok("void main() { mediump float x = 1.0; gl_FragColor = vec4(x); }", "fragment", 1)


def test_preprocessor_macros_and_conditionals():
    prelude = """#define A 3
#define SQR(x) ((x) * (x))
#define ADD(a, b) (a + b)
#if defined(A) && A > 2 && !defined(B)
#define C 10
#elif 1
#define C 20
#else
#error unreachable
#endif
#ifdef A
#undef A
#endif
#ifndef A
#define D SQR(ADD(1, 2))
#endif"""
    assert value_of("C + D", prelude) == 19
    assert value_of("__VERSION__") == 100
    assert value_of("GL_ES") == 1
    assert value_of("__LINE__", "\n\n") == 5
    assert value_of("GL_FRAGMENT_PRECISION_HIGH") == 1
    assert value_of("X", "#if ((1 << 4) | (7 % 4) ^ (~0 & 2)) == 17 && (-7 / 2 == -3) && (5 > 3 ? 1 : 0)\n#define X 1\n#else\n#define X 2\n#endif") == 1


def test_preprocessor_line_directive_and_error():
    log = compile_errors("#line 100\nvoid main() { x; }", "vertex", 1)
    assert "ERROR: 0:100: 'x' : undeclared identifier" in log
    log = compile_errors("#if 1\n#error stop here\n#endif\nvoid main() {}", "vertex", 1)
    assert log.startswith("ERROR: 0:2: '#error' : stop here")
    log = compile_errors("#if FOO\n#endif\nvoid main() {}", "vertex", 1)
    assert "undefined identifier" in log
    log = compile_errors("#if 1\nvoid main() {}", "vertex", 1)
    assert "missing #endif" in log
    log = compile_errors("void main() {}\n#version 100\n", "vertex", 1)
    assert "ERROR: 0:2: '#version' : must occur first" in log
    log = compile_errors("#version 300 es\nvoid main() {}", "vertex", 1)
    assert "not supported" in log
    log = compile_errors("#define GL_FOO 1\nvoid main() {}", "vertex", 1)
    assert "reserved" in log
    log = compile_errors("#extension GL_NOT_REAL : require\nvoid main() {}", "vertex", 1)
    assert "not supported" in log
    compile_ok("#pragma optimize(off)\n#extension GL_OES_standard_derivatives : enable\n#\nvoid main() { gl_Position = vec4(0.0); }", "vertex", 1)
    compile_ok("#version 300 es\n// comment\n#define X(a) a\nvoid main() { gl_Position = vec4(X(1.0)); }", "vertex", 2)


def test_semantic_errors():
    cases = [
        ("vertex", 1, "void main() { const float c; }", "must be initialized"),
        ("vertex", 1, "uniform float u; void main() { u = 1.0; }", "l-value"),
        ("vertex", 1, "attribute float a; void main() { a = 1.0; gl_Position = vec4(a); }", "l-value"),
        ("vertex", 1, "void main() { vec3 v; v.xx = vec2(1.0); }", "duplicate components"),
        ("vertex", 1, "void main() { vec2 v = vec2(1.0); float f = v.z; }", "out of range"),
        ("vertex", 1, "void main() { int i = 1 + 1.0; }", "wrong operand types"),
        ("vertex", 1, "void main() { discard; }", "only allowed in fragment"),
        ("vertex", 1, "void main() { break; }", "break"),
        ("vertex", 1, "float f(); void main() { float x = f(1.0); }", "no matching overloaded function"),
        ("vertex", 1, "float f(float x) { return f(x); } void main() { gl_Position = vec4(f(1.0)); }", "recursive"),
        ("vertex", 1, "void main() { int x = 0; int x = 1; }", "redefinition"),
        ("vertex", 1, "void main() { float a[0]; }", "greater than zero"),
        ("vertex", 1, "void main() { float gl_x = 1.0; }", "reserved"),
        ("vertex", 1, "void main() { while (true) {} }", "This type of loop is not allowed"),
        ("fragment", 2, "#version 300 es\nprecision mediump float;\nout vec4 a; out vec4 b;\nvoid main() { a = vec4(1.0); b = a; }", "locations"),
        ("fragment", 2, "#version 300 es\nprecision mediump float;\nin int i;\nout vec4 o;\nvoid main() { o = vec4(i); }", "flat"),
        ("vertex", 2, "#version 300 es\nattribute vec4 a;\nvoid main() {}", "reserved"),
        ("vertex", 1, "void main() { gl_Position = texture(vec2(0.0)); }", "no matching overloaded function"),
    ]
    for stage, version, src, needle in cases:
        log = compile_errors(src, stage, version)
        assert needle in log, (src, log)
        assert log.startswith("ERROR: 0:"), log


def test_missing_main():
    assert "Missing main()" in compile_errors("void f() {}", "vertex", 1)


VS = """attribute vec4 p;
varying vec3 v;
uniform mediump float shared;
void main() { v = p.xyz * shared; gl_Position = p; }"""


def test_link_errors():
    ok, log, _ = _core.glsl_link(VS, "precision mediump float; varying vec2 v; void main() { gl_FragColor = vec4(v, 0.0, 1.0); }", 1)
    assert not ok and "Types of varying 'v' differ" in log
    ok, log, _ = _core.glsl_link(VS, "precision mediump float; varying vec3 w; void main() { gl_FragColor = vec4(w, 1.0); }", 1)
    assert not ok and "'w'" in log
    ok, log, _ = _core.glsl_link(VS, "precision mediump float; uniform highp float shared; void main() { gl_FragColor = vec4(shared); }", 1)
    assert not ok and "Precisions of uniform 'shared'" in log
    ok, log, _ = _core.glsl_link(VS, "precision mediump float; uniform vec2 shared; void main() { gl_FragColor = vec4(shared, 0.0, 0.0); }", 1)
    assert not ok and "Types of uniform 'shared'" in log
    many = "\n".join(f"varying vec4 v{i};" for i in range(9))
    vs = many + "\nvoid main() {" + "".join(f"v{i} = vec4({i}.0);" for i in range(9)) + "gl_Position = vec4(0.0); }"
    fs = "precision mediump float;\n" + many + "\nvoid main() { gl_FragColor = " + " + ".join(f"v{i}" for i in range(9)) + "; }"
    ok, log, _ = _core.glsl_link(vs, fs, 1, {"max_varying_vectors": 8})
    assert not ok and "Too many varyings" in log
    ok, log, _ = _core.glsl_link(vs, fs, 1, {"max_varying_vectors": 15})
    assert ok, log
    attrs = "\n".join(f"attribute vec4 a{i};" for i in range(17))
    vs = attrs + "\nvoid main() { gl_Position = " + " + ".join(f"a{i}" for i in range(17)) + "; }"
    ok, log, _ = _core.glsl_link(vs, "void main() { gl_FragColor = vec4(1.0); }", 1)
    assert not ok and "Too many attributes" in log


def test_link_reflection_and_skipping_info():
    fs = """precision mediump float;
    varying vec3 v;
    uniform mediump float shared;
    uniform sampler2D tex;
    struct S { float a; vec2 b[2]; };
    uniform S s[2];
    void main() {
        if (v.x < 0.0) discard;
        gl_FragColor = vec4(v * shared, s[1].b[1].y) + texture2D(tex, gl_FragCoord.xy) * s[0].a;
    }"""
    ok, log, prog = _core.glsl_link(VS, fs, 1, {}, {"p": 3})
    assert ok, log
    assert prog["attributes"][0]["location"] == 3
    names = [u["name"] for u in prog["uniforms"] if u["active"]]
    assert "s[1].b[0]" in names and "s[0].a" in names and "shared" in names and "tex" in names
    assert prog["fragment"]["may_discard"] and prog["fragment"]["reads_frag_coord"] and prog["fragment"]["uses_derivatives"]
    assert not prog["fragment_depends_only_on_uniforms"]
    shared = [u for u in prog["uniforms"] if u["name"] == "shared"]
    assert len(shared) == 1


def test_unused_varyings_are_not_interpolated():
    vs = "attribute vec4 p; varying vec4 used; varying vec4 unused; void main() { used = p; unused = p * 2.0; gl_Position = p; }"
    fs = "precision mediump float; varying vec4 used; varying vec4 unused; void main() { gl_FragColor = used; }"
    ok, log, prog = _core.glsl_link(vs, fs, 1)
    assert ok, log
    assert [v["name"] for v in prog["varyings"]] == ["used"]
    r = compile_ok(fs, "fragment", 1)
    assert r["varyings_read"] == ["used"]


def test_constant_folding_and_dead_code():
    r = compile_ok("""precision mediump float;
    const float k = 2.0 * 3.0;
    uniform float u;
    void main() {
        float unused = sin(u) * 4.0;
        if (k > 100.0) { gl_FragColor = vec4(sin(u)); return; }
        gl_FragColor = vec4(sqrt(k * k) + exp2(3.0));
    }""", "fragment", 1)
    assert r["instructions"] <= 8, r["ir"]
    assert r["output_depends_only_on_uniforms"]
    assert not any(u["active"] for u in r["uniforms"])
    out = run("""precision mediump float; const float k = 2.0 * 3.0;
    void main() { gl_FragColor = vec4(sqrt(k * k) + exp2(3.0)); }""", "fragment", version=1)
    assert out["gl_FragColor"][0, 0] == 14.0


def test_es100_array_elements_are_lvalues():
    """GLSL ES 1.00 §5.8: whole arrays cannot be assigned, their elements can (gl_FragData[n],
    local arrays)."""
    src = ("#extension GL_EXT_draw_buffers : require\nprecision highp float;\n"
           "void main() { float a[2]; a[0] = 0.25; a[1] = 0.5;\n"
           "gl_FragData[0] = vec4(a[0]); gl_FragData[1].xy = vec2(a[1]); }\n")
    compile_ok(src, "fragment", version=1)
    assert "arrays cannot be assigned" in compile_errors(
        "precision highp float;\nvoid main() { float a[2]; float b[2]; a = b; gl_FragColor = vec4(0.0); }\n",
        "fragment", version=1)
    assert value_of("f()", "precision highp float; float f() { float a[2]; a[0] = 1.0; a[1] = 0.75; return a[1]; }",
                    version=1) == np.float32(0.75)
