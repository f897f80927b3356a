"""The executor's lane loops are compiled once per SIMD level (portable SSE2, AVX2, AVX-512) and
the CPU's best is chosen at run time: every level must give the same bits. Runs the built-in
function tests' expressions, a set of integer/conversion/control-flow programs and the seed
corpus at each available level over lanes with ordinary and special values (inf, denormals,
signed zeros, NaN), with lane counts that leave partial vectors at every width, and compares the
outputs bit for bit (NaN payloads aside, see assert_same_bits); and draws benchmark scenes
through the whole pipeline at each level."""
import hashlib
import pathlib
import sys
import zlib

import numpy as np
import pytest

from conftest import FRAG_EXPR
from softgl import _core
from test_builtins import BINARY, UNARY

LEVELS = _core.glsl_simd_levels()
LANES = 4 * 53   # two batches of 128 and 84 lanes: full vectors and a tail at every width
CORPUS = sorted((pathlib.Path(__file__).parent / "corpus").iterdir())

pytestmark = pytest.mark.skipif(len(LEVELS) < 2, reason="this CPU runs only the portable level")

SPECIAL = np.float32([0.0, -0.0, 1.0, -1.0, 0.5, -2.5, 1e-40, -1e-40, 3.4e38, -3.4e38, np.inf, -np.inf, np.nan,
                      1e-7, 65504.0, 2.0 ** 31, -(2.0 ** 31), 4.3e9, 0.25, 100.0])

EXPRESSIONS = [u[1] for u in UNARY] + [b[1] for b in BINARY] + [
    "mix(a, b, c)", "clamp(a, b, c)", "smoothstep(a, b, c)", "fract(a)", "round(a)", "mod(a, b)", "sign(a)",
    "step(a, b)", "vec4(dot(a, b), length(a), distance(a, b), 0.0)", "reflect(a, b)", "refract(a, b, c.x)",
    "vec4(isnan(a)) + vec4(isinf(b))", "vec4(ivec4(a))", "vec4(uvec4(a))", "vec4(uvec4(ivec4(a)) / uvec4(ivec4(b)))",
    "vec4(ivec4(a) / ivec4(b)) + vec4(ivec4(a) % ivec4(b))", "vec4((ivec4(a) << 3) >> ivec4(b) ^ ~ivec4(c))",
    "vec4(min(ivec4(a), ivec4(b))) + vec4(clamp(uvec4(a), uvec4(b), uvec4(c)))",
    "intBitsToFloat(floatBitsToInt(a) + 1)", "vec4(lessThanEqual(a, b)) + vec4(notEqual(a, c))",
    "vec4(unpackHalf2x16(packHalf2x16(a.xy)), unpackSnorm2x16(packSnorm2x16(b.zw)))",
    "vec4(unpackUnorm2x16(packUnorm2x16(a.xy)), dFdx(b.x), dFdy(c.y))", "a.x > 0.0 ? b : c",
    "vec4(bvec4(a)) + vec4(not(bvec4(b)))", "vec4(abs(ivec4(a))) + vec4(sign(ivec4(b)))",
    "vec4(float(uint(a.x)), float(int(b.y)), float(uint(4.3e9)), exp2(c.z))",
]

CONTROL_FLOW = """#version 300 es
precision highp float;
precision highp int;
in vec4 a;
in vec4 b;
in vec4 c;
uniform vec4 uArray[4];
out vec4 o;
float f(float x) { if (x < 0.0) return -x; return sqrt(x); }
void main() {
  vec4 acc = vec4(0.0);
  float arr[5];
  for (int i = 0; i < 5; i++) arr[i] = a[i % 4] * float(i);
  int k = int(abs(b.x)) % 7;
  for (int i = 0; i < 9; i++) {
    if (i > k) break;
    if (c[i % 4] > 0.5) continue;
    acc += uArray[(k + i) % 4] * arr[(i + k) % 5];
    arr[k % 5] += f(acc.x);
  }
  switch (k) { case 0: acc.y += 1.0; case 1: acc.z -= 2.0; break; default: acc.w = pow(abs(a.w), b.w); }
  if (acc.x > 1e30) discard;
  o = acc + vec4(arr[k % 5]);
}"""


def lane_values(rng, columns, integer=False, lanes=LANES):
    if integer:
        return rng.integers(-50, 50, size=(lanes, columns)).astype(np.int32)
    v = (rng.normal(size=(lanes, columns)) * rng.choice([0.01, 1.0, 1e4], size=(lanes, columns))).astype(np.float32)
    special = rng.random((lanes, columns)) < 0.2
    v[special] = rng.choice(SPECIAL, size=int(special.sum()))
    return v


def run_all_levels(source, stage, version, inputs, uniforms, textures, lanes=LANES):
    results = {}
    for level in LEVELS:
        out = _core.glsl_run(source, stage, version, inputs, uniforms, lanes, textures, 128, 1, level)
        out.pop("seconds")
        results[level] = out
    return results


def assert_same_bits(results):
    # Every bit except NaN payloads: when both operands of an IEEE operation are NaN, x86 returns
    # the first one, and the compiler may commute a + b or a * b differently in each build
    # (C++ does not specify NaN payloads). Which lanes are NaN must agree.
    first, *others = results.values()
    for other in others:
        assert first.keys() == other.keys()
        for name in first:
            x, y = np.asarray(first[name]), np.asarray(other[name])
            if x.dtype == np.float32:
                np.testing.assert_array_equal(np.isnan(x), np.isnan(y), err_msg=name)
                x, y = (np.where(np.isnan(v), np.float32(np.nan), v).view(np.uint32) for v in (x, y))
            np.testing.assert_array_equal(x, y, err_msg=name)


