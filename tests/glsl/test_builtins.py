"""Every built-in function against NumPy float64. Tolerances (relative, with a small absolute
floor near zero) follow GLSL ES 3.00 §4.5.1 highp: basic arithmetic and exact functions are
compared exactly or to 1 ulp; transcendental functions to 4e-7..2e-6 relative (a few ulp)."""
import numpy as np
import pytest

from conftest import eval_expr, run, compile_ok

rng = np.random.default_rng(7)
N = 64


def f32(x):
    return np.asarray(x, np.float32).astype(np.float64)


def vals(lo=-4, hi=4):
    return rng.uniform(lo, hi, size=(N, 4)).astype(np.float32)


UNARY = [
    # name, glsl, numpy, domain, rtol, atol
    ("radians", "radians(a)", np.radians, (-360, 360), 2e-7, 0),
    ("degrees", "degrees(a)", np.degrees, (-7, 7), 2e-7, 0),
    ("sin", "sin(a)", np.sin, (-10, 10), 0, 2e-7),
    ("cos", "cos(a)", np.cos, (-10, 10), 0, 2e-7),
    ("tan", "tan(a)", np.tan, (-1.4, 1.4), 4e-7, 1e-7),
    ("asin", "asin(a)", np.arcsin, (-1, 1), 4e-7, 1e-7),
    ("acos", "acos(a)", np.arccos, (-1, 1), 4e-7, 1e-7),
    ("atan", "atan(a)", np.arctan, (-10, 10), 4e-7, 1e-7),
    ("sinh", "sinh(a)", np.sinh, (-5, 5), 4e-7, 1e-7),
    ("cosh", "cosh(a)", np.cosh, (-5, 5), 4e-7, 0),
    ("tanh", "tanh(a)", np.tanh, (-5, 5), 4e-7, 1e-7),
    ("asinh", "asinh(a)", np.arcsinh, (-10, 10), 4e-7, 1e-7),
    ("acosh", "acosh(a)", np.arccosh, (1, 10), 4e-7, 1e-7),
    ("atanh", "atanh(a)", np.arctanh, (-0.99, 0.99), 4e-7, 1e-7),
    ("exp", "exp(a)", np.exp, (-10, 10), 4e-7, 0),
    ("log", "log(a)", np.log, (0.01, 100), 4e-7, 1e-7),
    ("exp2", "exp2(a)", np.exp2, (-10, 10), 4e-7, 0),
    ("log2", "log2(a)", np.log2, (0.01, 100), 4e-7, 1e-7),
    ("sqrt", "sqrt(a)", np.sqrt, (0, 100), 1.2e-7, 0),
    ("inversesqrt", "inversesqrt(a)", lambda x: 1 / np.sqrt(x), (0.01, 100), 2.4e-7, 0),
    ("abs", "abs(a)", np.abs, (-4, 4), 0, 0),
    ("sign", "sign(a)", np.sign, (-4, 4), 0, 0),
    ("floor", "floor(a)", np.floor, (-4, 4), 0, 0),
    ("ceil", "ceil(a)", np.ceil, (-4, 4), 0, 0),
    ("trunc", "trunc(a)", np.trunc, (-4, 4), 0, 0),
    ("fract", "fract(a)", lambda x: x - np.floor(x), (-4, 4), 0, 1.2e-7),
    ("roundEven", "roundEven(a)", np.round, (-4, 4), 0, 0),
    ("normalize", "normalize(a)", lambda x: x / np.linalg.norm(x, axis=1, keepdims=True), (-4, 4), 3e-7, 1e-7),
]


@pytest.mark.parametrize("name,glsl,ref,domain,rtol,atol", UNARY, ids=[u[0] for u in UNARY])
def test_unary(name, glsl, ref, domain, rtol, atol):
    a = vals(*domain)
    out = eval_expr(glsl, a)
    np.testing.assert_allclose(out, ref(f32(a)), rtol=rtol, atol=atol)


