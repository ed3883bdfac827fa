"""How sphinx-gallery runs slidernet's examples: their command line, and the figures they write.

The examples are command-line scripts: ``main(argv)`` writes its figures as
PNG files into ``--out`` and draws on :class:`matplotlib.figure.Figure`
objects, not through pyplot, so sphinx-gallery's matplotlib scraper sees
nothing. Here

* :func:`reset_argv` gives each example the arguments the gallery runs it
  with: ``--out`` a fresh temporary folder, and ``--quick`` (the short
  preset, seconds per example) unless ``SLIDERNET_DOCS_QUICK=0`` is set in
  the environment of the build (the full presets: minutes);
* :func:`png_scraper` puts the PNG files an example wrote into that folder
  into the gallery, after the code block that wrote them.

``docs/conf.py`` names both by their qualified names, so that Sphinx can
cache its configuration.
"""

from __future__ import annotations

import ast
import os
import shutil
import tempfile
from pathlib import Path
from typing import Any

from sphinx_gallery.scrapers import figure_rst

_OUT_ROOT: Path | None = None
_REPORTED: dict[str, set[Path]] = {}


def quick() -> bool:
    """Whether the gallery runs the quick presets (the default; ``SLIDERNET_DOCS_QUICK=0`` turns it off)."""
    return os.environ.get("SLIDERNET_DOCS_QUICK", "1") != "0"


def out_dir(src_file: str | Path) -> Path:
    """The ``--out`` folder of one example: ``<a temporary folder of this build>/<example name>``."""
    global _OUT_ROOT
    if _OUT_ROOT is None:
        _OUT_ROOT = Path(tempfile.mkdtemp(prefix="slidernet-gallery-"))
    return _OUT_ROOT / Path(src_file).stem


def _options(src_file: Path) -> set[str]:
    """The ``--options`` that the example's argument parser declares (read from its source)."""
    found = set()
    for node in ast.walk(ast.parse(src_file.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Call) and getattr(node.func, "attr", None) == "add_argument":
            found |= {a.value for a in node.args if isinstance(a, ast.Constant) and isinstance(a.value, str)}
    return {o for o in found if o.startswith("--")}


def reset_argv(gallery_conf: dict[str, Any], script_vars: dict[str, Any]) -> list[str]:
    """``sys.argv[1:]`` for one example: ``--out`` a fresh folder, and ``--quick`` where it has one."""
    src_file = Path(script_vars["src_file"])
    out = out_dir(src_file)
    shutil.rmtree(out, ignore_errors=True)
    _REPORTED.pop(str(src_file), None)
    argv = ["--out", str(out)]
    if quick() and "--quick" in _options(src_file):
        argv.append("--quick")
    return argv


def png_scraper(block: Any, block_vars: dict[str, Any], gallery_conf: dict[str, Any]) -> str:
    """The reST of the PNG files the example has written into its ``--out`` folder since the last block."""
    src_file = str(block_vars["src_file"])
    folder = out_dir(src_file)
    seen = _REPORTED.setdefault(src_file, set())
    new = sorted(p for p in folder.rglob("*.png") if p not in seen) if folder.is_dir() else []
    image_paths = []
    for png, image_path in zip(new, block_vars["image_path_iterator"], strict=False):
        shutil.copyfile(png, image_path)
        seen.add(png)
        image_paths.append(image_path)
    return figure_rst(image_paths, gallery_conf["src_dir"])
