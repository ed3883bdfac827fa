"""Importing the Python files and modules that register plugins: the ``plugins`` key of a configuration.

A physicist's own law or driver lives in a ``.py`` file (or an importable
module) that calls :func:`slidernet.register_distribution` or
:func:`slidernet.register_driver` when it is imported. A configuration
lists such files and modules under ``plugins``; :func:`import_plugins`
imports them, in order, before the names of ``[friction.static]`` and
``[driver]`` are looked up, so that what they register can be named there.

Each entry is imported once per process. A file is loaded under a module
name made from its resolved path (:func:`module_name`): the same in every
process, so that an object defined in the file pickles by reference, and a
worker that imports the file again (every worker loads the configuration)
finds it under that name. A forked worker inherits the module; a spawned or
Dask worker imports it again, so the file must exist at the same path
there. A dotted module name is imported with :func:`importlib.import_module`,
which Python itself caches.

>>> is_file_entry("my_laws.py"), is_file_entry("my_package.laws")
(True, False)
"""

from __future__ import annotations

import hashlib
import importlib
import importlib.util
import re
import sys
import traceback
from collections.abc import Iterable
from pathlib import Path
from types import ModuleType

from slidernet.errors import ConfigError

#: The prefix of the module names of plugin files: outside the ``slidernet`` package, so that
#: no file can shadow one of its modules.
MODULE_PREFIX = "slidernet_plugin_"


def is_file_entry(entry: str) -> bool:
    """True if ``entry`` names a Python file (it ends in ``.py``), False for a dotted module name."""
    return entry.endswith(".py")


def absolute_entry(entry: str, base: str | Path) -> str:
    """``entry`` with a relative file path made absolute against the folder ``base``; a module name as is.

    Parameters
    ----------
    entry : str
        A ``plugins`` entry: the path of a ``.py`` file or a dotted module name.
    base : str or Path
        The folder a relative path is relative to: that of the configuration
        file that names it, or the current directory for ``--plugin``.

    Returns
    -------
    str
        The entry, absolute if it is a file (``~`` expanded, symbolic links
        kept: the path the user wrote, anchored).
    """
    if not is_file_entry(entry):
        return entry
    path = Path(entry).expanduser()
    return str(path if path.is_absolute() else (Path(base) / path).absolute())


def module_name(path: str | Path) -> str:
    """The module name a plugin file is imported under: its stem and a digest of its resolved path.

    The digest (SHA-1, not Python's salted ``hash``) makes the name the same
    in every process and different for two files of the same name.

    >>> module_name("/home/me/my_laws.py") == module_name("/home/me/../me/my_laws.py")
    True
    >>> module_name("/home/me/my_laws.py").startswith("slidernet_plugin_my_laws_")
    True
    """
    resolved = Path(path).expanduser().resolve()
    stem = re.sub(r"\W", "_", resolved.stem)  # a file name may hold '-' or '.', a module name may not
    digest = hashlib.sha1(str(resolved).encode("utf-8")).hexdigest()[:12]
    return f"{MODULE_PREFIX}{stem}_{digest}"


def import_plugins(entries: Iterable[str], *, field: str = "'plugins' field") -> list[ModuleType]:
    """Import each entry, in order; each once per process.

    Parameters
    ----------
    entries : iterable of str
        Paths of ``.py`` files (a relative one is relative to the current
        directory; a configuration file's are made absolute when it is read)
        or dotted module names.
    field : str
        What the entries came from, for the error message.

    Returns
    -------
    list of module
        The imported modules, in the order of ``entries``.

    Raises
    ------
    ConfigError
        If a file does not exist, a module cannot be found, an entry is
        neither, or importing one raises; the message names ``field``, the
        entry and the reason.
    """
    return [import_plugin(entry, field=field) for entry in entries]


def import_plugin(entry: str, *, field: str = "'plugins' field") -> ModuleType:
    """Import one ``plugins`` entry (see :func:`import_plugins`); an entry already imported is not run again."""
    if not isinstance(entry, str) or not entry:
        raise ConfigError(f"The {field}: {entry!r} is not a file path or a module name (a non-empty string).")
    if is_file_entry(entry):
        return _import_file(entry, field)
    if not all(part.isidentifier() for part in entry.split(".")):
        raise ConfigError(
            f"The {field}: cannot import {entry!r}: it is neither the path of a Python file (ending in .py) "
            f"nor a dotted module name such as 'my_package.laws'."
        )
    try:
        return importlib.import_module(entry)
    except ModuleNotFoundError as exc:
        missing = exc.name or ""
        if entry == missing or entry.startswith(missing + "."):  # the entry itself (or its package) is missing
            hint = ". Install it, or put the folder that holds it on PYTHONPATH."
        else:  # the module exists, and one of its own imports failed
            hint = f", which {entry!r} imports."
        raise ConfigError(f"The {field}: cannot import {entry!r}: {exc}{hint}") from exc
    except Exception as exc:  # anything the module raises at import: say what and where
        raise ConfigError(f"The {field}: cannot import {entry!r}: {_reason(exc)}") from exc


def _import_file(entry: str, field: str) -> ModuleType:
    path = Path(entry).expanduser()
    if not path.exists():
        raise ConfigError(
            f"The {field}: cannot import {entry!r}: No such file. A path in a configuration file is relative "
            f"to that file; a --plugin path, to the current directory."
        )
    if not path.is_file():
        raise ConfigError(f"The {field}: cannot import {entry!r}: it is not a file.")
    name = module_name(path)
    if name in sys.modules:  # imported already, in this process or in the parent of a forked worker
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, path.resolve())
    if spec is None or spec.loader is None:  # pragma: no cover - a .py file always has a source loader
        raise ConfigError(f"The {field}: cannot import {entry!r}: Python cannot load it as a module.")
    module = importlib.util.module_from_spec(spec)
    # In sys.modules before it runs, as `import` does: classes defined in the file then pickle by
    # reference, and dataclasses and typing can find their module.
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except Exception as exc:
        del sys.modules[name]  # a failed import leaves nothing behind: fixing the file and retrying works
        raise ConfigError(f"The {field}: cannot import {entry!r}: {_reason(exc, path.resolve())}") from exc
    return module


def _reason(exc: BaseException, source: Path | None = None) -> str:
    """An exception raised at import as one line: its type, message, and the line that raised it.

    The line is the last one of ``source`` (the plugin file) in the traceback, where there is one:
    the line the physicist wrote, not one deep inside numpy.
    """
    if isinstance(exc, SyntaxError):  # its message already names the file and line
        return f"SyntaxError: {exc}."
    frames = traceback.extract_tb(exc.__traceback__)
    own = [f for f in frames if source is not None and Path(f.filename) == source]
    frame = (own or frames or [None])[-1]
    where = f" (line {frame.lineno} of {Path(frame.filename).name})" if frame is not None else ""
    return f"{type(exc).__name__}: {exc}{where}."
