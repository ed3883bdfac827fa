"""Checks of the documentation sources that need no Sphinx (.ci/run builds the site itself)."""

from __future__ import annotations

import inspect
import re
import shutil
import subprocess
import typing
from pathlib import Path

import pytest
from pydantic import BaseModel

from slidernet import config

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
EXAMPLES = ROOT / "examples"
GENERATED = ("_build", "auto_examples", "api/generated")


def _models_in(annotation: object) -> set[type[BaseModel]]:
    """The pydantic models an annotation names, at any depth (``X | None``, ``list[X]``, ``Annotated``)."""
    if inspect.isclass(annotation) and issubclass(annotation, BaseModel):
        return {annotation}
    found: set[type[BaseModel]] = set()
    for arg in typing.get_args(annotation):
        found |= _models_in(arg)
    return found


def config_models() -> set[type[BaseModel]]:
    """Every public pydantic model of ``slidernet.config`` and every model nested in their fields."""
    # Defined in the package's modules (slidernet.config.run, ...) and exported by the package.
    todo = [cls for name, cls in vars(config).items() if not name.startswith("_") and inspect.isclass(cls)
            and issubclass(cls, BaseModel) and cls.__module__.startswith(f"{config.__name__}.")]
    seen: set[type[BaseModel]] = set()
    while todo:
        cls = todo.pop()
        if cls in seen:
            continue
        seen.add(cls)
        for field in cls.model_fields.values():
            todo.extend(_models_in(field.annotation))
    return seen


def test_config_models_are_found():
    # The walk below must see the models it checks, nested ones included.
    names = {cls.__name__ for cls in config_models()}
    assert {"Config", "NetworkConfig", "FrictionConfig", "PluginSpec", "UnitsConfig", "SolverConfig",
            "ExecutionConfig"} <= names


def test_configuration_reference_lists_every_model():
    # The reference's tables are generated from the models (tests/test_reference.py checks they are up to date);
    # every key of every model reached from Config has its row (PluginSpec's keys are the plugins').
    source = (DOCS / "configuration-reference.md").read_text(encoding="utf-8")
    rows = set(re.findall(r"^\| `(?:[\w.]+\.)?(\w+)` \|", source, re.M))
    missing = sorted(f"{cls.__name__}.{name}" for cls in config_models() if cls.__name__ != "PluginSpec"
                     for name in cls.model_fields if name not in rows)
    assert not missing, f"docs/configuration-reference.md has no row for {missing}"


def test_every_config_field_has_a_description():
    # The reference is generated from these; a field without one is listed with no meaning.
    bare = sorted(f"{cls.__name__}.{name}" for cls in config_models()
                  for name, field in cls.model_fields.items() if not field.description)
    assert not bare, f"fields without description=: {bare}"


def _pages() -> list[Path]:
    return sorted(p for p in DOCS.rglob("*") if p.suffix in (".md", ".rst")
                  and not any(p.relative_to(DOCS).as_posix().startswith(g) for g in GENERATED))


def _toctree_entries(page: Path) -> list[str]:
    text = page.read_text(encoding="utf-8")
    if page.suffix == ".md":
        blocks = re.findall(r"^```\{toctree\}[^\n]*\n(.*?)^```", text, re.M | re.S)
    else:
        blocks = re.findall(r"^\.\. toctree::\n((?:[ \t]+.*\n|\n)*)", text, re.M)
    entries = []
    for block in blocks:
        for line in block.splitlines():
            line = line.strip()
            if line and not line.startswith(":"):
                entries.append(re.sub(r"^.*<(.*)>$", r"\1", line))  # "Title <page>" -> page
    return entries


def _source_of(entry: str, page: Path) -> Path | None:
    """The file a toctree entry of ``page`` builds from (the gallery's index: examples/README.txt)."""
    name = entry.lstrip("/")
    base = DOCS if entry.startswith("/") else page.parent
    if (base / name).relative_to(DOCS).as_posix() == "auto_examples/index":
        return EXAMPLES / "README.txt"
    for suffix in (".md", ".rst"):
        if (base / f"{name}{suffix}").is_file():
            return base / f"{name}{suffix}"
    return None


def test_the_landing_page_lists_every_part_of_the_site():
    entries = _toctree_entries(DOCS / "index.md")
    assert entries == ["getting-started", "model", "configuration", "guides/index", "auto_examples/index",
                       "api/index", "reproduction", "changelog", "citing"]


@pytest.mark.parametrize("page", _pages(), ids=lambda p: p.relative_to(DOCS).as_posix())
def test_every_toctree_entry_and_included_file_exists(page):
    missing = [e for e in _toctree_entries(page) if _source_of(e, page) is None]
    text = page.read_text(encoding="utf-8")
    included = re.findall(r"^(?:```\{(?:include|literalinclude)\}|\.\. (?:include|literalinclude)::) (\S+)",
                          text, re.M)
    missing += [f for f in included if not (page.parent / f).is_file()]
    assert not missing, f"{page.relative_to(ROOT)} names files that do not exist: {missing}"


def test_every_example_is_a_gallery_item():
    # sphinx-gallery takes an example's title from the first line of its docstring, underlined
    # (reST); the gallery's README.txt says what each one shows.
    readme = (EXAMPLES / "README.txt").read_text(encoding="utf-8")
    for script in sorted(EXAMPLES.glob("*.py")):
        lines = script.read_text(encoding="utf-8").splitlines()
        title = lines[0].removeprefix('"""')
        assert title and lines[1] == "=" * len(title), f"{script.name}: no underlined title in its docstring"
        assert f"``{script.name}``" in readme, f"examples/README.txt does not name {script.name}"


def _tracked_files() -> list[Path]:
    if shutil.which("git") is None or not (ROOT / ".git").exists():
        pytest.skip("not a git checkout")
    out = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True).stdout
    return [ROOT / name for name in out.decode().split("\0") if name]


# Built by concatenation so that this file does not match itself.
OUTSIDE = ("../" + "shared", "MODEL" + ".md", "/wo" + "rk/")


def test_no_tracked_file_refers_outside_the_repository():
    found = []
    for path in _tracked_files():
        if not path.is_file():
            continue
        data = path.read_bytes()
        if b"\0" in data[:8192]:  # binary
            continue
        text = data.decode("utf-8", errors="replace")
        found += [f"{path.relative_to(ROOT)}: {word}" for word in OUTSIDE if word in text]
    assert not found, found