def test_round_halves():
    a = np.tile(np.float32([0.5, 1.5, 2.5, -0.5]), (4, 1))
    np.testing.assert_array_equal(eval_expr("roundEven(a)", a)[0], [0, 2, 2, -0.0])
    r = eval_expr("round(a)", a)[0]  # ES 3.00: .5 rounds in an implementation-chosen direction
    assert np.all(np.abs(r - a[0]) == 0.5)


BINARY = [
    ("pow", "pow(a, b)", np.power, (0.1, 4), (-3, 3), 1e-6, 0),
    ("atan2", "atan(a, b)", np.arctan2, (-4, 4), (-4, 4), 4e-7, 1e-7),
    ("mod", "mod(a, b)", lambda x, y: x - y * np.floor(x / y), (-10, 10), (0.5, 3), 0, 4e-6),
    ("min", "min(a, b)", np.minimum, (-4, 4), (-4, 4), 0, 0),
    ("max", "max(a, b)", np.maximum, (-4, 4), (-4, 4), 0, 0),
    ("step", "step(a, b)", lambda e, x: np.where(x < e, 0.0, 1.0), (-4, 4), (-4, 4), 0, 0),
    ("add", "a + b", np.add, (-4, 4), (-4, 4), 1.2e-7, 0),
    ("div", "a / b", np.divide, (-4, 4), (0.5, 4), 1.2e-7, 0),
    ("reflect", "reflect(a, normalize(b))",
     lambda i, n: i - 2 * np.sum(n / np.linalg.norm(n, axis=1, keepdims=True) * i, axis=1, keepdims=True) * (n / np.linalg.norm(n, axis=1, keepdims=True)),
     (-4, 4), (-4, 4), 1e-5, 1e-5),
    ("matrixCompMult", "matrixCompMult(mat2(a), mat2(b))[0].xyxy", lambda x, y: (x * y)[:, [0, 1, 0, 1]], (-4, 4), (-4, 4), 1.2e-7, 0),
    ("lessThan", "vec4(lessThan(a, b))", lambda x, y: (x < y).astype(float), (-1, 1), (-1, 1), 0, 0),
    ("greaterThanEqual", "vec4(greaterThanEqual(a, b))", lambda x, y: (x >= y).astype(float), (-1, 1), (-1, 1), 0, 0),
    ("equal", "vec4(equal(floor(a), floor(b)))", lambda x, y: (np.floor(x) == np.floor(y)).astype(float), (-2, 2), (-2, 2), 0, 0),
]


@pytest.mark.parametrize("name,glsl,ref,da,db,rtol,atol", BINARY, ids=[b[0] for b in BINARY])
def test_binary(name, glsl, ref, da, db, rtol, atol):
    a = vals(*da)
    b = vals(*db)
    out = eval_expr(glsl, a, b)
    np.testing.assert_allclose(out, ref(f32(a), f32(b)), rtol=rtol, atol=atol)


def test_ternary_functions():
    a, b, c = vals(-2, 2), vals(-2, 2), vals(0, 1)
    A, B, C = f32(a), f32(b), f32(c)
    np.testing.assert_allclose(eval_expr("mix(a, b, c)", a, b, c), A * (1 - C) + B * C, rtol=1e-6, atol=1e-6)
    lo, hi = np.minimum(B, C), np.maximum(B, C)
    np.testing.assert_array_equal(eval_expr("clamp(a, min(b, c), max(b, c))", a, b, c), np.minimum(np.maximum(A, lo), hi))
    t = np.clip((A - (-1.0)) / 2.0, 0, 1)
    np.testing.assert_allclose(eval_expr("smoothstep(-1.0, 1.0, a)", a), t * t * (3 - 2 * t), rtol=1e-6, atol=1e-7)
    np.testing.assert_array_equal(eval_expr("mix(a, b, greaterThan(c, vec4(0.5)))", a, b, c), np.where(C > 0.5, B, A))


