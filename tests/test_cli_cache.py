"""``slidernet cache``: where the compiled kernels are kept, and clearing them (issue 46, point 3).

Every test points ``NUMBA_CACHE_DIR`` at a temporary folder holding files laid out as numba and
:func:`slidernet.kernels.jit.compile_lock` write them, beside files that are not slidernet's: nothing is
compiled, and the user's own cache is never touched.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from slidernet import cli
from slidernet.kernels import jit

#: slidernet's files, relative to the cache root: two versions of the sources, and their sizes in bytes.
OURS = {"0123456789abcdef/kernels/pair.run_pair-40.py312.nbi": 100,
        "0123456789abcdef/kernels/pair.run_pair-40.py312.1.nbc": 2000,
        "0123456789abcdef/compile-1a2b3c4d5e6f.lock": 0,
        "fedcba9876543210/validation/event_loop.step-12.py312.nbi": 300}
#: Files that are not slidernet's: another package's numba cache beside ours, and a stranger in our folder.
THEIRS = ("otherpackage/module.func-3.py312.nbi", "0123456789abcdef/notes.txt", "README")


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    root = tmp_path / "numba"
    for name, size in {**OURS, **dict.fromkeys(THEIRS, 7)}.items():
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_bytes(b"x" * size)
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(root))
    return root


def test_cache_shows_the_folder_the_files_and_their_size(cache, capsys):
    assert cli.main(["cache"]) == 0
    out = capsys.readouterr().out
    assert f"kernel cache: {cache}" in out
    assert f"{len(OURS)} files, {sum(OURS.values()) / 2**20:.1f} MiB" in out
    assert "slidernet cache clear" in out


def test_cache_clear_removes_only_slidernets_files(cache, capsys):
    assert cli.main(["cache", "clear"]) == 0
    assert f"removed {len(OURS)} files" in capsys.readouterr().out
    left = sorted(str(path.relative_to(cache)) for path in cache.rglob("*") if path.is_file())
    assert left == sorted(THEIRS)
    assert not (cache / "fedcba9876543210").exists()  # a version's folder left empty goes too
    assert jit.cache_files() == []


def test_cache_without_a_folder(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "missing"))
    assert cli.main(["cache", "clear"]) == 0
    assert cli.main(["cache"]) == 0
    assert "0 files, 0.0 MiB" in capsys.readouterr().out
    assert not (tmp_path / "missing").exists()


def test_cache_refuses_another_action(cache, capsys):
    with pytest.raises(SystemExit) as stop:
        cli.main(["cache", "purge"])
    assert stop.value.code == 2
    assert "invalid choice: 'purge'" in capsys.readouterr().err
