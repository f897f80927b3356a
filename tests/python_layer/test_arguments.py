"""Argument conversion (cpp/bindings/arguments.h, docs/reliability.md "Argument conversion"): a
wrong non-array argument to any Context method is a TypeError that names the method, the
parameter and what it accepts, before anything is done. Checked over every public method and
every parameter, from the signatures help() shows, so a method added later is covered too."""
import re
import sys
from pathlib import Path

import numpy as np
import pytest

import softgl

sys.path.insert(0, str(Path(__file__).parent))
from test_signatures import public_methods, signature_lines  # noqa: E402

CONTEXT = softgl.WebGL2RenderingContext

# The parameter types help() shows for non-array parameters, a value each accepts, and values of a
# wrong type (with the words their refusal must use).
INT = ("int", "typing.SupportsInt | typing.SupportsIndex")
OPTIONAL_INT = "typing.SupportsInt | typing.SupportsIndex | None"
FLOAT = "typing.SupportsFloat | typing.SupportsIndex"
WRONG = {
    "int": {"float": 1.5, "whole float": 2.0, "str": "1", "list": [1]},
    "float": {"str": "0.5", "list": [0.5]},
    "bool": {"str": "no", "list": [True]},
    "str": {"float": 1.5, "None": None},
    "object": {"str": "x", "int": 1},
}
ACCEPTS = {"int": "an int", "float": "a number", "bool": "a bool", "str": "a str", "object": " or None"}


def kind_of(type_text):
    if type_text in INT or type_text == OPTIONAL_INT:
        return "int"
    if type_text == FLOAT:
        return "float"
    if type_text in ("bool", "str"):
        return type_text
    if re.fullmatch(r"softgl\._core\.WebGL\w+", type_text):
        return "object"
    return None   # arrays and sequences: the array intake's (test_array_intake.py)


def valid(kind):
    return {"int": 0, "float": 0.0, "bool": False, "str": "", "object": None}.get(kind)


def overloads(method):
    """Each overload's parameters after self: [(name, kind), ...]."""
    out = []
    for line in signature_lines(method):
        params = line[line.index("(") + 1:line.rindex(") ->")]
        parts = [p for p in re.split(r",\s*(?![^\[]*\])", params) if p.strip()][1:]
        out.append([(p.split(":")[0].strip(), kind_of(p.split(":", 1)[1].split("=")[0].strip()))
                    for p in parts])
    return out


def cases():
    out = []
    for name in public_methods():
        for params in overloads(getattr(CONTEXT, name)):
            for i, (param, kind) in enumerate(params):
                if kind is None:
                    continue
                for what, value in WRONG[kind].items():
                    args = [valid(k) for _, k in params]
                    args[i] = value
                    out.append((name, param, kind, what, args))
    return out


CASES = cases()


def test_every_method_is_covered():
    # Every public method with a non-array parameter appears; the count guards the parser.
    methods = {c[0] for c in CASES}
    with_scalars = {n for n in public_methods()
                    if any(k for params in overloads(getattr(CONTEXT, n)) for _, k in params)}
    assert methods == with_scalars
    assert len(methods) > 150
    assert len(CASES) > 1000


@pytest.mark.parametrize("method, param, kind, what, args", CASES,
                         ids=[f"{m}-{p}-{w}-{len(a)}" for m, p, _, w, a in CASES])
def test_a_wrong_argument_names_method_and_parameter(method, param, kind, what, args):
    gl = softgl.Context(4, 4)
    with pytest.raises(TypeError) as info:
        getattr(gl, method)(*args)
    message = str(info.value)
    assert message.startswith(f"{method}: {param} must be "), message
    assert ACCEPTS[kind] in message.split("; got ")[0], message
    wrong = WRONG[kind][what]
    assert f"; got {'None' if wrong is None else type(wrong).__name__}" in message, message
    assert gl.getError() == gl.NO_ERROR   # a JS TypeError: no GL error, nothing done


