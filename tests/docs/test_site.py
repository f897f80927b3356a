"""The documentation site builds with warnings as errors, and it executes the notebooks.

The build (Sphinx, furo, myst-nb; docs/conf.py) runs every notebook in notebooks/ top to bottom
with the installed softgl, so this is also the test that the notebooks run: a cell that raises
fails the build, and every notebook page must show the pictures it rendered.
"""
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

import softgl

ROOT = Path(__file__).parents[2]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))


def test_there_are_notebooks():
    assert [p.name[:2] for p in NOTEBOOKS] == ["01", "02", "03", "04", "05", "06", "07", "08", "09"]


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    pytest.importorskip("sphinx")
    pytest.importorskip("myst_nb")
    out = tmp_path_factory.mktemp("site")
    # An editable (developer) install rebuilds the core on import and streams the build's output
    # to the notebook kernels' stdout: keep it quiet.
    env = dict(os.environ, SKBUILD_EDITABLE_VERBOSE="0")
    run = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-c", str(ROOT / "docs"),
                          str(ROOT), str(out)], capture_output=True, text=True, env=env, cwd=ROOT)
    return run, out


def test_site_builds_with_warnings_as_errors(site):
    run, out = site
    assert run.returncode == 0, run.stderr[-6000:]
    pages = [p for p in out.rglob("*.html") if "_static" not in p.parts]
    assert len(pages) >= 20


@pytest.mark.parametrize("notebook", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_notebook_page_shows_its_pictures(site, notebook):
    run, out = site
    page = out / "notebooks" / f"{notebook.stem}.html"
    assert page.exists(), run.stderr[-3000:]
    html = page.read_text()
    assert "Traceback" not in html
    assert len(re.findall(r"<img [^>]*src=\"[^\"]*_images/", html)) >= 1


def test_api_reference_documents_every_context_method(site):
    run, out = site
    html = (out / "docs" / "api.html").read_text()
    methods = [m for m in dir(softgl.Context) if not m.startswith("_") and callable(getattr(softgl.Context, m))]
    missing = [m for m in methods if f'id="softgl.Context.{m}"' not in html]
    assert len(methods) > 150 and missing == []
