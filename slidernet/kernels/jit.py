"""How the kernels are compiled and cached: one numba cache per version of the sources, per machine.

numba's own disk cache (``cache=True``) keys a function by the path of its
file and that file's modification time, and checks nothing else. For
slidernet that is wrong twice:

* a kernel compiles helpers of the other files of this folder into its
  machine code: after an edit of ``heap.py`` alone, ``run_plane`` (in
  ``plane.py``) would load its old machine code, with the old layout of the
  heaps (a segfault was seen);
* ``pip install .`` and then ``pip install -e .`` of the same sources put
  the files at two paths with two modification times: the second install
  compiled every kernel again, minutes on a small machine.

:func:`cached_jit` therefore gives each compiled function a cache keyed by
the *content* of the sources: the folder is ``cache_dir()``, one per digest
of this folder's ``.py`` files (:func:`sources_digest`), and numba's
"source stamp" is that digest plus the digest of the function's own file.
An edit anywhere in ``kernels/`` gets new machine code; the same sources
installed anywhere share one cache. numba's index key adds the function's
bytecode, its signature and the machine (CPU name and features), so one
cache folder serves several machines of a cluster on a shared disk.

:func:`compile_lock` serializes compiling across the processes of one
machine (the workers of a run, the test suite's), so that the kernels are
compiled once and loaded by the others; :func:`on_first_compile` tells the
caller when numba really compiles (not when it loads from the cache).
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import os
import re
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import ClassVar

import platformdirs
from numba import njit
from numba.core import caching
from numba.core import event as numba_event

from slidernet._version import folder_digest

try:
    from numba.core.cpu import CPUTargetOptions

    _NUMBA_HAS_NRT_FLAG = hasattr(CPUTargetOptions, "_nrt")
except ImportError:  # pragma: no cover - numba moved its internals
    _NUMBA_HAS_NRT_FLAG = False

_PACKAGE = Path(__file__).resolve().parent.parent  # the slidernet package folder
_KERNELS = Path(__file__).resolve().parent


def kernel_jit(**options) -> Callable:
    """``numba.njit`` for the kernels: compiled once, cached on disk, no reference counting.

    The kernels never allocate arrays; they only read and write the arrays
    they are given. With numba's reference counting (NRT) on, every call of
    a helper that takes arrays increments and decrements each array's count
    atomically: about 4.5 ns per array per call, measured with numba 0.68,
    which made the heap bookkeeping of a 2D slip several times slower than
    its arithmetic. ``_nrt=False`` compiles without it, and a helper's call
    is then a plain call that LLVM inlines where it pays. It is a private
    numba flag, so a numba that refuses it gets the plain decorator.
    """
    if _NUMBA_HAS_NRT_FLAG:
        options["_nrt"] = False
    # Said explicitly: a function that does not set it inherits forceinline from the function being
    # compiled when numba meets it (numba's Flags.inherit_if_not_set), so a large helper first reached
    # from an inlined one (the exact 2D slip's integrator) would be inlined at every call site.
    options.setdefault("forceinline", False)
    return cached_jit(**options)


@functools.cache
def sources_digest() -> str:
    """A digest of the kernels' sources (every ``.py`` file of this folder), 16 hex digits.

    The first digits of :func:`slidernet._version.folder_digest` of this
    folder, the rule behind the run's code identity too.
    """
    return folder_digest(_KERNELS)[:16]


@functools.cache
def _file_digest(path: str) -> str:
    return hashlib.sha1(Path(path).read_bytes()).hexdigest()[:16]


def cache_root() -> str:
    """The folder that holds :func:`cache_dir` of every version of the sources (``NUMBA_CACHE_DIR`` when set)."""
    return os.environ.get("NUMBA_CACHE_DIR") or os.path.join(platformdirs.user_cache_dir("slidernet"), "numba")


def cache_dir() -> str:
    """Where numba keeps slidernet's compiled kernels: a folder per version of their sources.

    Under ``NUMBA_CACHE_DIR`` when the user set it, else under ``numba`` in
    the per-user cache directory (``platformdirs.user_cache_dir("slidernet")``,
    e.g. ``~/.cache/slidernet/numba/<sources_digest()>`` on Linux). Never
    inside the installed package: cache files left in
    ``site-packages/slidernet/`` by a ``pip install .`` outlive a
    ``pip uninstall`` and then shadow an editable install as an empty
    namespace package.
    """
    return os.path.join(cache_root(), sources_digest())


#: The files slidernet's cache folders hold: numba's index (``.nbi``) and machine code (``.nbc``) of each
#: function, and the compile locks of :func:`compile_lock`.
_CACHE_SUFFIXES = (".nbi", ".nbc")
#: A version's folder: 16 hex digits of :func:`sources_digest`; nothing else under the root is slidernet's
#: (``NUMBA_CACHE_DIR`` may hold other packages' caches beside it).
_VERSION_FOLDER = re.compile(r"[0-9a-f]{16}")


def _is_cache_file(name: str) -> bool:
    return name.endswith(_CACHE_SUFFIXES) or (name.startswith("compile-") and name.endswith(".lock"))


def cache_files() -> list[Path]:
    """slidernet's compiled-kernel files under :func:`cache_root`, every version of the sources; [] without one.

    Only the files of the folders named by a sources digest, and of the
    kinds numba and :func:`compile_lock` write there, are counted.
    """
    root = Path(cache_root())
    if not root.is_dir():
        return []
    found = []
    for version in sorted(root.iterdir()):
        if version.is_dir() and not version.is_symlink() and _VERSION_FOLDER.fullmatch(version.name):
            found += [path for path in sorted(version.rglob("*"))
                      if path.is_file() and not path.is_symlink() and _is_cache_file(path.name)]
    return found


def clear_cache() -> tuple[int, int]:
    """Remove slidernet's compiled kernels (:func:`cache_files`) and the folders left empty; (files, bytes).

    Nothing else under :func:`cache_root` is touched; a root that does not
    exist is nothing to clear. The next run compiles the kernels again.
    """
    files = cache_files()
    size = 0
    for path in files:
        size += path.stat().st_size
        path.unlink()
    root = Path(cache_root())
    for version in {path.relative_to(root).parts[0] for path in files}:
        folders = [root / version, *(root / version).rglob("*")]
        for folder in sorted(folders, key=lambda p: len(p.parts), reverse=True):  # the deepest first
            if folder.is_dir() and not any(folder.iterdir()):
                folder.rmdir()
    return len(files), size


class _SourcesLocator(caching._CacheLocator):
    """numba's cache locator for slidernet's functions: where they are installed does not matter.

    The folder is ``cache_dir()/<the file's folder in the package>`` (``kernels``,
    ``validation``, ...); the stamp numba compares before it loads anything
    is the kernels' digest and the digest of the function's own file.
    """

    def __init__(self, py_func: Callable, py_file: str) -> None:
        self._lineno = py_func.__code__.co_firstlineno
        parts = Path(py_file).resolve().parent.relative_to(_PACKAGE).parts
        self._cache_path = os.path.join(cache_dir(), *parts)
        self._stamp = (sources_digest(), _file_digest(str(Path(py_file).resolve())))

    def get_cache_path(self) -> str:
        return self._cache_path

    def get_source_stamp(self) -> tuple[str, str]:
        return self._stamp

    def get_disambiguator(self) -> str:
        return str(self._lineno)

    @classmethod
    def from_function(cls, py_func: Callable, py_file: str) -> _SourcesLocator | None:
        try:
            Path(py_file).resolve().relative_to(_PACKAGE)
        except ValueError:
            return None
        self = cls(py_func, py_file)
        try:
            self.ensure_cache_path()
        except OSError:  # no writable cache folder: compile in every process, as numba would
            return None
        return self


class _SourcesCacheImpl(caching.CompileResultCacheImpl):
    _locator_classes: ClassVar[list[type]] = [_SourcesLocator]


class _SourcesCache(caching.FunctionCache):
    _impl_class = _SourcesCacheImpl


def cached_jit(**options) -> Callable:
    """``numba.njit(**options)`` with a disk cache keyed by the sources' content (see the module)."""

    def decorate(func: Callable) -> Callable:
        dispatcher = njit(**options)(func)
        try:
            dispatcher._cache = _SourcesCache(func)  # what numba's enable_caching() does, with our locator
        except RuntimeError:  # no locator: the cache folder cannot be written
            pass
        return dispatcher

    return decorate


