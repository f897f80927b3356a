"""The benchmark scenes (benchmarks/scenes.py) drawn by softgl give exactly the bytes recorded in
reference/scene_bytes.json, at every thread count.

The hashes were recorded before the speed work on the draw path (executor, fragment batches,
per-fragment ops), so every fast path must reproduce the straightforward path's bytes. They guard
the GLSL draw path end to end (vertex fetch, vertex shader, setup, raster, early/late depth,
fragment shader, blending, MSAA). A deliberate change of the drawn bytes (e.g. a coverage-rule
fix) regenerates them with the command below. That happened once so far, when varying
interpolation moved from double to float (session 4): at 256x256, 44 of the scenes' 983,040 pixels
changed, by 1 in one channel each. Regenerate with:

    SOFTGL_UPDATE_SCENE_BYTES=1 python -m pytest tests/benchmarks/test_scene_bytes.py
"""
from __future__ import annotations

import hashlib
import json
import os
import sys
from pathlib import Path

import pytest

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"
sys.path.insert(0, str(BENCHMARKS))
import scenes as S  # noqa: E402

REFERENCE = Path(__file__).parent / "reference" / "scene_bytes.json"
SIZE = 96
UPDATE = bool(os.environ.get("SOFTGL_UPDATE_SCENE_BYTES"))
SPECS = {s.key: s for s in S.SUITE + S.EXECUTOR}
_recorded = json.loads(REFERENCE.read_text()) if REFERENCE.exists() else {}


def _digest(key: str, threads: int) -> str:
    spec = SPECS[key]
    r = S.SoftglRenderer(SIZE, SIZE, threads=threads, samples=spec.samples)
    img = r.render(spec.build(SIZE))
    r.gl.finish()
    # Depth too: early/late depth paths must leave the same depth buffer (seen by a second frame).
    img2 = r.render(spec.build(SIZE)) if spec.key.startswith(("large_b0_d1", "tiny")) else img
    return hashlib.sha256(img.tobytes() + img2.tobytes()).hexdigest()


@pytest.mark.parametrize("key", sorted(SPECS))
def test_scene_bytes_for_any_thread_count(key):
    got = {t: _digest(key, t) for t in (1, 2, 3)}
    assert len(set(got.values())) == 1, f"{key}: bytes depend on the thread count: {got}"
    if UPDATE:
        _recorded[key] = got[1]
        REFERENCE.write_text(json.dumps(dict(sorted(_recorded.items())), indent=1) + "\n")
        return
    assert key in _recorded, "no recorded bytes: run with SOFTGL_UPDATE_SCENE_BYTES=1"
    assert got[1] == _recorded[key], f"{key}: drawn bytes changed"


LEVELS = ("scalar", "sse2", "avx2", "avx512")


@pytest.mark.parametrize("key", sorted(SPECS))
def test_scene_bytes_at_every_simd_level(key):
    """The draw stages' kernels at each SIMD level the CPU has (the contexts' tuning, simd) give
    the recorded bytes."""
    from softgl import _core
    from softgl.testing import default_tuned
    assert key in _recorded, "no recorded bytes: run with SOFTGL_UPDATE_SCENE_BYTES=1"
    for level in LEVELS[:_core.testing.simd_level() + 1]:
        with default_tuned(simd=level):
            assert _digest(key, 1) == _recorded[key], f"{key}: drawn bytes changed at simd level {level}"
