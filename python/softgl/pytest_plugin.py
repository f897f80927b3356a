"""pytest plugin: the ``golden`` fixture and the ``--update-goldens`` option.

Enable it in a conftest.py with ``pytest_plugins = ["softgl.pytest_plugin"]`` (or ``-p
softgl.pytest_plugin``). A test then compares an image with a committed PNG::

    def test_alpha_cube(golden):
        gl = draw_alpha_cube()
        golden("blend/alpha_cube", gl)          # tests/goldens/blend/alpha_cube.png

Goldens hold *reviewed* images: a person has looked at each one and agreed that it is right
(or it comes from an independent reference such as Chromium or a float64 formula). A golden
only catches changes; it never proves that the code which produced it is correct, so a golden
must not be the sole expected value for the code that wrote it. ``pytest --update-goldens``
writes the images the tests produce instead of comparing: use it only for a deliberate change,
then look at every PNG it lists before committing.

Goldens are stored as given, row 0 at the top: pass the context itself (its canvas is read top
row first) or flip a readPixels result (``[::-1]``) so that reviewers see the picture upright.
Float images are stored as 8-bit PNGs (within the default atol of one 8-bit step).

The folder is ``tests/goldens`` under pytest's rootdir, or the ``golden_dir`` ini option.
On a mismatch, the actual/expected/diff images are written into the test's ``tmp_path``
(``golden-<name>/``), or into ``<DIR>/golden-<name>/`` with ``--image-failures=DIR`` (e.g. a
folder that CI keeps); the failure message names the folder. Nothing is written elsewhere.
"""
from __future__ import annotations

import re
from pathlib import Path

import pytest

from .io import load_image, save
from .testing import _image, _for_png, assert_images_close, compare_images

_written = pytest.StashKey[list]()


def pytest_addoption(parser):
    group = parser.getgroup("softgl")
    group.addoption("--update-goldens", action="store_true", default=False,
                    help="write golden images instead of comparing (deliberate changes only; "
                         "review every written PNG)")
    parser.addini("golden_dir", "folder of golden PNGs, relative to the rootdir",
                  default="tests/goldens")
    group.addoption("--image-failures", default=None, metavar="DIR",
                    help="write the images of failed golden comparisons into DIR/golden-<name>/ "
                         "(default: the test's tmp_path)")


def pytest_configure(config):
    config.stash[_written] = []


def _golden_path(root: Path, name: str) -> Path:
    # Names are relative paths of plain characters, so a typo cannot write outside the folder.
    if not re.fullmatch(r"[A-Za-z0-9_-]+(/[A-Za-z0-9_-]+)*(\.png)?", name):
        raise ValueError(f"golden: name {name!r} must be like 'topic/picture' "
                         "(letters, digits, _ and -, separated by /)")
    return root / (name if name.endswith(".png") else name + ".png")


@pytest.fixture
def golden(request):
    """golden(name, image, **tolerances): compare `image` (an array or a softgl context) with the
    golden PNG `name`; tolerances are assert_images_close's (atol, max_outliers, min_psnr)."""
    config = request.config
    root = Path(config.rootpath) / config.getini("golden_dir")
    update = config.getoption("update_goldens")
    chosen = config.getoption("image_failures")

    def failures() -> Path:   # asked for only on a failure, so passing tests make no folder
        return Path(chosen) if chosen else request.getfixturevalue("tmp_path")

    def check(name: str, image, **tolerances):
        path = _golden_path(root, name)
        actual = _image(image, "golden")
        label = "golden-" + name.replace("/", "-").removesuffix(".png")
        if update:
            stored = load_image(path) if path.exists() else None
            # Rewrite only what changed, so an update does not touch unchanged files in git.
            if (stored is None or stored.shape != actual.shape
                    or compare_images(actual, stored, tolerances.get("atol", 1 / 255)).outliers
                    > tolerances.get("max_outliers", 0)):
                save(_for_png(actual), path)
                config.stash[_written].append(
                    f"{'updated' if stored is not None else 'created'} {path}")
            return
        if not path.exists():
            written = save(_for_png(actual), failures() / label / "actual.png").resolve()
            pytest.fail(f"golden {path} does not exist. This test's image is {written}: "
                        f"review it, then create the golden with pytest --update-goldens",
                        pytrace=False)
        expected = load_image(path)
        # Compare without writing; on a failure compare again, writing the images.
        try:
            assert_images_close(actual, expected, name=label, **tolerances)
            return
        except AssertionError:
            pass
        assert_images_close(actual, expected, name=label, out_dir=failures(), **tolerances)

    return check


def pytest_terminal_summary(terminalreporter, config):
    written = config.stash.get(_written, [])
    if written:
        terminalreporter.section("golden images written (review each before committing)")
        for line in written:
            terminalreporter.write_line(line)
