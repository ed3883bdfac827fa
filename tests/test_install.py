"""Nothing slidernet caches lives inside the installed package.

numba's cache files written next to the kernels' sources (its default) end
up in ``site-packages/slidernet/`` after ``pip install .``; ``pip uninstall``
leaves them there, and the leftover folder then shadows an editable install
as an empty namespace package. The kernels are therefore cached in the
per-user cache folder (or ``NUMBA_CACHE_DIR``, when set). These tests compile
one small cached function in a fresh interpreter and look where its cache
files land. ``.ci/run`` runs the README's whole install sequence.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

import slidernet

PACKAGE = Path(slidernet.__file__).parent

# Compiles (or loads from the cache) a small cached kernel of the package.
SNIPPET = """
import numpy as np
from slidernet.plugins.drivers import _ar1_in_place
y = np.ones(4)
_ar1_in_place(y, 0.5)
assert y[-1] == 1.875
"""


def _index_files(folder: Path) -> set[Path]:
    return set(folder.rglob("*.nbi")) if folder.exists() else set()


def _run(env_updates: dict[str, str]) -> None:
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", "XDG_CACHE_HOME")}
    env.update(env_updates)
    subprocess.run([sys.executable, "-c", SNIPPET], env=env, check=True, capture_output=True)


LINUX_ONLY = pytest.mark.skipif(sys.platform != "linux", reason="XDG_CACHE_HOME is the per-user cache on Linux")


@pytest.mark.parametrize("variable", [pytest.param("XDG_CACHE_HOME", marks=LINUX_ONLY), "NUMBA_CACHE_DIR"],
                         ids=["per-user", "numba-cache-dir"])
def test_compiled_kernels_are_cached_outside_the_package(tmp_path, variable):
    before = {p: p.stat().st_mtime_ns for p in _index_files(PACKAGE)}
    _run({variable: str(tmp_path)})
    cached = _index_files(tmp_path)
    assert any("_ar1_in_place" in p.name for p in cached), sorted(cached)
    if variable == "XDG_CACHE_HOME":  # platformdirs' per-user cache folder on Linux
        assert all(p.is_relative_to(tmp_path / "slidernet" / "numba") for p in cached)
    after = {p: p.stat().st_mtime_ns for p in _index_files(PACKAGE)}
    assert after == before  # nothing written into the package


def test_another_packages_numba_cache_is_left_alone(tmp_path):
    """Only slidernet's functions are redirected: numba's own setting is restored after each decoration."""
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env["XDG_CACHE_HOME"] = str(tmp_path)
    code = "import numba, slidernet.plugins.drivers; print(repr(numba.config.CACHE_DIR))"
    out = subprocess.run([sys.executable, "-c", code], env=env, check=True, capture_output=True, text=True)
    assert out.stdout.strip() == "''"


def test_each_version_of_the_kernels_sources_has_its_own_cache_folder(tmp_path):
    # A kernel compiles helpers of the other files of kernels/ into its machine code, so an edit
    # anywhere in kernels/ must lead to another folder (tests/test_compile.py runs the whole story).
    import shutil

    from slidernet._version import folder_digest
    from slidernet.kernels import jit

    copy = tmp_path / "kernels"
    shutil.copytree(Path(jit.__file__).parent, copy, ignore=shutil.ignore_patterns("__pycache__"))
    assert folder_digest(copy)[:16] == jit.sources_digest()
    assert jit.cache_dir().endswith(jit.sources_digest())
    heap = copy / "heap.py"
    heap.write_text(heap.read_text() + "\n# an edit\n")
    assert folder_digest(copy)[:16] != jit.sources_digest()