def test_the_messages_of_the_unclear_cases():
    gl = softgl.Context(8, 8)
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    prog = gl.createProgram()
    loc = None   # a null location: the call would be a no-op, but its arguments are converted first
    expected = {
        lambda: gl.drawArrays(gl.TRIANGLES, 1.5, 3):
            "drawArrays: first must be an int (GLint, 32 bits); got float 1.5 - use int(...) (or //): "
            "softgl refuses a float where WebGL takes an integer",
        lambda: gl.uniform1i(loc, "a"): "uniform1i: x must be an int (GLint, 32 bits); got str 'a'",
        lambda: gl.enable("BLEND"): "enable: cap must be an int (GLenum/GLuint, 32 bits); got str 'BLEND'",
        lambda: gl.texSubImage2D(gl.TEXTURE_2D, 0, 0.5, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, np.zeros(4, np.uint8)):
            "texSubImage2D: xoffset must be an int (GLint, 32 bits); got float 0.5 - use int(...) (or //): "
            "softgl refuses a float where WebGL takes an integer",
        lambda: gl.readPixels(0, 0, 2.0, 2, gl.RGBA, gl.UNSIGNED_BYTE):
            "readPixels: width must be an int (GLint, 32 bits); got float 2.0 - use int(...) (or //): "
            "softgl refuses a float where WebGL takes an integer",
        lambda: gl.bindBuffer(gl.ARRAY_BUFFER, prog):
            "bindBuffer: buffer must be a WebGLBuffer or None; got softgl._core.WebGLProgram",
        lambda: gl.drawElements(gl.TRIANGLES, 3, gl.UNSIGNED_SHORT, 2**64):
            "drawElements: offset must be an int of 64 bits (GLintptr); got int 18446744073709551616 - it does not fit",
    }
    for call, message in expected.items():
        with pytest.raises(TypeError) as info:
            call()
        assert str(info.value) == message
    assert gl.getError() == gl.NO_ERROR


def test_what_is_accepted():
    # Integers: Python and NumPy ints and bools, wrapped to 32 bits as WebIDL's ToInt32/ToUint32.
    gl = softgl.Context(8, 8)
    gl.stencilMask(np.uint64(2**64 - 1))
    assert gl.getParameter(gl.STENCIL_WRITEMASK) == 0xFFFFFFFF
    gl.clearStencil(np.int8(-1))
    assert gl.getParameter(gl.STENCIL_CLEAR_VALUE) == -1
    gl.viewport(True, 0, 4, 4)
    assert list(gl.getParameter(gl.VIEWPORT)) == [1, 0, 4, 4]
    # Numbers: ints, NumPy scalars, anything float() takes (not strings).
    gl.clearColor(1, np.float16(0.5), np.int32(0), True)
    assert list(gl.getParameter(gl.COLOR_CLEAR_VALUE)) == [1.0, 0.5, 0.0, 1.0]
    # GLboolean: by truth value, as JS's ToBoolean (numbers, NumPy bools, None).
    gl.colorMask(0, np.bool_(True), None, 2)
    assert gl.getParameter(gl.COLOR_WRITEMASK) == [False, True, False, True]
    assert gl.getError() == gl.NO_ERROR


@pytest.mark.parametrize("kwargs, message", [
    (dict(alpha="no"), "Context: alpha must be a bool; got str 'no'"),
    (dict(premultipliedAlpha=[True]), "Context: premultipliedAlpha must be a bool; got list [True]"),
    (dict(powerPreference=3), "Context: powerPreference must be a str; got int 3"),
    (dict(samples="4"), "Context: samples must be an int; got str '4'"),
    (dict(threads=1.5), "Context: threads must be an int; got float 1.5"),
    (dict(color_format=None), "Context: color_format must be a str; got NoneType None"),
    (dict(strict="yes"), "Context: strict must be a bool; got str 'yes'"),
    (dict(height=8.0), "Context: height must be an int; got float 8.0"),
])
def test_context_attributes_name_the_attribute(kwargs, message):
    with pytest.raises(TypeError) as info:
        softgl.Context(**{"width": 8, "height": 8, **kwargs})
    assert str(info.value) == message


def test_the_methods_written_in_python_name_their_parameter():
    gl = softgl.Context(4, 4)
    with pytest.raises(TypeError) as info:
        gl.getExtension(5)
    assert str(info.value) == "getExtension: name must be a str; got int 5"
    with pytest.raises(TypeError) as info:
        gl.stats("yes")
    assert str(info.value) == "stats: reset must be a bool; got str 'yes'"