@contextlib.contextmanager
def compile_lock(name: str = "all") -> Iterator[None]:
    """Hold an advisory lock named ``name`` in this version's cache folder: one process compiles, the others
    wait.

    A process that waits then loads from the cache what the first one
    compiled. Processes that compile different things take different names
    and go on side by side. The lock dies with its process. Where ``fcntl``
    is missing (Windows) or the folder cannot be written, nothing is locked.
    """
    try:
        import fcntl
    except ImportError:  # pragma: no cover - Windows
        yield
        return
    try:
        os.makedirs(cache_dir(), exist_ok=True)
        tag = hashlib.sha1(name.encode()).hexdigest()[:12]
        fd = os.open(os.path.join(cache_dir(), f"compile-{tag}.lock"), os.O_RDWR | os.O_CREAT, 0o644)
    except OSError:
        yield
        return
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)  # releases the lock


class _FirstCompile(numba_event.Listener):
    def __init__(self, notice: Callable[[], None]) -> None:
        self.notice = notice
        self.compiled = False

    def on_start(self, event: numba_event.Event) -> None:
        # numba fires this only on a cache miss, for every function it compiles (nested ones too).
        if not self.compiled:
            self.compiled = True
            self.notice()

    def on_end(self, event: numba_event.Event) -> None:
        pass


@contextlib.contextmanager
def on_first_compile(notice: Callable[[], None]) -> Iterator[_FirstCompile]:
    """Call ``notice()`` once, as soon as numba starts compiling anything inside the block.

    Loading from the cache calls nothing. The yielded object's ``compiled``
    says afterwards whether anything was compiled.
    """
    listener = _FirstCompile(notice)
    with numba_event.install_listener("numba:compile", listener):
        yield listener


__all__ = ["cache_dir", "cache_files", "cache_root", "cached_jit", "clear_cache", "compile_lock", "kernel_jit",
           "on_first_compile", "sources_digest"]