def test_geometric():
    a, b = vals(), vals()
    A, B = f32(a), f32(b)
    np.testing.assert_allclose(eval_expr("vec4(dot(a, b))", a, b)[:, 0], np.sum(A * B, axis=1), rtol=1e-6, atol=1e-5)
    np.testing.assert_allclose(eval_expr("vec4(length(a))", a)[:, 0], np.linalg.norm(A, axis=1), rtol=3e-7)
    np.testing.assert_allclose(eval_expr("vec4(distance(a, b))", a, b)[:, 0], np.linalg.norm(A - B, axis=1), rtol=3e-7)
    np.testing.assert_allclose(eval_expr("vec4(cross(a.xyz, b.xyz), 0.0)", a, b)[:, :3], np.cross(A[:, :3], B[:, :3]), rtol=1e-5, atol=1e-5)
    ff = eval_expr("faceforward(a, b, a.wzyx)", a, b)
    np.testing.assert_array_equal(ff, np.where((np.sum(A[:, ::-1] * B, axis=1) < 0)[:, None], A, -A))
    # refract with eta = 0.66 and normalized vectors
    i = A / np.linalg.norm(A, axis=1, keepdims=True)
    n = B / np.linalg.norm(B, axis=1, keepdims=True)
    eta = np.float32(0.66)
    d = np.sum(n * i, axis=1, keepdims=True)
    k = 1 - eta * eta * (1 - d * d)
    expected = np.where(k < 0, 0.0, eta * i - (eta * d + np.sqrt(np.maximum(k, 0))) * n)
    np.testing.assert_allclose(eval_expr("refract(normalize(a), normalize(b), 0.66)", a, b), expected, rtol=1e-5, atol=1e-5)


def test_matrix_functions():
    a, b, c = vals(), vals(), vals()
    for lane in range(0, N, 7):
        pass
    m = np.stack([f32(a), f32(b), f32(c), f32(a[:, ::-1])], axis=2)  # (N, 4 rows, 4 cols) columns a, b, c, a.wzyx
    cols = "mat4(a, b, c, a.wzyx)"
    det = eval_expr(f"vec4(determinant({cols}))", a, b, c)[:, 0]
    np.testing.assert_allclose(det, np.linalg.det(m), rtol=1e-4, atol=1e-3)
    inv = np.linalg.inv(m)
    for col in range(4):
        out = eval_expr(f"inverse({cols})[{col}]", a, b, c)
        good = np.abs(np.linalg.det(m)) > 0.5
        np.testing.assert_allclose(out[good], inv[good][:, :, col], rtol=1e-3, atol=1e-3)
        out = eval_expr(f"transpose({cols})[{col}]", a, b, c)
        np.testing.assert_array_equal(out, m[:, col, :])
        out = eval_expr(f"outerProduct(a, b)[{col}]", a, b)
        np.testing.assert_allclose(out, f32(a) * f32(b)[:, col:col + 1], rtol=1.2e-7)
    m2 = eval_expr("vec4(determinant(mat2(a)), determinant(mat3(a.xyz, b.xyz, c.xyz)), 0.0, 0.0)", a, b, c)
    np.testing.assert_allclose(m2[:, 0], f32(a[:, 0]) * f32(a[:, 3]) - f32(a[:, 2]) * f32(a[:, 1]), rtol=1e-5, atol=1e-5)
    np.testing.assert_allclose(m2[:, 1], np.linalg.det(np.stack([f32(a[:, :3]), f32(b[:, :3]), f32(c[:, :3])], axis=2)), rtol=1e-4, atol=1e-4)
    # matrix * vector, vector * matrix, matrix * matrix
    mv = eval_expr(f"{cols} * c", a, b, c)
    np.testing.assert_allclose(mv, np.einsum("nij,nj->ni", m, f32(c)), rtol=1e-5, atol=1e-5)
    vm = eval_expr(f"c * {cols}", a, b, c)
    np.testing.assert_allclose(vm, np.einsum("nj,nji->ni", f32(c), m), rtol=1e-5, atol=1e-5)


