import numpy as np
import pytest

from softgl import _core


def compile_ok(source, stage, version=2):
    ok, log, reflection = _core.glsl_compile(source, stage, version)
    assert ok, log
    return reflection


def compile_errors(source, stage, version=2):
    ok, log, _ = _core.glsl_compile(source, stage, version)
    assert not ok, "expected a compile error"
    return log


def run(source, stage, inputs=None, uniforms=None, lanes=4, version=2, textures=None, batch=128):
    return _core.glsl_run(source, stage, version, inputs or {}, uniforms or {}, lanes, textures or {}, batch)


FRAG_EXPR = """#version 300 es
precision highp float;
precision highp int;
in vec4 a;
in vec4 b;
in vec4 c;
out vec4 o;
void main() {{ o = {expr}; }}
"""


def eval_expr(expr, a, b=None, c=None):
    """Evaluates a vec4 GLSL expression of a, b, c (each (lanes, 4)) in a fragment shader."""
    lanes = a.shape[0]
    b = a if b is None else b
    c = a if c is None else c
    out = run(FRAG_EXPR.format(expr=expr), "fragment",
              {"a": a.astype(np.float32), "b": b.astype(np.float32), "c": c.astype(np.float32)}, lanes=lanes)
    return out["o"]
