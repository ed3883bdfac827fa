"""Paths as slidernet takes them: anchored once in the process that reads them, and what they name.

Every path a run hands to its workers is absolute (:func:`absolute_path`):
a Dask worker starts in its own working folder, where a relative path
names another file or none. :func:`not_a_folder` and :func:`not_utf8` say,
in words for a one-line message, why a path cannot be an output folder;
:func:`slidernet.io.store.check_output_dir` is the rule built on them.

>>> absolute_path("/data/graph.graphml", "/home/me")
'/data/graph.graphml'
>>> absolute_path("graph.graphml", "/home/me/runs")
'/home/me/runs/graph.graphml'
>>> import os
>>> not_utf8(os.fsdecode(b"caf\\xe9")), not_utf8("café")
('is not UTF-8 text: its byte 0xe9 cannot be decoded', None)
"""

from __future__ import annotations

import errno
import os
from pathlib import Path


def absolute_path(path: str | os.PathLike[str], base: str | os.PathLike[str]) -> str:
    """``path`` made absolute against the folder ``base`` (``~`` expanded, symbolic links kept).

    Parameters
    ----------
    path : path-like
        A path as the user wrote it.
    base : path-like
        The folder a relative ``path`` is relative to: that of the
        configuration file that names it, or the current directory.

    Returns
    -------
    str
        The path the user wrote, anchored: not resolved, so that a link
        keeps pointing where it points when the run resumes.
    """
    expanded = Path(path).expanduser()
    return str(expanded if expanded.is_absolute() else (Path(base) / expanded).absolute())


def not_utf8(path: str | os.PathLike[str]) -> str | None:
    """Why ``path`` is not UTF-8 text, in words; None if it is.

    A name with a byte that is not UTF-8 reaches Python as a lone surrogate
    (``surrogateescape``): Python's own file functions take it, but the
    netCDF library, which names its files in UTF-8, does not.
    """
    text = os.fspath(path)
    try:
        text.encode("utf-8")
    except UnicodeEncodeError as exc:
        code = ord(text[exc.start])
        if 0xDC80 <= code <= 0xDCFF:  # the byte that surrogateescape kept
            return f"is not UTF-8 text: its byte 0x{code - 0xDC00:02x} cannot be decoded"
        return f"is not UTF-8 text: it holds the character U+{code:04X}, which UTF-8 cannot encode"
    return None


def not_a_folder(path: str | os.PathLike[str]) -> str | None:
    """What ``path`` is, in words, where it exists (or is a symbolic link) but is not a folder; else None.

    >>> import tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> (folder / "loop").symlink_to(folder / "loop")
    >>> not_a_folder(folder), not_a_folder(folder / "missing"), not_a_folder(folder / "loop")
    (None, None, 'is a symbolic link in a loop of links, which never reaches a folder')
    """
    path = Path(path)
    if path.is_dir():
        return None
    if path.is_symlink():
        target = Path(os.readlink(path))
        target = target if target.is_absolute() else path.parent / target
        try:
            os.stat(path)
        except OSError as exc:
            if exc.errno == errno.ELOOP:
                return "is a symbolic link in a loop of links, which never reaches a folder"
            return f"is a symbolic link to {str(target)!r}, which does not exist"
        return f"is a symbolic link to the file {str(target)!r}"
    if path.is_file():
        return "is a file"
    if os.path.lexists(path):
        return "is not a folder"
    return None