def test_isnan_isinf_bits():
    a = np.tile(np.float32([np.nan, np.inf, -1.5, 0.0]), (4, 1))
    np.testing.assert_array_equal(eval_expr("vec4(isnan(a))", a)[0], [1, 0, 0, 0])
    np.testing.assert_array_equal(eval_expr("vec4(isinf(a))", a)[0], [0, 1, 0, 0])
    b = vals()
    np.testing.assert_array_equal(eval_expr("intBitsToFloat(floatBitsToInt(a))", b), b)
    np.testing.assert_array_equal(eval_expr("uintBitsToFloat(floatBitsToUint(a) ^ 0x80000000u)", b), -b)


def test_modf():
    fs = """#version 300 es
    precision highp float;
    in vec4 a;
    layout(location = 0) out vec4 f;
    layout(location = 1) out vec4 w;
    void main() { vec4 whole; f = modf(a, whole); w = whole; }"""
    a = vals()
    out = run(fs, "fragment", {"a": a}, lanes=N)
    np.testing.assert_array_equal(out["w"], np.trunc(a))
    np.testing.assert_array_equal(out["f"], a - np.trunc(a))


def test_pack_unpack():
    a = np.float32([[0.25, -0.5, 1.0, -1.0]] * 4)
    out = eval_expr("vec4(unpackSnorm2x16(packSnorm2x16(a.xy)), unpackUnorm2x16(packUnorm2x16(abs(a.zw))))", a)
    np.testing.assert_allclose(out[0], [round(0.25 * 32767) / 32767, round(-0.5 * 32767) / 32767, 1, 1], rtol=1e-7)
    out = eval_expr("vec4(unpackHalf2x16(packHalf2x16(a.xy)), unpackHalf2x16(packHalf2x16(vec2(1.0/3.0, 65504.0))))", a)
    np.testing.assert_allclose(out[0], [0.25, -0.5, float(np.float16(1 / 3)), 65504.0])
    out = eval_expr("vec4(float(packSnorm2x16(vec2(1.0, -1.0))), float(packUnorm2x16(vec2(0.0, 1.0))), 0.0, 0.0)", a)
    assert out[0, 0] == float(0x8001 << 16 | 0x7fff) and out[0, 1] == float(0xffff << 16)


def test_integer_and_bit_operations():
    fs = """#version 300 es
    precision highp float; precision highp int;
    flat in ivec4 i;
    flat in uvec4 u;
    layout(location = 0) out ivec4 r1;
    layout(location = 1) out uvec4 r2;
    layout(location = 2) out ivec4 r3;
    void main() {
        r1 = ivec4(i.x / 3, i.y % 5, abs(i.z), sign(i.w));
        r2 = uvec4(u.x >> 3, u.y << 2, u.z & 0xF0u, ~u.w);
        r3 = ivec4(min(i.x, i.y), max(i.z, i.w), clamp(i.x, -5, 5), (i.y ^ i.z) | 1);
    }"""
    I = rng.integers(-1000, 1000, size=(8, 4)).astype(np.int32)
    U = rng.integers(0, 2**32, size=(8, 4), dtype=np.uint64).astype(np.uint32)
    out = run(fs, "fragment", {"i": I, "u": U.view(np.int32)}, lanes=8)
    np.testing.assert_array_equal(out["r1"][:, 0], np.trunc(I[:, 0] / 3).astype(np.int32))
    np.testing.assert_array_equal(out["r1"][:, 1], np.fmod(I[:, 1], 5))
    np.testing.assert_array_equal(out["r1"][:, 2:], np.stack([np.abs(I[:, 2]), np.sign(I[:, 3])], 1))
    r2 = out["r2"].view(np.uint32)
    np.testing.assert_array_equal(r2, np.stack([U[:, 0] >> 3, U[:, 1] << 2, U[:, 2] & 0xF0, ~U[:, 3]], 1))
    np.testing.assert_array_equal(out["r3"], np.stack([np.minimum(I[:, 0], I[:, 1]), np.maximum(I[:, 2], I[:, 3]),
                                                       np.clip(I[:, 0], -5, 5), (I[:, 1] ^ I[:, 2]) | 1], 1))


