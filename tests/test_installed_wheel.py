"""The suite runs against the installed manylinux wheel when quickstart.sh built one.

`./quickstart.sh test` (and so CI) builds the wheel, repairs it with auditwheel, installs it and
names it in SOFTGL_TESTED_WHEEL; then `softgl` must be imported from that installation, not from
the source tree's python/ folder. Without the variable (a developer's editable install) this skips.
"""
import importlib.metadata
import os
import zipfile
from pathlib import Path

import pytest

import softgl

WHEEL = os.environ.get("SOFTGL_TESTED_WHEEL")


@pytest.mark.skipif(not WHEEL, reason="not run by quickstart.sh (no wheel built)")
def test_softgl_is_the_installed_manylinux_wheel():
    wheel = Path(WHEEL)
    assert "manylinux" in wheel.name
    source_tree = Path(__file__).parents[1] / "python"
    imported = Path(softgl.__file__).resolve()
    assert source_tree not in imported.parents
    dist = importlib.metadata.distribution("softgl")
    installed_core = [f for f in dist.files if f.name.startswith("_core") and f.suffix == ".so"]
    assert len(installed_core) == 1
    core = Path(dist.locate_file(installed_core[0])).resolve()
    assert core.parent == imported.parent
    with zipfile.ZipFile(wheel) as z:
        assert z.read(str(installed_core[0]).replace(os.sep, "/")) == core.read_bytes()
