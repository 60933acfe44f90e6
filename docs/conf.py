"""Sphinx configuration of the mbsuite documentation (``make docs``).

Built with ``sphinx-build -W --keep-going -b html docs docs/_build/html``: every warning is an
error.  Pages are Markdown (MyST); the API reference is generated recursively from the docstrings
of the four packages (numpydoc layout); the gallery runs the scripts of ``examples/`` in fast mode.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # the four packages, also without the editable install
sys.path.insert(0, str(ROOT / "docs" / "_ext"))  # local extensions: the gallery's scene-figure scraper

# The examples read MBSUITE_MODE: the gallery runs them in fast mode (set before any example runs).
os.environ["MBSUITE_MODE"] = "fast"
# ... and write their scene folders below MBSUITE_OUT; sphinx-gallery runs each script in its own
# folder, so without this the tables and figures would land in examples/<domain>/out/.
os.environ["MBSUITE_OUT"] = str(ROOT / "docs" / "_build" / "gallery-out")
# ... and queue the figures they hand to their scene for the scraper (docs/_ext/scene_figures.py)
os.environ["MBSUITE_SHOW_FIGURES"] = "1"
os.environ.setdefault("MPLBACKEND", "Agg")

import core  # noqa: E402

project = "mbsuite"
author = "mbsuite developers"
copyright = "mbsuite developers"
release = version = core.__version__

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "**.ipynb_checkpoints",
                    "auto_examples/**/*.ipynb", "auto_examples/**/*.py", "auto_examples/**/*.zip",
                    "auto_examples/**/*.json", "auto_examples/**/*.md5"]

# --- MyST: the README's Markdown moves over nearly verbatim ------------------------------------
myst_heading_anchors = 4          # `[text](page.md#section-title)` links to headings
myst_enable_extensions = ["colon_fence", "deflist"]

# --- API reference ------------------------------------------------------------------------------
autosummary_generate = True
autosummary_imported_members = False
autodoc_default_options = {"members": True, "show-inheritance": True,
                           "ignore-module-all": True}   # a re-exported name is documented once, in its module
autodoc_member_order = "bysource"
autodoc_typehints = "none"        # numpydoc's Parameters sections carry the types
autodoc_mock_imports = ["opensim", "exudyn"]   # optional peers, not installed by `.[docs]`
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_validation_checks: set[str] = set()
numpydoc_xref_param_type = False
nitpicky = False

# --- Gallery: examples/ (sub-folders core, railway, biomech, coaster) ----------------------------
sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples"),
    "gallery_dirs": "auto_examples",
    "filename_pattern": r".*\.py$",      # every example runs (in fast mode, MBSUITE_MODE above)
    "ignore_pattern": r"(__init__|/_[^/]*)\.py$",   # helper modules of examples are not examples
    "subsection_order": ["../examples/core", "../examples/railway", "../examples/biomech",
                         "../examples/coaster", "*"],
    "within_subsection_order": "FileNameSortKey",
    "download_all_examples": False,
    "plot_gallery": "True",
    "remove_config_comments": True,
    "matplotlib_animations": False,
    # mbsuite's figures are pyplot-free Figure objects handed to the scene (docs/_ext/scene_figures.py)
    "image_scrapers": ("matplotlib", "scene_figures.scene_figure_scraper"),
}

# --- HTML -----------------------------------------------------------------------------------------
html_theme = "furo"
html_title = f"mbsuite {release}"
html_static_path: list[str] = []

# Warnings that cannot be fixed in the sources:
# - ref.citation: numpydoc renames the citations of a "References" section; a reference list that the
#   text does not cite by number ([1]_) is reported as "Citation [R...-1] is not referenced", which
#   the numpydoc layout allows (core.contact_laws, biomech.muscles, railway.contact.creep, ...).
suppress_warnings = ["ref.citation"]