def test_derivatives_in_quads():
    fs = """#version 300 es
    precision highp float;
    in vec4 a;
    out vec4 o;
    void main() { o = vec4(dFdx(a.x), dFdy(a.x), fwidth(a.x), 0.0); }"""
    # one quad: (x, y) = (0,0), (1,0), (0,1), (1,1); a.x = 3x + 5y
    x = np.array([0, 1, 0, 1]); y = np.array([0, 0, 1, 1])
    a = np.zeros((4, 4), np.float32); a[:, 0] = 3 * x + 5 * y
    out = run(fs, "fragment", {"a": a}, lanes=4)
    np.testing.assert_array_equal(out["o"][:, 0], [3, 3, 3, 3])
    np.testing.assert_array_equal(out["o"][:, 1], [5, 5, 5, 5])
    np.testing.assert_array_equal(out["o"][:, 2], [8, 8, 8, 8])
    ok = compile_ok("""#extension GL_OES_standard_derivatives : enable
    precision mediump float; varying float v; void main() { gl_FragColor = vec4(dFdx(v)); }""", "fragment", 1)
    assert ok["uses_derivatives"]


def test_texture_functions_compile():
    fs = """#version 300 es
    precision highp float;
    uniform sampler2D s; uniform highp sampler3D s3; uniform samplerCube c; uniform highp sampler2DShadow sh;
    uniform highp sampler2DArray arr; uniform highp isampler2D si; uniform highp usampler2D su;
    in vec4 v;
    out vec4 o;
    void main() {
        o = texture(s, v.xy) + texture(s, v.xy, 1.0) + textureProj(s, v.xyz) + textureLod(s, v.xy, 2.0)
          + textureOffset(s, v.xy, ivec2(1, -1)) + texelFetch(s, ivec2(v.xy), 0) + textureGrad(s, v.xy, v.zw, v.wz)
          + texture(s3, v.xyz) + texture(c, v.xyz) + vec4(texture(sh, v.xyz)) + texture(arr, v.xyz)
          + vec4(texture(si, v.xy)) + vec4(texture(su, v.xy)) + vec4(vec2(textureSize(s, 0)), 0.0, 0.0)
          + textureProjLodOffset(s, v, 0.0, ivec2(2)) + textureLodOffset(s, v.xy, 1.0, ivec2(0));
    }"""
    r = compile_ok(fs, "fragment")
    assert sum(u["is_sampler"] for u in r["uniforms"]) == 7
    compile_ok("""uniform sampler2D s; attribute vec2 uv; varying vec4 c;
    void main() { c = texture2DLod(s, uv, 0.0) + texture2DProj(s, vec3(uv, 1.0)); gl_Position = vec4(0.0); }""", "vertex", 1)


def test_texel_fetch_and_size():
    fs = """#version 300 es
    precision highp float;
    uniform sampler2D s;
    flat in ivec2 p;
    out vec4 o;
    void main() { o = texelFetch(s, p, 0) + vec4(vec2(textureSize(s, 0)), 0.0, 0.0) * 100.0; }"""
    img = rng.random((3, 5, 4)).astype(np.float32)
    p = np.array([[0, 0], [4, 2], [1, 1], [3, 0]], np.int32)
    out = run(fs, "fragment", {"p": p}, {"s": 0}, lanes=4, textures={0: img})
    expected = img[p[:, 1], p[:, 0]].astype(np.float64) + np.array([500, 300, 0, 0])
    np.testing.assert_allclose(out["o"], expected, rtol=1e-6)
