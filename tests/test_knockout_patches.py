"""The patches of benchmarks/knockout/ still apply to the kernels they double a part of.

``benchmarks/knockout.py`` applies each patch to a checkout of HEAD; a change
of the kernels that moves the patched lines would make the script fail only
when someone next measures. ``git apply --check`` reads the working tree and
writes nothing.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PATCHES = sorted((ROOT / "benchmarks" / "knockout").glob("*.diff"))


def test_there_are_patches():
    assert {p.name for p in PATCHES} >= {"roots_twice.diff", "trees_both.diff"}


@pytest.mark.skipif(shutil.which("git") is None or not (ROOT / ".git").exists(),
                    reason="needs git and a checkout of the repository")
@pytest.mark.parametrize("patch", PATCHES, ids=[p.stem for p in PATCHES])
def test_patch_applies_to_the_working_tree(patch):
    done = subprocess.run(["git", "-C", str(ROOT), "apply", "--check", str(patch)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
