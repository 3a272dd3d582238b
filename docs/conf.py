"""Sphinx configuration of the coated-punch documentation.

Built by ``tests/run.sh`` (``python -m sphinx -W --keep-going -b html docs BUILD_DIR``), so
a warning fails the test run. Everything under ``api/packages``, ``auto_examples`` and
``benchmarks/reports`` is generated at build time (see ``docs/_ext``) and git-ignored.

A build from nothing (no build directory, no generated pages) took 112 s of wall time and
109 s of CPU on a 2-core machine at load average 1.6 (``/usr/bin/time``), 22 s of it
running the gallery's examples (18 s the back-analysis, two calibrations) and ~40 % in
the theme's navigation tree of the ~190 pages (cProfile); peak memory 560 MB. With the
pages of functions and classes kept out of that tree (``api_pages.off_the_tree``; a
faster machine, 2026-12-07, fresh clones one after the other): 35.5 s of CPU against
54.6 s, peak memory 630 MB either way.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(DOCS / "_ext"))

# Small dense matrices: BLAS threads only fight each other on 2 cores (tests/run.sh says
# the same); the gallery's examples solve in this process.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("MPLBACKEND", "Agg")

import core  # noqa: E402  (after the path is set)

project = "coated-punch"
author = "the coated-punch authors"
copyright = "the coated-punch authors"
release = core.__version__
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    # MathJax shipped with the pages: the equations show without a network
    "sphinx-mathjax-offline",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
    "api_pages",
    "cli_help",
    "repo_links",
    "reports",
    "explorer_pages",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "**/README.txt", "examples/*.py"]
templates_path = ["_templates"]

# MyST: $...$ and $$...$$ math, headings linkable as page.md#heading-slug (the links the
# Markdown sources already use on their code host).
myst_enable_extensions = ["dollarmath", "amsmath", "deflist", "colon_fence"]
myst_heading_anchors = 4

# The API reference: one page per public package, generated from each ``__all__``
# (docs/_ext/api_pages.py); numpydoc reads the docstrings.
autosummary_generate = True
autosummary_imported_members = True
autodoc_default_options = {"members": True, "undoc-members": False}
autodoc_typehints = "none"  # the numpydoc sections carry the types with their units
autodoc_member_order = "bysource"
autoclass_content = "class"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_attributes_as_param_list = False

sphinx_gallery_conf = {
    "examples_dirs": "examples",
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "within_subsection_order": "gallery_order.ReadingOrder",
    "download_all_examples": False,
    "remove_config_comments": True,
    "backreferences_dir": None,
    "reset_modules": ("matplotlib",),
    "image_scrapers": ("matplotlib",),
    "abort_on_example_error": True,
    # every build runs every example (~2 s), so one the code no longer runs fails it
    "run_stale_examples": True,
    "show_memory": False,
    "min_reported_time": 1,
}

html_theme = "furo"
html_title = f"coated-punch {release}"
html_static_path: list[str] = []
html_show_sourcelink = False
pygments_style = "sphinx"
