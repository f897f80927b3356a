"""Regenerate tests/textures/reference/mrt_webgl{1,2}.npz from real WebGL in headless Chromium
(SwiftShader).

    python tools/regen_mrt_references.py        (needs `apt-get install chromium`)

The scene is tests/textures/mrt_scene.py (three colour attachments, drawBuffers / WEBGL_draw_buffers,
a NONE draw buffer, blending); each file holds `buffers`, (3, 16, 16, 4) uint8, rows bottom-up
as readPixels returns them, and the Chromium version.
"""
import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "webgl"))
sys.path.insert(0, str(ROOT / "tests" / "textures"))
from chromium import chromium_version, run_script  # noqa: E402
import mrt_scene as scene  # noqa: E402

OUT = ROOT / "tests" / "textures" / "reference"


def main():
    result = run_script("const P = " + json.dumps(scene.js_params()) + ";\n" + scene.SCENE_JS, timeout=300)
    OUT.mkdir(parents=True, exist_ok=True)
    version = chromium_version()
    for key, value in result.items():
        assert value["error"] == 0, (key, value["error"])
        buffers = np.array(value["buffers"], np.uint8).reshape(3, scene.SIZE, scene.SIZE, 4)
        np.savez_compressed(OUT / f"mrt_{key}.npz", buffers=buffers, chromium=version)
    print("wrote", sorted(result), "with", version)


if __name__ == "__main__":
    main()
