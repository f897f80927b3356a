"""three.js (Debian's libjs-three, r111), unchanged, renders its scenes on softgl as headless
Chromium (SwiftShader) renders the same pages: references recorded once by
tests/pages/record_three.py into tests/pages/three/reference/.

Tolerance as in tests/webgl: pixels within 1/255, except a few on triangle edges. Chromium's
SwiftShader snaps vertices to 1/16 pixel where softgl snaps to 1/256 (README, "Checked against
references"), so a pixel whose centre lies within ~1/32 pixel of an edge may be covered by the
other triangle: such a pixel can differ by the whole colour step across the edge.
"""
from pathlib import Path

import numpy as np
import pytest

import softgl
import softgl.page
from softgl.testing import compare_images

THREE = Path(__file__).parent / "three"
LIBRARY = Path("/usr/share/javascript/three/three.js")

pytestmark = pytest.mark.skipif(not LIBRARY.is_file(), reason="needs Debian's libjs-three (apt-get install libjs-three)")

# page -> (frames, pixels allowed beyond 1/255: the edge pixels, counted when recorded)
SCENES = {
    "lambert": (1, 3),
}


def agreement(frame: np.ndarray, reference: np.ndarray):
    d = np.abs(frame.astype(int) - reference.astype(int)).max(axis=2)
    return (d <= 1).mean(), (d <= 4).mean(), int((d > 1).sum())


@pytest.mark.parametrize("name", sorted(SCENES))
def test_three_scene_matches_chromium(name):
    frames, allowed = SCENES[name]
    result = softgl.page.run(THREE / f"{name}.html", frames=frames)
    assert [e for e in result.errors if not e.startswith("GL: ")] == []
    reference = softgl.io.load_image(THREE / "reference" / f"{name}.png", np.uint8)
    frame = result.frames[-1][::-1]
    assert frame.shape == reference.shape
    within1, within4, beyond = agreement(frame, reference)
    assert beyond <= allowed, f"{name}: {beyond} pixels beyond 1/255 (allowed {allowed}); within 1/255 {within1:.4%}"
    # The scene is not empty: the reference has the clear colour and at least two other colours.
    assert len(np.unique(reference.reshape(-1, 4), axis=0)) >= 3
