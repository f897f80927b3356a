"""python -m softgl.showcase renders every gallery picture and a contact sheet, quickly."""
import os
import subprocess
import sys
import time

import numpy as np

from softgl import io, showcase


def test_showcase_renders_every_picture(tmp_path):
    start = time.perf_counter()
    items = showcase.render(tmp_path, progress=False)
    assert time.perf_counter() - start < 30
    assert [name for name, _, _ in items] == [name for name, _, _ in showcase.GALLERY]
    index = (tmp_path / "index.html").read_text()
    for name, title, path in items:
        image = io.load_image(path)
        assert image.shape[0] > 50 and image.shape[1] > 50
        assert len(np.unique(image.reshape(-1, image.shape[-1]), axis=0)) > 3, name   # not blank
        assert f'src="{path.name}"' in index


def test_showcase_command_prints_where_it_is(tmp_path):
    out = subprocess.run([sys.executable, "-m", "softgl.showcase", str(tmp_path / "gallery")],
                         capture_output=True, text=True, check=True,
                         env={**os.environ, "SKBUILD_EDITABLE_VERBOSE": "0"})
    assert str(tmp_path / "gallery" / "index.html") in out.stdout
    assert (tmp_path / "gallery" / "three_spotlights.png").exists()
