"""The multiple-render-target scene (mrt_scene.py) against real WebGL (Chromium + SwiftShader).

References: tests/textures/reference/mrt_webgl{1,2}.npz, regenerated with
`python tools/regen_mrt_references.py` (needs `apt-get install chromium`).
"""
import sys
from pathlib import Path

import numpy as np
import pytest

import softgl

sys.path.insert(0, str(Path(__file__).parent))
import mrt_scene as scene  # noqa: E402

REF = Path(__file__).parent / "reference"


@pytest.mark.parametrize("version", [1, 2])
def test_mrt_scene_matches_chromium(version):
    gl = softgl.Context(scene.SIZE, scene.SIZE, version=version, antialias=False)
    ours = scene.mrt_scene(gl)
    assert gl.getError() == gl.NO_ERROR
    ref = np.load(REF / f"mrt_webgl{version}.npz")["buffers"]
    # Coverage is identical: the same pixels differ from each buffer's clear colour.
    for k, clear in enumerate(scene.CLEAR):
        c = np.round(np.array(clear) * 255)
        assert np.array_equal(np.any(ours[k] != c, axis=2), np.any(ref[k] != c, axis=2)), k
    # Colours agree to one step of 8 bits (SwiftShader interpolates varyings in lower precision).
    diff = np.abs(ours.astype(int) - ref.astype(int))
    assert diff.max() <= 1
    assert (diff > 0).any(axis=3).mean() < 0.3
    # Attachment 1 was NONE for the second triangle: no blended pixels there.
    assert not np.array_equal(ours[0], ours[1])


def test_mrt_scene_same_in_webgl1_and_webgl2():
    a = scene.mrt_scene(softgl.Context(scene.SIZE, scene.SIZE, version=1, antialias=False))
    b = scene.mrt_scene(softgl.Context(scene.SIZE, scene.SIZE, version=2, antialias=False))
    assert np.array_equal(a, b)
