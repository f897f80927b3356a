"""What help() and an IDE see: every public Context method has WebGL's parameter names and a
docstring, and the committed typed stub (python/softgl/_core.pyi) matches the built module."""
import importlib.util
import inspect
import re
from pathlib import Path

import numpy as np
import pytest

import softgl
from softgl import _core

ROOT = Path(__file__).resolve().parents[2]
CONTEXT = softgl.WebGL2RenderingContext


def public_methods():
    return sorted(name for name in dir(CONTEXT)
                  if not name.startswith("_") and inspect.isroutine(getattr(CONTEXT, name)))


def signature_lines(method):
    """The signature lines of a pybind11 method's docstring (one per overload)."""
    return [line for line in (method.__doc__ or "").splitlines()
            if re.match(rf"(\d+\. )?{method.__name__}\(self", line)]


def parameter_names(method):
    """Each overload's parameter names after self."""
    out = []
    for line in signature_lines(method):
        params = line[line.index("(") + 1:line.rindex(") ->")]
        names = [p.split(":")[0].strip() for p in re.split(r",\s*(?![^\[]*\])", params) if p.strip()]
        out.append(names[1:])
    return out


def test_every_public_method_has_names_and_a_docstring():
    methods = public_methods()
    assert len(methods) > 180
    unnamed, undocumented = [], []
    for name in methods:
        method = getattr(CONTEXT, name)
        if inspect.isfunction(method):   # written in Python (python/softgl/context.py)
            params = list(inspect.signature(method).parameters)
            doc = inspect.getdoc(method) or ""
        else:
            params = [p for names in parameter_names(method) for p in names]
            assert signature_lines(method), name
            # The docstring after the signature lines (pybind11 puts the signatures first).
            doc = "\n".join(line for line in method.__doc__.splitlines()
                            if line not in signature_lines(method) and line != "Overloaded function."
                            and line != f"{name}(*args, **kwargs)").strip()
        if any(re.fullmatch(r"arg\d+", p) for p in params):
            unnamed.append(name)
        if not doc:
            undocumented.append(name)
    assert unnamed == []
    assert undocumented == []


def test_the_context_classes_are_documented():
    for cls in (_core.Context, softgl.Context, softgl.WebGLRenderingContext, softgl.WebGL2RenderingContext):
        assert cls.__doc__ and cls.__doc__.strip()
    assert "premultipliedAlpha" in softgl.Context.__doc__ and "README" in softgl.Context.__doc__


def test_names_are_webgls():
    gl = softgl.Context(4, 4)
    assert parameter_names(gl.drawArrays) == [["mode", "first", "count"]]
    assert parameter_names(gl.drawElements) == [["mode", "count", "type", "offset"]]
    assert parameter_names(gl.vertexAttribPointer) == [["index", "size", "type", "normalized", "stride", "offset"]]
    assert parameter_names(gl.blendFuncSeparate) == [["srcRGB", "dstRGB", "srcAlpha", "dstAlpha"]]
    # texImage2D's two WebGL forms: the 9 arguments (and WebGL 2's srcOffset) and an image source.
    assert parameter_names(gl.texImage2D) == [
        ["target", "level", "internalformat", "width", "height", "border", "format", "type", "pixels", "srcOffset"],
        ["target", "level", "internalformat", "format", "type", "source"]]
    assert "Draws count vertices" in gl.drawArrays.__doc__


def test_names_work_as_keywords():
    gl = softgl.Context(2, 2, antialias=False)
    gl.clearColor(red=1, green=0, blue=0, alpha=1)
    gl.clear(mask=gl.COLOR_BUFFER_BIT)
    assert gl.readPixels(x=0, y=0, width=1, height=1, format=gl.RGBA, type=gl.UNSIGNED_BYTE)[0, 0].tolist() == [255, 0, 0, 255]
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, 1, 1, 0, gl.RGBA, gl.UNSIGNED_BYTE, pixels=np.zeros(4, np.uint8))
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, gl.RGBA, gl.UNSIGNED_BYTE, source=np.zeros((1, 1, 4), np.uint8))
    assert gl.getError() == gl.NO_ERROR


def _gen_stubs():
    spec = importlib.util.spec_from_file_location("gen_stubs", ROOT / "tools/gen_stubs.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _shape(stub: str):
    """The stub's classes, functions and parameter names, without types or docstrings."""
    return [re.sub(r":[^,=)]*(?=[,=)])|=[^,)]*|->.*", "", line.strip())
            for line in stub.splitlines() if re.match(r"\s*(class|def) ", line)]


def test_the_committed_stub_matches_the_module():
    pytest.importorskip("pybind11_stubgen")
    committed = (ROOT / "python/softgl/_core.pyi").read_text()
    generated = _gen_stubs().generate()
    assert (ROOT / "python/softgl/py.typed").exists()
    made_by = re.search(r"pybind11 ([\d.]+)", committed.splitlines()[0]).group(1)
    if made_by == _core._pybind11_version:
        assert generated == committed, "python/softgl/_core.pyi is out of date: run python tools/gen_stubs.py"
    else:
        # Another pybind11 spells types differently (e.g. SupportsInt); the names must still agree.
        assert _shape(generated) == _shape(committed), "python/softgl/_core.pyi is out of date: run python tools/gen_stubs.py"