@pytest.mark.parametrize("expr", EXPRESSIONS)
def test_expression_bits_equal_at_every_level(expr):
    rng = np.random.default_rng(zlib.crc32(expr.encode()))
    inputs = {k: lane_values(rng, 4) for k in "abc"}
    assert_same_bits(run_all_levels(FRAG_EXPR.format(expr=expr), "fragment", 2, inputs, {}, {}))


def test_control_flow_bits_equal_at_every_level():
    rng = np.random.default_rng(3)
    inputs = {k: lane_values(rng, 4) for k in "abc"}
    uniforms = {"uArray": rng.normal(size=16).astype(np.float32)}
    assert_same_bits(run_all_levels(CONTROL_FLOW, "fragment", 2, inputs, uniforms, {}))


@pytest.mark.parametrize("path", CORPUS, ids=[p.name for p in CORPUS])
def test_corpus_bits_equal_at_every_level(path):
    source = path.read_text()
    stage = "vertex" if path.suffix == ".vert" else "fragment"
    version = 2 if "#version 300 es" in source else 1
    ok, log, reflection = _core.glsl_compile(source, stage, version)
    assert ok, log
    rng = np.random.default_rng(11)
    names = [v["name"] for v in reflection["attributes"] + reflection["varyings"]]
    ints = {v["name"] for v in reflection["attributes"] + reflection["varyings"] if "int" in v["type_name"]}
    inputs = {n: lane_values(rng, 64, n in ints) for n in names}
    uniforms, textures = {}, {}
    for u in reflection["uniforms"]:
        if u["is_sampler"]:
            uniforms[u["base_name"]] = 0
            textures[0] = rng.random((8, 8, 4)).astype(np.float32)
        else:
            uniforms[u["base_name"]] = rng.normal(size=u["size"] * u["stride"]).astype(np.float32)
    assert_same_bits(run_all_levels(source, stage, version, inputs, uniforms, textures))


# Lane counts around the vector widths (4, 8, 16 floats) and the batch (128): loops end in
# partial vectors and masked or scalar tails.
TAIL_LANES = list(range(1, 34)) + [127, 128, 129]
TAIL_EXPR = ("mix(a, b, c) * sqrt(abs(a)) / b + floor(c) - vec4(ivec4(a) / ivec4(b)) + vec4(uvec4(c) >> 3u)"
             " + vec4(dFdx(a.x), dFdy(b.y), float(uint(c.z)), max(c.w, a.w))")


@pytest.mark.parametrize("lanes", TAIL_LANES)
def test_partial_vectors_bits_equal_at_every_level(lanes):
    rng = np.random.default_rng(lanes)
    inputs = {k: lane_values(rng, 4, lanes=lanes) for k in "abc"}
    assert_same_bits(run_all_levels(FRAG_EXPR.format(expr=TAIL_EXPR), "fragment", 2, inputs, {}, {}, lanes))
    uniforms = {"uArray": rng.normal(size=16).astype(np.float32)}
    assert_same_bits(run_all_levels(CONTROL_FLOW, "fragment", 2, inputs, uniforms, {}, lanes))


def test_pack_nan_is_zero_at_every_level():
    # NaN is undefined for packUnorm/packSnorm (ES 3.00 §8.4); softgl packs it as 0 at every level
    # (the vector float->int conversions of each instruction set disagree on NaN).
    a = np.tile(np.float32([np.nan, 0.5, -np.nan, 1.0]), (37, 1))
    source = FRAG_EXPR.format(expr="vec4(uintBitsToFloat(packUnorm2x16(a.xy)), uintBitsToFloat(packSnorm2x16(a.zw)),"
                                   " uintBitsToFloat(packUnorm2x16(a.zx)), 0.0)")
    for level in LEVELS:
        o = _core.glsl_run(source, "fragment", 2, {"a": a}, {}, len(a), {}, 128, 1, level)["o"].view(np.uint32)
        np.testing.assert_array_equal(o[:, 0], 32768 << 16, err_msg=level)   # x NaN -> 0, y round(0.5 * 65535) = 32768
        np.testing.assert_array_equal(o[:, 1], 32767 << 16, err_msg=level)   # z NaN -> 0, w 1.0 -> 32767
        np.testing.assert_array_equal(o[:, 2], 0, err_msg=level)


BENCHMARKS = pathlib.Path(__file__).resolve().parents[2] / "benchmarks"
# The Tuning::simd levels this CPU runs (core/tuning.h; the executor's portable build serves the first two).
SIMD = ["scalar", "sse2", "avx2", "avx512"][:_core.testing.simd_level() + 1]


@pytest.mark.parametrize("scene", ["exec_color", "exec_spot", "exec_tex2", "spot_mesh", "small_blend"])
def test_pipeline_bytes_equal_at_every_level(scene):
    # A context's draws run at its tuning's level: a new context's (from the process default, its
    # programs' executors new), and one context's changed between draws (its executors reused).
    sys.path.insert(0, str(BENCHMARKS))
    import scenes
    spec = {s.key: s for s in scenes.SUITE + scenes.EXECUTOR}[scene]
    digests = {}
    reused = scenes.SoftglRenderer(64, 64, threads=2)
    for level in SIMD:
        before = _core.testing.set_default_tuning(simd=level)
        try:
            r = scenes.SoftglRenderer(64, 64, threads=2)
        finally:
            _core.testing.set_default_tuning(**before)
        assert _core.testing.tuning(r.gl)["simd"] == level
        digests["new", level] = hashlib.sha256(r.render(spec.build(64)).tobytes()).hexdigest()
        _core.testing.set_tuning(reused.gl, simd=level)
        digests["reused", level] = hashlib.sha256(reused.render(spec.build(64)).tobytes()).hexdigest()
    assert len(set(digests.values())) == 1, digests
