"""The layers of cpp/ depend one way (docs/architecture.md, "Layers"):

    bindings -> api -> pipeline -> surface -> core,   glsl -> core,   runtime -> core

A layer may include its own headers and those of the layers below it; glsl (the compiler and
executor) and runtime (the thread pool) only core. Harnesses (cpp/testing, cpp/fuzz) and the
Python bindings sit on top and may include anything. Within a layer, the modules (a .h with its
.cpp) include each other without cycles; api is the exception: its files are one class, Context,
whose methods are grouped by topic (programs.cpp, textures.cpp, ...) around context.h. This test reads the #include lines, so the rule holds
by itself from now on.
"""
from __future__ import annotations

import re
import sys
from pathlib import Path

import pytest

CPP = Path(__file__).resolve().parents[2] / "cpp"
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)

# What each layer may include (besides itself).
BELOW = {
    "core": set(),
    "glsl": {"core"},
    "runtime": {"core"},
    "surface": {"core", "glsl", "runtime"},
    "pipeline": {"core", "glsl", "runtime", "surface"},
    "api": {"core", "glsl", "runtime", "surface", "pipeline"},
}
ON_TOP = {"bindings", "testing", "fuzz"}


def layer_of(path: Path) -> str:
    rel = path.relative_to(CPP).parts
    return rel[1] if rel[0] == "softgl" else rel[0]


def sources():
    return sorted(p for p in CPP.rglob("*") if p.suffix in (".h", ".cpp"))


def includes(path: Path):
    # Quoted includes name a file beside the includer or below cpp/ (the include directory).
    for m in INCLUDE.finditer(path.read_text()):
        name = m.group(1)
        if (path.parent / name).exists():
            yield path.parent / name
        elif name.startswith("softgl/") or (CPP / name).exists():
            yield CPP / name


def test_every_layer_is_known():
    layers = {layer_of(p) for p in sources()}
    assert layers <= set(BELOW) | ON_TOP, f"unknown layers: {layers - set(BELOW) - ON_TOP}"


def test_includes_point_down():
    wrong = []
    for path in sources():
        src = layer_of(path)
        if src in ON_TOP:
            continue
        for target in includes(path):
            assert target.exists(), f"{path.relative_to(CPP)} includes a missing {target.relative_to(CPP)}"
            dst = layer_of(target)
            if dst != src and dst not in BELOW[src]:
                wrong.append(f"{path.relative_to(CPP)} ({src}) includes {target.relative_to(CPP)} ({dst})")
    assert not wrong, "includes against the layer order:\n" + "\n".join(wrong)


def test_product_code_includes_no_harness():
    wrong = [f"{p.relative_to(CPP)} includes {t.relative_to(CPP)}"
             for p in sources() if layer_of(p) in BELOW
             for t in includes(p) if layer_of(t) in ON_TOP]
    assert not wrong, "\n".join(wrong)


def test_modules_within_a_layer_form_no_cycle():
    # Module = a header and its source (foo.h + foo.cpp); edges: what either includes.
    graph: dict[Path, set[Path]] = {}
    for path in sources():
        if layer_of(path) in ON_TOP or layer_of(path) == "api":
            continue
        module = path.with_suffix("")
        for target in includes(path):
            if layer_of(target) == layer_of(path) and target.with_suffix("") != module:
                graph.setdefault(module, set()).add(target.with_suffix(""))
    state: dict[Path, int] = {}
    cycles = []

    def visit(node, trail):
        state[node] = 1
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                cycle = trail[trail.index(nxt):] + [nxt]
                cycles.append(" -> ".join(str(c.relative_to(CPP)) for c in cycle))
            elif nxt not in state:
                visit(nxt, trail + [nxt])
        state[node] = 2

    for node in sorted(graph):
        if node not in state:
            visit(node, [node])
    assert not cycles, "include cycles between modules:\n" + "\n".join(cycles)


def test_the_rule_catches_a_wrong_include(tmp_path, monkeypatch):
    # The checker itself: a surface file including the pipeline must be reported.
    root = tmp_path / "cpp"
    (root / "softgl" / "surface").mkdir(parents=True)
    (root / "softgl" / "pipeline").mkdir(parents=True)
    (root / "softgl" / "pipeline" / "x.h").write_text("#pragma once\n")
    (root / "softgl" / "surface" / "y.h").write_text('#include "softgl/pipeline/x.h"\n')
    monkeypatch.setattr(sys.modules[__name__], "CPP", root)
    with pytest.raises(AssertionError, match=re.escape("surface/y.h (surface) includes softgl/pipeline/x.h (pipeline)")):
        test_includes_point_down()


def test_the_rule_catches_a_harness_include(tmp_path, monkeypatch):
    # A product file including a harness by its path below cpp/ ("testing/...") must be reported.
    root = tmp_path / "cpp"
    (root / "softgl" / "pipeline").mkdir(parents=True)
    (root / "testing").mkdir(parents=True)
    (root / "testing" / "probe.h").write_text("#pragma once\n")
    (root / "softgl" / "pipeline" / "draw.cpp").write_text('#include "testing/probe.h"\n')
    monkeypatch.setattr(sys.modules[__name__], "CPP", root)
    with pytest.raises(AssertionError, match=re.escape("softgl/pipeline/draw.cpp includes testing/probe.h")):
        test_product_code_includes_no_harness()
