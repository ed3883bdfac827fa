"""The installed version of slidernet and the digest of its code, recorded in every result and checkpoint.

The version string names a release; it does not say which code computed a
result: an editable install that pulls new code, or a second install of the
same version with an edited file, keeps it. :func:`code_digest` does: a
digest of every ``.py`` file of the package this process imported. A run's
identity holds both, and a run is resumed only by the code that started it.
"""

from __future__ import annotations

import functools
import hashlib
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

try:
    __version__ = version("slidernet")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0+unknown"


def folder_digest(folder: str | Path) -> str:
    """The SHA-1 (40 hex digits) of the ``.py`` files under ``folder``, its subfolders included.

    Each file's path relative to ``folder`` and its contents, in the order of
    those paths: the same sources give the same digest wherever they are
    installed, and an edited, added, removed or renamed file another one.
    Compiled files (``__pycache__``) are not sources. A detector of change,
    not a signature.
    """
    folder = Path(folder)
    sha = hashlib.sha1()
    for name in sorted(path.relative_to(folder).as_posix() for path in folder.rglob("*.py")):
        sha.update(name.encode())
        sha.update((folder / name).read_bytes())
    return sha.hexdigest()


@functools.cache
def code_digest() -> str:
    """:func:`folder_digest` of the slidernet package this process runs: computed once per process."""
    return folder_digest(Path(__file__).resolve().parent)
