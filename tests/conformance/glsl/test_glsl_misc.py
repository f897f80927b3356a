"""conformance/glsl/misc (WebGL 1 / GLSL ES 1.00 compile and link expectations). Each entry:
their test name, the stage, a source of our own exhibiting the same rule, and whether it must
compile. Rules: GLSL ES 1.00 spec sections and WebGL 1.0 §6.x, as cited."""
import pytest

from conformance.helpers import compiles, context, try_link

V, F = "vertex", "fragment"
P = "precision mediump float;\n"
CASES = [
    ("shader-with-256-character-identifier.frag", F, P + "float %s = 1.0; void main() { gl_FragColor = vec4(%s); }" % ("a" * 256, "a" * 256), True),
    ("shader-with-257-character-identifier.frag", F, P + "float %s = 1.0; void main() { gl_FragColor = vec4(%s); }" % ("a" * 257, "a" * 257), False),  # WebGL 1.0 §6.21
    ("shader-with-_webgl-identifier.vert", V, "float _webgl_x; void main() { gl_Position = vec4(_webgl_x); }", False),  # WebGL 1.0 §6.19
    ("shader-with-version-100.vert", V, "#version 100\nvoid main() { gl_Position = vec4(0.0); }", True),
    ("shader-with-version-120.vert", V, "#version 120\nvoid main() { gl_Position = vec4(0.0); }", False),
    ("shader-with-glcolor.vert", V, "void main() { gl_Position = gl_Color; }", False),
    ("shader-with-glprojectionmatrix.vert", V, "void main() { gl_Position = gl_ProjectionMatrix * vec4(1.0); }", False),
    ("shader-with-clipvertex.vert", V, "void main() { gl_Position = vec4(0.0); gl_ClipVertex = vec4(0.0); }", False),
    ("shader-with-include.vert", V, '#include "foo"\nvoid main() { gl_Position = vec4(0.0); }', False),
    ("shader-with-function-recursion.frag", F, P + "float f(float x) { return x > 0.0 ? f(x - 1.0) : 0.0; } void main() { gl_FragColor = vec4(f(2.0)); }", False),  # ES 1.00 §6.1
    ("shader-with-dfdx-no-ext.frag", F, P + "void main() { gl_FragColor = vec4(dFdx(gl_FragCoord.x)); }", False),
    pytest.param("shader-with-attrib-array.vert", V, "attribute vec4 a[2]; void main() { gl_Position = a[0]; }", False),  # ES 1.00 §4.3.3
    ("shader-with-attrib-struct.vert", V, "struct S { vec4 v; }; attribute S s; void main() { gl_Position = s.v; }", False),
    ("shader-without-precision.frag", F, "void main() { float f = 1.0; gl_FragColor = vec4(f); }", False),  # ES 1.00 §4.5.3
    ("shader-with-default-precision.frag", F, P + "void main() { gl_FragColor = vec4(1.0); }", True),
    ("shader-with-default-precision.vert", V, "precision highp float; void main() { gl_Position = vec4(1.0); }", True),
    ("shader-with-illegal-default-precision.vert", V, "precision mediump vec4; void main() { gl_Position = vec4(1.0); }", False),
    ("shader-with-illegal-default-precision.frag", F, "precision mediump vec2; void main() { gl_FragColor = vec4(1.0); }", False),
    ("shader-with-error-directive.html", F, P + "#error this must fail\nvoid main() { gl_FragColor = vec4(1.0); }", False),
    ("shader-with-undefined-preprocessor-symbol.frag", F, P + "#if UNDEFINED_SYMBOL\n#endif\nvoid main() { gl_FragColor = vec4(1.0); }", False),  # ES 1.00 §3.4
    ("shader-with-gles-1.frag", F, P + "#if GL_ES == 1\nvoid main() { gl_FragColor = vec4(1.0); }\n#endif", True),
    ("shader-with-gles-symbol.frag", F, P + "#ifndef GL_ES\n#error\n#endif\nvoid main() { gl_FragColor = vec4(1.0); }", True),
    ("shader-with-hex-int-constant-macro.html", V, "#define K 0x1F\nvoid main() { int k = K; gl_Position = vec4(float(k)); }", True),
    ("shader-with-comma-assignment.html", F, P + "void main() { float a, b; a = (b = 0.5, b + 0.25); gl_FragColor = vec4(a); }", True),
    ("shader-with-comma-separated-variable-declarations.html", F, P + "void main() { float a = 1.0, b = a, c; c = b; gl_FragColor = vec4(c); }", True),
    ("shader-with-float-return-value.frag", F, P + "float f() { return 1.0; } void main() { gl_FragColor = vec4(f()); }", True),
    ("shader-with-ivec3-return-value.frag", F, P + "ivec3 f() { return ivec3(1); } void main() { gl_FragColor = vec4(vec3(f()), 1.0); }", True),
    ("shader-with-explicit-int-cast.vert", V, "void main() { int k = int(2.7); gl_Position = vec4(float(k)); }", True),
    ("shader-with-implicit-vec3-to-vec4-cast.vert", V, "void main() { vec4 v = vec3(1.0); gl_Position = v; }", False),  # no implicit conversions
    ("shader-with-vec4-vec3-vec4-conditional.html", F, P + "void main() { gl_FragColor = true ? vec4(1.0) : vec3(1.0); }", False),
    ("shader-with-frag-depth.frag", F, P + "void main() { gl_FragDepth = 0.5; gl_FragColor = vec4(1.0); }", False),
    ("shader-with-non-ascii-error.frag", F, P + "void main() { float \u00e9 = 1.0; gl_FragColor = vec4(1.0); }", False),
    ("non-ascii-comments.vert", V, "// \u00e9\u00e8 \u2603\n/* \u00fc */ void main() { gl_Position = vec4(0.0); }", True),
    ("embedded-struct-definitions-forbidden.html", F, P + "struct S { struct T { float f; } t; }; void main() { gl_FragColor = vec4(1.0); }", False),
    ("constant-index-out-of-range.html", F, P + "void main() { float a[2]; a[0] = 1.0; a[1] = 1.0; gl_FragColor = vec4(a[2]); }", False),  # ES 1.00 §4.1.9
    ("empty_main.vert", V, "void main() {}", True),
    ("gl_position_unset.vert", V, "void main() { float x = 1.0; }", True),
    ("shader-with-long-line.html", F, P + "void main() { float x = 0.0" + " + 1.0" * 2000 + "; gl_FragColor = vec4(x); }", True),
    ("shader-with-precision.frag", F, "precision lowp float; uniform highp vec4 u; void main() { mediump float m = u.x; gl_FragColor = vec4(m); }", True),
    ("shader-with-for-loop.html", F, P + "void main() { float s = 0.0; for (int i = 0; i < 4; ++i) s += 0.25; gl_FragColor = vec4(s); }", True),
    ("shader-with-function-scoped-struct.html", F, P + "void main() { struct S { float f; }; S s = S(1.0); gl_FragColor = vec4(s.f); }", True),
]
RESERVED = ["asm", "class", "union", "enum", "typedef", "template", "this", "packed", "goto",
            "inline", "noinline", "volatile", "public", "static", "extern", "external",
            "interface", "long", "short", "double", "half", "fixed", "unsigned", "input",
            "output", "hvec2", "fvec3", "sizeof", "cast", "namespace", "using"]


