"""Fuzz target: random, mutated and truncated sources must never crash or hang compile/link.
Bounded (a few seconds); the seed corpus is tests/glsl/corpus/."""
import pathlib

from hypothesis import HealthCheck, given, settings, strategies as st

from softgl import _core

CORPUS = sorted((pathlib.Path(__file__).parent / "corpus").iterdir())
SEEDS = [p.read_text() for p in CORPUS]
TOKENS = ["#define", "#if", "#ifdef", "#endif", "#else", "#elif", "#undef", "#line", "#version 300 es", "#version 100",
          "#extension", "defined", "(", ")", "{", "}", "[", "]", ";", ",", ".", "=", "+", "-", "*", "/", "%", "<<", ">>",
          "<", ">", "?", ":", "&&", "||", "^^", "!", "~", "++", "--", "void", "main", "float", "int", "uint", "vec4",
          "mat4", "struct", "uniform", "attribute", "varying", "in", "out", "inout", "const", "precision", "highp",
          "for", "while", "do", "if", "else", "switch", "case", "default", "break", "continue", "return", "discard",
          "x", "y", "1", "1.0", "0x7fffffff", "1e38", "gl_FragColor", "gl_Position", "texture2D", "sampler2D",
          "__LINE__", "X(", "\n", " ", "\\\n", "/*", "*/", "//"]


def check(source):
    for stage in ("vertex", "fragment"):
        for version in (1, 2):
            ok, log, reflection = _core.glsl_compile(source, stage, version)
            assert isinstance(log, str)
            assert ok or log.startswith("ERROR: ") or "\nERROR: " in log, log
            assert ok == (reflection is not None)


fuzz_settings = settings(max_examples=150, deadline=None, suppress_health_check=list(HealthCheck))


def test_corpus_compiles_and_links():
    by_name = {p.name: p.read_text() for p in CORPUS}
    for name, src in by_name.items():
        stage = "vertex" if name.endswith(".vert") else "fragment"
        ok, log, _ = _core.glsl_compile(src, stage, 2)
        assert ok, (name, log)
    ok, log, _ = _core.glsl_link(by_name["color.vert"], by_name["color.frag"], 1)
    assert ok, log


@fuzz_settings
@given(st.sampled_from(SEEDS), st.data())
def test_truncated(seed, data):
    cut = data.draw(st.integers(0, len(seed)))
    check(seed[:cut])


@fuzz_settings
@given(st.sampled_from(SEEDS), st.lists(st.tuples(st.integers(0, 10_000), st.sampled_from(TOKENS + ["", "\x00", "\xff"])), max_size=8))
def test_mutated(seed, edits):
    s = seed
    for pos, token in edits:
        pos %= len(s) + 1
        s = s[:pos] + token + s[pos + (len(token) % 3):]
    check(s)


@fuzz_settings
@given(st.lists(st.sampled_from(TOKENS), max_size=60))
def test_token_soup(tokens):
    check(" ".join(tokens))


@fuzz_settings
@given(st.text(max_size=300))
def test_random_text(text):
    check(text)


def test_pathological_inputs():
    check("#define A A A\n#define B(x) B(x) A\nvoid main() { B(B(A)) }")
    check("#define A B B B B B B B B\n#define B C C C C C C C C\n#define C D D D D D D D D\n#define D E E E E E E E E\n"
          "#define E F F F F F F F F\n#define F G G G G G G G G\n#define G 1 1 1 1 1 1 1 1\nint x = A;")
    check("void main() { float x = " + "(" * 5000 + "1.0" + ")" * 5000 + "; }")
    check("#if " + "(" * 3000 + "1" + ")" * 3000 + "\n#endif\n")
    check("void main() { " + "{" * 3000 + "}" * 3000 + " }")
    check("\n".join("#if 1" for _ in range(200)))
    nested = "float f0(float x) { return x; }\n" + "\n".join(
        f"float f{i}(float x) {{ return f{i - 1}(x) + f{i - 1}(x) + f{i - 1}(x); }}" for i in range(1, 30))
    check(nested + "\nvoid main() { gl_Position = vec4(f29(1.0)); }")
    check("float f(); void main() { f(); }")


@fuzz_settings
@given(st.sampled_from(SEEDS), st.sampled_from(SEEDS), st.integers(0, 400), st.integers(0, 400))
def test_link_mutations(vs, fs, cut_v, cut_f):
    ok, log, _ = _core.glsl_link(vs[: len(vs) - cut_v], fs[: len(fs) - cut_f], 2)
    assert isinstance(log, str)
