"""Sphinx configuration of softgl's documentation site.

Build from the repository root (the pages live in docs/, the notebooks in notebooks/):

    python -m sphinx -W -c docs . build/docs

The notebooks are executed during the build (myst-nb), so every picture on the site is one the
installed softgl just rendered; a notebook cell that raises fails the build.
"""
import softgl

project = "softgl"
author = "the softgl developers"
copyright = "2026, the softgl developers"
release = softgl.__version__

extensions = ["myst_nb", "sphinx.ext.autodoc", "sphinx.ext.napoleon"]

# The repository root is the source directory: only these files are pages.
root_doc = "docs/index"
include_patterns = ["docs/*.md", "notebooks/*.ipynb", "README.md", "benchmarks/README.md",
                    "benchmarks/results/*.md"]
exclude_patterns = ["build", ".venv"]

myst_enable_extensions = ["dollarmath", "colon_fence"]
myst_heading_anchors = 3

nb_execution_mode = "force"
nb_execution_timeout = 600
nb_execution_raise_on_error = True
nb_execution_show_tb = True

autodoc_member_order = "bysource"
autodoc_typehints = "signature"

html_theme = "furo"
html_title = f"softgl {release}"
