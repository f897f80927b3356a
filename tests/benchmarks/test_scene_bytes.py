"""The benchmark scenes (benchmarks/scenes.py) drawn by softgl give exactly the bytes recorded in
reference/scene_bytes.json, at every thread count and at every SIMD level this CPU runs (the
context's tuning, core/tuning.h).

The hashes were recorded before the speed work on the draw path (executor, fragment batches,
per-fragment ops), so every fast path must reproduce the straightforward path's bytes. They guard
the GLSL draw path end to end (vertex fetch, vertex shader, setup, raster, early/late depth,
fragment shader, blending, MSAA). A deliberate change of the drawn bytes (e.g. a coverage-rule
fix) regenerates them with the command below. That happened once so far, when varying
interpolation moved from double to float (session 4): at 256x256, 44 of the scenes' 983,040 pixels
changed, by 1 in one channel each. Session 9: LINEAR filtering of 8-bit unorm textures took the
fixed-point rule of README "Choices" (8-bit weights): spot_mesh_tex at 256x256 changed in 2,758
of 65,536 pixels, by 1. Regenerate with:

    SOFTGL_UPDATE_SCENE_BYTES=1 python -m pytest tests/benchmarks/test_scene_bytes.py
"""
from __future__ import annotations

import hashlib
import json
import os
import sys
from pathlib import Path

import pytest

from softgl import _core

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"
sys.path.insert(0, str(BENCHMARKS))
import scenes as S  # noqa: E402

REFERENCE = Path(__file__).parent / "reference" / "scene_bytes.json"
SIZE = 96
UPDATE = bool(os.environ.get("SOFTGL_UPDATE_SCENE_BYTES"))
SPECS = {s.key: s for s in S.SUITE + S.EXECUTOR}
_recorded = json.loads(REFERENCE.read_text()) if REFERENCE.exists() else {}
# Tuning::simd levels up to this CPU's best; the best is the default.
SIMD = ["scalar", "sse2", "avx2", "avx512"][:_core.testing.simd_level() + 1]
THREADS = (1, 2, 3)


def _digest(key: str, threads: int, simd: str) -> str:
    spec = SPECS[key]
    r = S.SoftglRenderer(SIZE, SIZE, threads=threads, samples=spec.samples)
    _core.testing.set_tuning(r.gl, simd=simd)
    img = r.render(spec.build(SIZE))
    r.gl.finish()
    # Depth too: early/late depth paths must leave the same depth buffer (seen by a second frame).
    img2 = r.render(spec.build(SIZE)) if spec.key.startswith(("large_b0_d1", "tiny")) else img
    return hashlib.sha256(img.tobytes() + img2.tobytes()).hexdigest()


@pytest.mark.parametrize("simd", SIMD)
@pytest.mark.parametrize("key", sorted(SPECS))
def test_scene_bytes_for_any_thread_count_and_simd_level(key, simd):
    got = {t: _digest(key, t, simd) for t in THREADS}
    assert len(set(got.values())) == 1, f"{key} at {simd}: bytes depend on the thread count: {got}"
    if UPDATE:
        if simd == SIMD[-1]:
            _recorded[key] = got[1]
            REFERENCE.write_text(json.dumps(dict(sorted(_recorded.items())), indent=1) + "\n")
        return
    assert key in _recorded, "no recorded bytes: run with SOFTGL_UPDATE_SCENE_BYTES=1"
    assert got[1] == _recorded[key], f"{key} at {simd}: drawn bytes changed"
