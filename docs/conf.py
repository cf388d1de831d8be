"""Sphinx configuration of the tslip documentation.

Build (warnings are errors)::

    python -m pip install -e ".[docs]"
    python -m sphinx -W --keep-going -b html docs docs/_build/html

``TSLIP_DOCS_RESOLUTION`` (tiny / quick / full) sets the resolution of the
reproduction whose verdict table the "Reproducing the thesis" page embeds.
"""

from __future__ import annotations

import sys
from pathlib import Path

import tslip

sys.path.insert(0, str(Path(__file__).parent / "_ext"))

project = "tslip"
author = "the tslip authors"
copyright = "2026, the tslip authors"  # noqa: A001 - Sphinx's name
release = tslip.__version__
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.viewcode",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
    "tslip_docs",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "gallery/*.ipynb", "**/*.codeobj.json", "**/*.zip"]
myst_heading_anchors = 3
myst_enable_extensions = ["colon_fence"]

napoleon_google_docstring = False
napoleon_numpy_docstring = True
napoleon_use_rtype = False
autodoc_member_order = "bysource"
autodoc_typehints = "none"  # the numpydoc "Parameters" sections carry types and units
autodoc_default_options = {"members": True, "show-inheritance": False}

html_theme = "furo"
html_title = f"tslip {release}"
html_extra_path = ["_generated/extra"]

sphinx_gallery_conf = {
    "examples_dirs": "../examples",
    "gallery_dirs": "gallery",
    "filename_pattern": r"/plot_",
    "within_subsection_order": "FileNameSortKey",
    "download_all_examples": False,
    "remove_config_comments": True,
    "show_memory": False,
    # the Figures tslip.plotting returns (bound to a name), then pyplot's figures
    "image_scrapers": ("tslip_docs.figure_scraper", "matplotlib"),
}
