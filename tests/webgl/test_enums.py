"""softgl's constants against the ones a real WebGL (Chromium) exposes."""
import json
from pathlib import Path

import softgl

REFERENCE = json.loads((Path(__file__).parent / "reference" / "enums.json").read_text())


def test_every_webgl2_constant_on_module_and_context():
    gl = softgl.Context(1, 1, version=2)
    for name, value in REFERENCE["webgl2"].items():
        assert getattr(softgl, name) == value, name
        assert getattr(gl, name) == value, name
        assert getattr(softgl.WebGL2RenderingContext, name) == value, name


def test_webgl1_context_has_exactly_webgl1_constants():
    gl = softgl.Context(1, 1, version=1)
    for name, value in REFERENCE["webgl1"].items():
        assert getattr(gl, name) == value, name
    for name in set(REFERENCE["webgl2"]) - set(REFERENCE["webgl1"]):
        assert not hasattr(gl, name), f"{name} is WebGL 2 only"
