"""Sphinx configuration of the slidernet documentation.

Build (from the repository root, after ``pip install -e ".[docs]"``)::

    python -m sphinx -W --keep-going -b html docs docs/_build/html

Generated parts: the configuration reference from the pydantic models of
``slidernet.config`` (autodoc-pydantic), the API reference from the
docstrings (autodoc, autosummary, numpydoc), the gallery from ``examples/``
(sphinx-gallery, which runs every example). The gallery runs each example's
``--quick`` preset unless ``SLIDERNET_DOCS_QUICK=0`` is set (see
``docs/_ext/slidernet_gallery.py``).
"""

from __future__ import annotations

import sys
from pathlib import Path

import slidernet

DOCS = Path(__file__).resolve().parent
sys.path.insert(0, str(DOCS / "_ext"))  # slidernet_gallery: the gallery's argv and image scraper

# -- Project -------------------------------------------------------------------
project = "slidernet"
author = "The slidernet developers"
copyright = "The slidernet developers"
release = slidernet.__version__
version = ".".join(release.split(".")[:2])

# -- General -------------------------------------------------------------------
extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "sphinxcontrib.autodoc_pydantic",
    "sphinx_gallery.gen_gallery",
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
templates_path = ["_templates"]
exclude_patterns = [
    "_build",
    "_ext",
    "Thumbs.db",
    ".DS_Store",
    # sphinx-gallery writes these next to the pages it generates; they are not pages.
    "auto_examples/*.ipynb",
    "auto_examples/*.py",
    "auto_examples/*.zip",
    "auto_examples/*.md5",
    "auto_examples/*.json",
]
# No intersphinx: the build must not reach the network (and cannot warn about it).
nitpicky = False
# A broken cross-reference is a warning, so -W turns it into an error.
suppress_warnings: list[str] = []

# -- MyST (the Markdown pages) ---------------------------------------------------
myst_enable_extensions = ["colon_fence", "deflist", "dollarmath"]
# Anchors for headings down to level 3, so that [text](model.md#1-two-sliders-and-one-spring-the-paper)
# resolves; a link to a missing page or anchor warns (myst.xref_missing), and -W fails the build.
myst_heading_anchors = 3

# -- autodoc, autosummary, numpydoc ---------------------------------------------
autosummary_generate = True
autosummary_imported_members = False
autodoc_default_options = {"members": True}
autodoc_member_order = "bysource"
autodoc_typehints = "signature"  # in the signature; numpydoc's Parameters sections add the units
numpydoc_show_class_members = False  # autosummary's own class pages list the members
numpydoc_class_members_toctree = False
numpydoc_validation_checks: set[str] = set()  # docstring style is checked by review, not by the build

# -- autodoc-pydantic (the configuration reference) -----------------------------
autodoc_pydantic_model_show_json = False
autodoc_pydantic_model_show_config_summary = False
autodoc_pydantic_model_show_validator_summary = False
autodoc_pydantic_model_show_validator_members = False
autodoc_pydantic_model_show_field_summary = True
autodoc_pydantic_model_member_order = "bysource"
autodoc_pydantic_model_summary_list_order = "bysource"
autodoc_pydantic_model_signature_prefix = "model"
autodoc_pydantic_field_list_validators = False
autodoc_pydantic_field_show_constraints = True
autodoc_pydantic_field_show_default = True
autodoc_pydantic_field_show_required = True
autodoc_pydantic_field_show_optional = True
autodoc_pydantic_field_signature_prefix = "field"

# -- sphinx-gallery (examples/) ---------------------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": "../examples",
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"\.py$",  # run every example (the TOML files are no gallery items)
    "within_subsection_order": "FileNameSortKey",
    # Fully qualified names, not functions, so that Sphinx can cache the configuration.
    "reset_argv": "slidernet_gallery.reset_argv",
    # pyplot figures (none so far) and the PNG files an example writes into its --out folder.
    "image_scrapers": ("matplotlib", "slidernet_gallery.png_scraper"),
    "download_all_examples": False,
    "remove_config_comments": True,
    "show_memory": False,
    "abort_on_example_error": False,  # a failing example warns (-W: the build fails), others still run
    "matplotlib_animations": False,
}

# -- HTML ------------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = f"slidernet {release}"
html_static_path: list[str] = []
html_theme_options = {
    "navbar_align": "left",
    "navbar_end": ["theme-switcher"],  # no repository icons: the site names no external URL
    "secondary_sidebar_items": ["page-toc"],
    "show_prev_next": True,
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
}
html_sidebars = {"index": [], "changelog": [], "citing": [], "reproduction": []}
html_show_sourcelink = False
