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

What a plugin computes may come from other files than its own: a module
beside it (``import helper``), which may import others. :func:`plugin_sources`
lists the files of every module a plugin brings in from outside the
environment (its standard library and site-packages, and slidernet itself,
whose code the run's identity covers as a whole), so that a run's identity
can hold their digests: those it brought into ``sys.modules`` when it was
imported, recorded then, and those its source names in an ``import``
statement (found again even when another import brought them in first),
each followed through its own imports. What it cannot see: a module it
imports only once the run has started (inside a function it calls then), a
data file it reads, and the code of an installed package.

>>> is_file_entry("my_laws.py"), is_file_entry("my_package.laws")
(True, False)
"""

from __future__ import annotations

import ast
import functools
import hashlib
import importlib
import importlib.util
import os
import re
import site
import sys
import sysconfig
import traceback
from collections.abc import Iterable, Iterator
from pathlib import Path
from types import ModuleType

from slidernet._paths import absolute_path
from slidernet.errors import ConfigError

#: The prefix of the module names of plugin files: outside the ``slidernet`` package, so that
#: no file can shadow one of its modules.
MODULE_PREFIX = "slidernet_plugin_"

#: The modules each plugin's first import brought into ``sys.modules``, by the plugin module's name.
_BROUGHT_IN: dict[str, tuple[str, ...]] = {}


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
    return absolute_path(entry, base) if is_file_entry(entry) else entry


def module_name(path: str | Path) -> str:
    """The module name a plugin file is imported under: its stem and a digest of its resolved path.

    The digest (SHA-1, not Python's salted ``hash``) makes the name the same
    in every process and different for two files of the same name. It is
    taken of the path's bytes, so a folder whose name is not UTF-8 text
    works too.

    >>> module_name("/home/me/my_laws.py") == module_name("/home/me/../me/my_laws.py")
    True
    >>> module_name("/home/me/my_laws.py").startswith("slidernet_plugin_my_laws_")
    True
    """
    resolved = Path(path).expanduser().resolve()
    stem = re.sub(r"\W", "_", resolved.stem)  # a file name may hold '-' or '.', a module name may not
    digest = hashlib.sha1(os.fsencode(resolved)).hexdigest()[:12]
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
    """Import one ``plugins`` entry (see :func:`import_plugins`); an entry already imported is not run again.

    The modules its first import brings into ``sys.modules`` are recorded
    for :func:`plugin_sources`; a plugin imported inside another's import
    has its own record, and is in the other's too.
    """
    if not isinstance(entry, str) or not entry:
        raise ConfigError(f"The {field}: {entry!r} is not a file path or a module name (a non-empty string).")
    before = set(sys.modules)
    module = _import_file(entry, field) if is_file_entry(entry) else _import_module(entry, field)
    _BROUGHT_IN.setdefault(module.__name__, tuple(sorted(set(sys.modules) - before - {module.__name__})))
    return module


def _import_module(entry: str, field: str) -> ModuleType:
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
    except SystemExit as exc:
        raise ConfigError(_exit_message(field, entry, exc)) from None
    except Exception as exc:  # anything the module raises at import: say what and where
        raise ConfigError(f"The {field}: cannot import {entry!r}: {exception_line(exc)}") from exc


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
    except SystemExit as exc:
        del sys.modules[name]
        raise ConfigError(_exit_message(field, entry, exc)) from None
    except Exception as exc:
        del sys.modules[name]  # a failed import leaves nothing behind: fixing the file and retrying works
        raise ConfigError(f"The {field}: cannot import {entry!r}: {exception_line(exc, path.resolve())}") from exc
    return module


def _exit_message(field: str, entry: str, exc: SystemExit) -> str:
    # A plugin that ends the process at import would end the run without a word (exit 3, say): it is the
    # plugin's error, said as one. KeyboardInterrupt passes: it stops the command as Ctrl-C does.
    return (f"The {field}: cannot import {entry!r}: it called sys.exit({exc.code!r}) while being imported; a "
            "plugin may not end the process (raise an exception instead).")


def exception_line(exc: BaseException, source: Path | None = None) -> str:
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


def plugin_sources(entry: str) -> tuple[str | None, dict[str, str]]:
    """The files a plugin entry computes with: its own, and those of the modules it brings in from outside.

    Parameters
    ----------
    entry : str
        A ``plugins`` entry (imported here if it was not yet).

    Returns
    -------
    own : str or None
        The entry's file: the entry itself for a ``.py`` file; a dotted
        module's file where it lies outside the environment's standard
        library and site-packages (a module of the user's, on
        ``PYTHONPATH``), else None (an installed package).
    imports : dict of str to str
        Module name -> file of every other module outside the environment,
        and outside slidernet, that the entry's import brought in or that
        its source imports, followed through their own imports (see the
        module's docstring), by module name.
    """
    module = import_plugin(entry)
    found: dict[str, str] = {}
    todo = [module, *(sys.modules[name] for name in _BROUGHT_IN.get(module.__name__, ()) if name in sys.modules)]
    seen = set()
    while todo:
        current = todo.pop()
        if current.__name__ in seen:
            continue
        seen.add(current.__name__)
        file = _outside_file(current)
        if file is None and current is not module:
            continue  # an installed or built-in module: its imports are the environment's
        if file is not None:
            found[current.__name__] = file
        todo += [sys.modules[name] for name in _imported_names(current) if name in sys.modules]
    own = found.pop(module.__name__, None)
    return (entry if is_file_entry(entry) else own), dict(sorted(found.items()))


@functools.cache
def _environment() -> tuple[Path, ...]:
    """The folders whose modules are the environment's: its standard library, site-packages, slidernet."""
    paths = sysconfig.get_paths()
    folders = [paths[key] for key in ("stdlib", "platstdlib", "purelib", "platlib") if key in paths]
    folders += site.getsitepackages() if hasattr(site, "getsitepackages") else []
    folders += [site.getusersitepackages()] if site.ENABLE_USER_SITE else []
    folders.append(str(Path(__file__).resolve().parent.parent))  # slidernet: its code digest covers it
    return tuple(Path(folder).resolve() for folder in folders)


def _outside_file(module: ModuleType) -> str | None:
    """The file of ``module`` if it lies outside :func:`_environment`, else None (none, or the environment's)."""
    file = getattr(module, "__file__", None)
    if not isinstance(file, str) or not os.path.isfile(file):
        return None
    resolved = Path(file).resolve()
    return None if any(resolved.is_relative_to(folder) for folder in _environment()) else file


def _imported_names(module: ModuleType) -> Iterator[str]:
    """Every module name an ``import`` statement of ``module``'s source may bring in (and their packages)."""
    file = getattr(module, "__file__", None)
    try:
        tree = ast.parse(Path(file).read_bytes()) if isinstance(file, str) and file.endswith(".py") else None
    except (OSError, SyntaxError, ValueError):
        tree = None
    for node in ast.walk(tree) if tree is not None else ():
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            try:
                base = importlib.util.resolve_name("." * node.level + (node.module or ""), module.__package__) \
                    if node.level else node.module
            except (ImportError, ValueError):  # a relative import outside a package
                continue
            names = [f"{base}.{alias.name}" for alias in node.names] + ([base] if base else [])
        else:
            continue
        for name in names:
            parts = name.split(".")
            yield from (".".join(parts[:k]) for k in range(1, len(parts) + 1))
