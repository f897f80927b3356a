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

EDGES = "triangle, line or point edges (vertex snapping 1/16 vs 1/256 px)"
# page -> (frames, pixels allowed beyond 1/255, pixels allowed beyond 4/255, cause): the counts
# measured when the references were recorded (160x120 = 19,200 pixels per page).
SCENES = {
    "lambert": (1, 3, 3, EDGES),
    "phong": (1, 200, 30, EDGES + "; specular pow() rounding, 2-4 steps on the highlight"),
    "standard": (1, 5, 3, EDGES),
    "fog": (1, 13, 13, EDGES),
    "fogexp2": (1, 12, 12, EDGES),
    "transparent": (1, 99, 99, EDGES + ": the floor's far edge lies on a row of pixel centres"),
    "points": (1, 21, 21, EDGES),
    "lines": (1, 20, 20, EDGES),
    "shadows": (1, 7, 5, EDGES),
    "instanced": (1, 22, 22, EDGES),
    "merged": (1, 21, 5, EDGES),
    "texture": (1, 4405, 183, "texture filtering: where the footprint switches between NEAREST "
                              "magnification and trilinear minification, and the trilinear weights' "
                              "precision, 1-4 steps (SwiftShader filters with fewer bits); counts "
                              "re-measured with softgl's fixed-point LINEAR rule (README, Choices)"),
    "webgl2": (1, 126, 18, EDGES + "; PBR specular rounding"),
    "image": (1, 1745, 6, "texture filtering of the PNG loaded by THREE.TextureLoader: trilinear "
                          "weights' precision, 1-4 steps (as 'texture'); " + EDGES),
    "flat_normalmap": (1, 66, 48, "the bump map: three.js's dFdx/dFdy of the filtered height "
                                  "texture, where a 1-step filtering difference at a texel step "
                                  "is multiplied into the normal; " + EDGES),
    "anisotropy": (1, 6129, 4518, "anisotropic filtering: softgl takes the extension "
                                  "specification's suggested method (N probes along the major "
                                  "axis at log2(Pmax/N), cpp/softgl/surface/sampler.cpp), "
                                  "SwiftShader its own; both change ~7,000 pixels from isotropic "
                                  "filtering, and differ by up to 31 steps in the distance; the "
                                  "rest as 'texture'"),
    "npot": (1, 87, 0, "the 48x40 PNG resized to 32x32 by three.js through canvas 2D drawImage: "
                       "softgl's bilinear rule (docs/pages.md, Canvas 2D) against Chrome's, "
                       "1-3 steps"),
}
# What three.js may say on the console, by scene (nothing elsewhere).
CONSOLE = {"npot": [("warn", "THREE.WebGLRenderer: Texture has been resized from (48x40) to (32x32).")]}


def agreement(frame: np.ndarray, reference: np.ndarray):
    d = np.abs(frame.astype(int) - reference.astype(int)).max(axis=2)
    return (d <= 1).mean(), (d <= 4).mean(), int((d > 1).sum())


@pytest.mark.parametrize("name", sorted(SCENES))
def test_three_scene_matches_chromium(name):
    frames, allowed, allowed4, cause = SCENES[name]
    result = softgl.page.run(THREE / f"{name}.html", frames=frames)
    assert result.errors == []   # no GL error, no JavaScript exception
    # three.js warns about extensions it asks for and does not get: softgl offers all of them.
    assert result.console == CONSOLE.get(name, [])
    reference = softgl.io.load_image(THREE / "reference" / f"{name}.png", np.uint8)
    frame = result.frames[-1][::-1]
    assert frame.shape == reference.shape
    within1, within4, beyond = agreement(frame, reference)
    beyond4 = round((1 - within4) * frame.shape[0] * frame.shape[1])
    assert beyond <= allowed and beyond4 <= allowed4, (
        f"{name}: {beyond} pixels beyond 1/255 (allowed {allowed}), {beyond4} beyond 4/255 "
        f"(allowed {allowed4}: {cause}); within 1/255 {within1:.4%}")
    # The scene is not empty: the reference has the clear colour and at least two other colours.
    assert len(np.unique(reference.reshape(-1, 4), axis=0)) >= 3