@pytest.mark.parametrize("name,stage,src,ok", CASES, ids=[c.values[0] if hasattr(c, "marks") else c[0] for c in CASES])
def test_compile_expectation(name, stage, src, ok):
    gl = context(version=1)
    kind = gl.VERTEX_SHADER if stage == V else gl.FRAGMENT_SHADER
    assert compiles(gl, kind, src) is ok


@pytest.mark.parametrize("word", RESERVED)
def test_reserved_words_are_not_identifiers(word):
    # shader-with-reserved-words (GLSL ES 1.00 §3.7 reserved keywords)
    gl = context(version=1)
    assert not compiles(gl, gl.FRAGMENT_SHADER, P + f"float {word}; void main() {{ gl_FragColor = vec4(1.0); }}")


@pytest.mark.parametrize("word", ["foo", "input1", "samplerfoo", "classic", "doubles", "ifx"])
def test_non_reserved_words_are_identifiers(word):
    # shader-with-non-reserved-words
    gl = context(version=1)
    assert compiles(gl, gl.FRAGMENT_SHADER, P + f"float {word} = 1.0; void main() {{ gl_FragColor = vec4({word}); }}")


def test_uniform_precision_mismatch_fails_link():
    # shader-with-global-variable-precision-mismatch: a uniform in both stages must have the same
    # precision (GLSL ES 1.00 §4.5.3).
    gl = context(version=1)
    vs = "uniform highp float u; void main() { gl_Position = vec4(u); }"
    fs = "precision mediump float; uniform mediump float u; void main() { gl_FragColor = vec4(u); }"
    assert try_link(gl, vs, fs)[2] is False


def test_too_many_uniforms_and_varyings_fail():
    # shader-with-too-many-uniforms, shader-uniform-packing-restrictions,
    # shader-varying-packing-restrictions (GLSL ES 1.00 Appendix A.7 packing limits)
    gl = context(version=1)
    n = gl.getParameter(gl.MAX_VERTEX_UNIFORM_VECTORS)
    vs = f"uniform vec4 u[{n + 1}]; void main() {{ vec4 s = vec4(0.0); for (int i = 0; i < {n + 1}; ++i) s += u[i]; gl_Position = s; }}"
    c = compiles(gl, gl.VERTEX_SHADER, vs)
    assert not c or try_link(gl, vs, "void main() { gl_FragColor = vec4(1.0); }")[2] is False
    m = gl.getParameter(gl.MAX_VARYING_VECTORS)
    decl = "".join(f"varying vec4 v{i};" for i in range(m + 1))
    vs = decl + "void main() { gl_Position = vec4(0.0); " + "".join(f"v{i} = vec4(1.0);" for i in range(m + 1)) + "}"
    fs = "precision mediump float;" + decl + "void main() { gl_FragColor = " + " + ".join(f"v{i}" for i in range(m + 1)) + "; }"
    s = try_link(gl, vs, fs)
    assert not (s[0] and s[1] and s[2])
