"""Output folders, and a run's checkpoint folder: what is done, kept so that a killed run loses (almost) nothing.

One lock per output folder, whatever writes into it: a run (and its
resume), a sweep (and each of its points, in its point's folder), the
paper's reproduction and ``slidernet plot`` (while it makes its picture)
take the folder's :class:`FolderLock`, ``DIR/.slidernet.lock``, before they
write anything there, and refuse a folder whose lock another process holds. Each
kind of output keeps to its own folders: a run never writes into a folder
that holds a sweep or a paper reproduction, nor they into a run's
(:func:`check_own_folder`; ``--overwrite`` replaces only the files of its
own kind).

Layout of a run's output directory ``DIR`` while its run is unfinished
(plain numeric files and JSON; no pickle)::

    .slidernet.lock          the folder's lock, while a process works in it (FolderLock)
    checkpoint/
      run.json               the run's identity: the configuration (without its
                             execution table), the resolved seed, the number of
                             realizations, the slidernet version, the digest of
                             slidernet's sources (``slidernet_code``), the SHA-256
                             of every input file (``inputs``), and ``digest``, the
                             SHA-256 of all of these
      block-<first>-<k>.npz  finished realizations, written together: their
                             indices, the run's digest (``run``), then every
                             record stacked (ragged records, the event catalogue,
                             concatenated with offsets);
                             block-<first>-<k>-<j>.npz where that name is taken
                             (j = 1, 2, ...; a realization in two blocks is read
                             from the one written last)
      partial-<r>.npz        a realization in progress (slidernet.io.checkpoint),
                             the run's digest in its meta

Every file is written to a temporary name and renamed, so a kill at any time
leaves either the old file or the new one; what a killed process left under a
temporary name is removed by the next run in the folder, which holds the lock.
The set of finished realizations is read from the blocks themselves (not from
a list that could disagree with them). A block or a partial file is read only
if it names this run's digest. Once ``result.nc`` is written the checkpoint
folder is removed, and when the run lets its lock go the lock file too: a
finished run leaves ``DIR/result.nc`` alone. ``docs/guides/file-formats.md``
says this for a user.
"""

from __future__ import annotations

import errno
import hashlib
import json
import os
import re
import secrets
import shutil
import warnings
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from slidernet._paths import not_a_folder, not_utf8
from slidernet.errors import CheckpointError, CheckpointWarning, FolderInUseError, OutputError
from slidernet.io.checkpoint import check_arrays, checkpoint_info, read_arrays, write_arrays
from slidernet.io.netcdf import atomic_output, reason, remove_temporaries

Record = dict[str, Any]

# A block's name; the suffix -<j> tells apart blocks whose first realization and size agree.
_BLOCK = re.compile(r"block-(\d+)-(\d+)(?:-(\d+))?\.npz")
_PARTIAL = re.compile(r"partial-(\d+)\.npz")

#: The keys of a run's identity (``run.json`` holds them and ``digest``).
IDENTITY_KEYS = ("config", "seed", "realizations", "slidernet_version", "slidernet_code", "inputs")

#: What each kind of output writes at the top of its folder, by which a folder is known as its. A
#: sweep's folder holds a result.nc too: the kinds are tried in this order.
OUTPUT_KINDS: dict[str, tuple[str, ...]] = {"sweep": ("sweep.json", "points"),
                                            "paper reproduction": ("summary.json", "runs"),
                                            "run": ("checkpoint", "result.nc")}


def _block_order(path: Path) -> tuple[int, int]:
    """(first realization, suffix j; 0 without one): the order in which blocks were written, per first index."""
    m = _BLOCK.fullmatch(path.name)
    return int(m.group(1)), int(m.group(3) or 0)


def _flat_diff(a: Any, b: Any, prefix: str = "") -> list[str]:
    """Dotted keys where two JSON-like trees differ."""
    if isinstance(a, dict) and isinstance(b, dict):
        out = []
        for key in sorted(set(a) | set(b)):
            out += _flat_diff(a.get(key), b.get(key), f"{prefix}{key}.")
        return out
    return [] if a == b else [f"{prefix[:-1]} ({json.dumps(a)} in the checkpoint, {json.dumps(b)} now)"]


def run_digest(identity: Mapping[str, Any]) -> str:
    """The SHA-256 (hex) of a run's identity (:data:`IDENTITY_KEYS`), in canonical JSON: what names a run.

    Every file of a run's checkpoint carries it, and no file that carries
    another is ever read for this run.
    """
    canonical = json.dumps({key: identity[key] for key in IDENTITY_KEYS}, sort_keys=True,
                           separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(canonical.encode("utf-8")).hexdigest()


def file_digest(path: str | Path) -> str:
    """The SHA-256 (hex) of a file's bytes, read in pieces of 1 MiB.

    Raises
    ------
    CheckpointError
        If the file cannot be read, naming it.
    """
    sha = hashlib.sha256()
    try:
        with open(path, "rb") as fh:
            for piece in iter(lambda: fh.read(1 << 20), b""):
                sha.update(piece)
    except OSError as exc:
        raise CheckpointError(f"The input file {str(path)!r} cannot be read: {reason(exc)}.") from None
    return sha.hexdigest()


class FolderLock:
    """An advisory lock on an output folder: one slidernet command at a time works in it.

    ``flock`` on the file ``folder/.slidernet.lock``, opened for writing (so
    that NFS, which emulates it with byte-range locks, locks it too). The
    operating system releases the lock when the process that holds it ends,
    however it ends (kill -9 included), so a lock never outlives its command
    and never blocks a resume; forked worker processes share it. The file
    holds the holder's process id and what it is doing, for the message of a
    process that is refused, and is removed on :meth:`release`.

    Parameters
    ----------
    folder : path
        An existing folder.
    holder : str
        What takes the lock, for that message: ``"run"``, ``"sweep"``,
        ``"paper reproduction"``, ``"plot"``.

    Raises
    ------
    FolderInUseError
        From :meth:`acquire`, if another process holds the lock.
    """

    NAME = ".slidernet.lock"

    def __init__(self, folder: str | Path, holder: str) -> None:
        self.folder = Path(folder)
        self.holder = holder
        self.path = self.folder / self.NAME
        self._fd: int | None = None

    @property
    def held(self) -> bool:
        """True while this object holds the lock."""
        return self._fd is not None

    def acquire(self) -> None:
        """Take the lock, or refuse at once (never wait) if another process holds it.

        Where the file system cannot lock (``flock`` unsupported), a
        :class:`~slidernet.errors.CheckpointWarning` says so and the run goes
        on unlocked.
        """
        import fcntl  # POSIX; the module is imported where a lock is taken

        while True:
            try:
                fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o666)
            except OSError as exc:
                raise OutputError(f"Cannot write in the output directory {str(self.folder)!r}: "
                                  f"{reason(exc)}.") from None
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                pid, what = _read_holder(fd)
                os.close(fd)
                who = f"process {pid}" if pid else "another process"
                raise FolderInUseError(
                    f"{str(self.folder)!r} is in use: a slidernet {what} is still going there ({who} holds its "
                    f"lock {str(self.path)!r}). Wait for it to end, or stop it, before you resume it or start "
                    "another command there.") from None
            except OSError as exc:
                os.close(fd)
                if exc.errno not in (errno.ENOLCK, errno.EOPNOTSUPP, errno.ENOSYS, errno.EBADF, errno.EINVAL):
                    raise
                warnings.warn(f"The output directory {str(self.folder)!r} cannot be locked on this file system "
                              f"({reason(exc)}): nothing stops a second run from working in it at the same time.",
                              CheckpointWarning, stacklevel=3)
                return
            # The file may have been removed by its last holder between our open and our lock: then we
            # hold a lock on a file that nobody else will find. Lock the file at the path instead.
            try:
                same = os.stat(self.path).st_ino == os.fstat(fd).st_ino
            except FileNotFoundError:
                same = False
            if same:
                break
            os.close(fd)
        os.ftruncate(fd, 0)
        os.write(fd, f"{os.getpid()} {self.holder}\n".encode())
        self._fd = fd

    def release(self) -> None:
        """Remove the lock file and let the lock go (the file is removed first, while it is still held)."""
        if self._fd is None:
            return
        self.path.unlink(missing_ok=True)
        os.close(self._fd)
        self._fd = None

    def __enter__(self) -> FolderLock:
        self.acquire()
        return self

    def __exit__(self, *exc: Any) -> None:
        self.release()


@contextmanager
def locked_folder(folder: str | Path, kind: str) -> Iterator[Path]:
    """Hold ``folder``'s :class:`FolderLock` for the block, as ``kind`` of :data:`OUTPUT_KINDS`; made if missing.

    Under the lock, a folder that holds another kind of output is refused
    (:func:`check_own_folder`) and what killed processes left there under a
    temporary name is removed. A folder made here and left empty by the
    block is removed again (a command refused before any work leaves no
    folder behind).

    Raises
    ------
    OutputError
        If ``folder`` is not a folder (:func:`check_output_dir`), cannot be
        made, or holds another kind of output.
    FolderInUseError
        If another process holds the lock.
    """
    folder = Path(folder)
    check_output_dir(folder)
    made = not folder.exists()
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"Cannot create the output directory {str(folder)!r}: {reason(exc)}.") from None
    try:
        with FolderLock(folder, kind):
            check_own_folder(folder, kind)
            remove_temporaries(folder)
            yield folder
    finally:
        if made and folder.is_dir() and not any(folder.iterdir()):
            folder.rmdir()


def check_own_folder(folder: Path, kind: str) -> None:
    """Refuse to write ``kind`` of output (:data:`OUTPUT_KINDS`) into a folder that holds another kind.

    Whatever the flags: ``--overwrite`` replaces what a command of the same
    kind wrote there (a run's result, a sweep's points), never another
    kind's work, which a mistyped ``--out`` would otherwise cost.

    Raises
    ------
    OutputError
        Naming the kind found and the files that tell it.
    """
    for held, marks in OUTPUT_KINDS.items():
        found = [mark for mark in marks if os.path.lexists(folder / mark)]
        if found:
            if held != kind:
                raise OutputError(
                    f"{str(folder)!r} holds a {held} ({', '.join(found)}): a {kind} does not write there, even "
                    f"with --overwrite, which replaces only a {kind}'s own files. Use another output directory.")
            return


def _read_holder(fd: int) -> tuple[int | None, str]:
    """The process id and the kind of command a lock file names (a run, where it does not say)."""
    try:
        pid, _, what = os.pread(fd, 256, 0).decode().strip().partition(" ")
        return int(pid or "0") or None, what or "run"
    except (OSError, ValueError):
        return None, "command"


class RunStore:
    """The checkpoint folder ``out_dir / "checkpoint"`` of one run.

    Parameters
    ----------
    out_dir : path
        The run's output directory; made absolute here (against the current
        directory), and with it every path of the checkpoint folder that is
        handed to a worker.
    identity : dict
        ``config`` (the configuration as JSON-ready dict, without ``execution``;
        its ``seed`` as the user gave it), ``seed`` (resolved), ``realizations``,
        ``slidernet_version``, ``slidernet_code`` (the digest of slidernet's
        sources) and ``inputs`` (input file field -> SHA-256).
    resume : bool
        Continue the run found there. Without it, a folder that holds an
        interrupted run is refused rather than overwritten.
    overwrite : bool
        Start again: what the folder holds of an earlier run (finished or
        not) is replaced.

    Notes
    -----
    :meth:`open` takes the output directory's lock (:class:`FolderLock`,
    ``out_dir/.slidernet.lock``: the one lock of the folder, whatever works
    in it) and :meth:`close` lets it go and removes its file: call ``close``
    however the run ends.
    """

    def __init__(self, out_dir: str | Path, identity: dict[str, Any], resume: bool,
                 overwrite: bool = False) -> None:
        self.dir = Path(out_dir).absolute() / "checkpoint"
        self.identity = dict(identity)
        self.resume = resume
        self.overwrite = overwrite
        self._buffer: dict[int, Record] = {}
        self._created: list[Path] = []  # folders this run made, outermost first (undone by abandon)
        self._wrote_identity = False  # run.json written by this run (undone by abandon)
        self._lock = FolderLock(self.dir.parent, "run")

    @property
    def digest(self) -> str:
        """The run's digest (:func:`run_digest`): in every file of its checkpoint."""
        return run_digest(self.identity)

    # -- opening ---------------------------------------------------------
    def open(self) -> int:
        """Lock the folder, create or check it; return the seed to use (the stored one on resume).

        On resume every block and partial file is checked (its CRCs, its
        run's digest) before any work: a damaged one is removed, with a
        :class:`~slidernet.errors.CheckpointWarning` naming it, and its
        realizations are computed again (every realization is a function of
        the seed alone, so this gives the same bits).

        Raises
        ------
        OutputError
            If the output directory is not a folder or cannot be created
            (:func:`check_output_dir`), holds a sweep or a paper
            reproduction (:func:`check_own_folder`), or holds a finished
            ``result.nc`` and neither ``overwrite`` nor a run to resume is
            there.
        FolderInUseError
            If a command is still going in the folder (another process holds its lock).
        CheckpointError
            If it holds an interrupted run and ``resume`` is not set, or
            another run's checkpoint, or nothing to resume; if ``run.json``
            is damaged; on resume, if the configuration, an input file, the
            version or the code differ from the run's.
        """
        check_output_dir(self.dir.parent)
        self._make_dirs(self.dir.parent)
        try:
            self._lock.acquire()
        except BaseException:
            self.abandon()
            raise
        try:
            return self._open_locked()
        except BaseException:
            self.abandon()
            self.close()
            raise

    def _open_locked(self) -> int:
        """:meth:`open` under the lock: nothing is written in the folder before its lock is held."""
        out = self.dir.parent
        check_own_folder(out, "run")
        existed = self.dir.is_dir()
        self._make_dirs(self.dir)
        # Under the lock no other process writes here: a temporary file is what a killed one left.
        self.remove_temporaries()
        run_json = self.dir / "run.json"
        result = out / "result.nc"
        if self.overwrite and not self.resume:
            for path in self.dir.iterdir():  # asked for: whatever run was there is replaced
                shutil.rmtree(path) if path.is_dir() else path.unlink()
        if run_json.exists():
            stored = _read_identity(run_json)
            if not self.resume:
                done = len(self.done(strict=False))
                raise CheckpointError(
                    f"{str(out)!r} holds an interrupted run ({done} of {stored['realizations']} realizations "
                    f"done; no process is working on it). Continue it with --resume, or start again with "
                    f"--overwrite.")
            self._check_same_run(stored)
            self.identity["seed"] = stored["seed"]
            self._check_files()
            return int(stored["seed"])
        saved = self._saved_files()
        if saved:
            raise CheckpointError(
                f"{str(self.dir)!r} holds {len(saved)} checkpoint files (e.g. {saved[0].name!r}) but no run.json, "
                "the run's identity: they cannot be matched to a configuration and are never read. Start again "
                "with --overwrite, or use another output directory.")
        if self.resume:
            if existed:
                why = "its checkpoint folder holds no run (no run.json, no saved realization)"
            else:
                why = "it has no checkpoint folder" + (" (its run is finished: result.nc is there)"
                                                       if result.exists() else "")
            raise CheckpointError(f"Nothing to resume in {str(out)!r}: {why}.")
        if result.exists() and not self.overwrite:
            raise OutputError(
                f"{str(out)!r} holds a finished result ({str(result)!r}); it is not replaced silently. "
                "Use --overwrite to replace it, or another output directory."
            )
        self.identity["digest"] = self.digest
        try:
            with atomic_output(run_json) as tmp:
                tmp.write_text(json.dumps(self.identity, indent=1, sort_keys=True))
        except OSError as exc:
            raise OutputError(f"Cannot write in the output directory {str(out)!r}: {reason(exc)}.") from None
        self._wrote_identity = True
        return int(self.identity["seed"])

    def _check_same_run(self, stored: dict[str, Any]) -> None:
        """Refuse to resume a run of another configuration, other input files, another version or other code."""
        diff = _flat_diff(stored["config"], self.identity["config"])
        if stored["realizations"] != self.identity["realizations"]:
            diff.append(f"realizations ({stored['realizations']} in the checkpoint, "
                        f"{self.identity['realizations']} now)")
        if diff:
            raise CheckpointError(
                "Cannot resume: the configuration differs from the checkpointed run's in "
                + "; ".join(diff) + ". Resume with the same configuration, or use another output directory."
            )
        code = changed_code(stored, self.identity)
        if code:
            raise CheckpointError(f"Cannot resume: the checkpoint {code}; results would not be bit-identical. "
                                  "Resume it with the slidernet that started it, or start again with --overwrite.")
        changed = changed_inputs(stored["inputs"], self.identity["inputs"])
        if changed:
            raise CheckpointError(
                f"Cannot resume: an input file changed since the run started: {changed}. The saved "
                "realizations were computed from the old contents; restore them, or start again with --overwrite.")

    def _check_files(self) -> None:
        """Check every block and partial file before any work (see :meth:`open`)."""
        digest = self.identity["digest"] = self.digest
        R = self.identity["realizations"]
        for path in self._blocks():
            try:
                check_arrays(path)
                arrays = read_arrays(path, ["run", "realization"])
                idx = arrays["realization"]
                if idx.ndim != 1 or idx.dtype.kind not in "iu" or ((idx < 0) | (idx >= R)).any():
                    raise CheckpointError(f"The checkpoint {str(path)!r} lists realizations outside 0 to {R - 1}.")
            except CheckpointError as exc:
                _recompute(path, exc, "its realizations are computed again")
                continue
            if bytes(arrays["run"]).decode("ascii", "replace") != digest:
                raise _foreign(path)
        for path in self._partials():
            try:
                meta = checkpoint_info(path).get("meta")
            except CheckpointError as exc:
                _recompute(path, exc, "its realization starts again from its beginning")
                continue
            if not isinstance(meta, dict) or meta.get("run") != digest:
                raise _foreign(path)

    def _make_dirs(self, folder: Path) -> None:
        """Create ``folder`` and its missing parents, remembering which were made here."""
        missing = [p for p in (folder, *folder.parents) if not p.exists()][::-1]
        for path in missing:
            try:
                path.mkdir()
            except FileExistsError:
                what = not_a_folder(path)
                if what is not None:  # made by another process meanwhile, as something else
                    self.abandon()
                    raise OutputError(f"The output path {str(path)!r} {what}; name a folder.") from None
            except OSError as exc:
                self.abandon()
                raise OutputError(
                    f"Cannot create the output directory {str(self.dir.parent)!r}: {reason(exc)}.") from None
            else:
                self._created.append(path)

    def abandon(self) -> None:
        """Undo :meth:`open` after a failure, if nothing worth keeping was saved.

        A run that failed before any realization was saved (a block or a
        partial realization on disk) leaves the output directory as it found
        it: the folders it created are removed. Saved work is kept, so that
        a fixed run can resume it. Flush the finished realizations first.
        """
        if self._saved_files():
            return
        if self._wrote_identity:
            (self.dir / "run.json").unlink(missing_ok=True)
            self._wrote_identity = False
        for path in reversed(self._created):
            shutil.rmtree(path, ignore_errors=True)
        self._created.clear()

    def remove_temporaries(self) -> None:
        """Remove the temporary files of writes that were killed, in the output and checkpoint folders.

        Call this only while the lock is held and no worker of this run writes.
        """
        remove_temporaries(self.dir.parent)
        remove_temporaries(self.dir)

    def close(self) -> None:
        """Let the folder's lock go and remove its file (however the run ended; :meth:`open` took it)."""
        self._lock.release()

    def _saved_files(self) -> list[Path]:
        return self._blocks() + self._partials()

    def _partials(self) -> list[Path]:
        return sorted(p for p in self.dir.iterdir() if _PARTIAL.fullmatch(p.name)) if self.dir.is_dir() else []

    def partials(self) -> int:
        """The number of realizations saved in progress."""
        return len(self._partials())

    # -- finished realizations -------------------------------------------
    def _blocks(self) -> list[Path]:
        if not self.dir.is_dir():
            return []
        return sorted((p for p in self.dir.iterdir() if _BLOCK.fullmatch(p.name)), key=_block_order)

    def done(self, strict: bool = True) -> dict[int, tuple[Path, int]]:
        """Finished realization -> (its block, its row in the block).

        ``strict=False`` skips a block that cannot be read instead of raising.
        """
        out: dict[int, tuple[Path, int]] = {}
        for path in self._blocks():
            try:
                idx = read_arrays(path, ["realization"])["realization"]
            except CheckpointError:
                if strict:
                    raise
                continue
            for row, r in enumerate(idx.tolist()):
                out[r] = (path, row)
        return out

    def add(self, r: int, record: Record) -> None:
        """Hold a finished realization until the next :meth:`flush`."""
        self._buffer[r] = record

    @property
    def held(self) -> int:
        """Finished realizations held in memory, not yet written."""
        return len(self._buffer)

    def flush(self) -> None:
        """Write the held realizations as one block, then drop their partial files.

        Raises
        ------
        OutputError
            If the block cannot be written (naming it); the realizations
            stay held.
        """
        if not self._buffer:
            return
        rs = sorted(self._buffer)
        arrays = _pack([self._buffer[r] for r in rs])
        arrays["realization"] = np.array(rs, np.int64)
        arrays["run"] = np.frombuffer(self.identity["digest"].encode("ascii"), np.uint8)
        path = self.dir / f"block-{rs[0]:09d}-{len(rs)}.npz"
        k = 0
        while path.exists():  # the same first realization can recur after a resume
            k += 1
            path = self.dir / f"block-{rs[0]:09d}-{len(rs)}-{k}.npz"
        write_arrays(path, arrays)
        for r in rs:
            self.partial(r).unlink(missing_ok=True)
        self._buffer.clear()

    def partial(self, r: int) -> Path:
        """Where realization ``r`` in progress is saved."""
        return self.dir / f"partial-{r:09d}.npz"

    def records(self, R: int) -> Iterator[Record]:
        """Every realization's records, in realization order, reading one block at a time (or two)."""
        where = self.done()
        missing = [r for r in range(R) if r not in where]
        if missing:
            raise CheckpointError(f"{len(missing)} realizations are missing from {str(self.dir)!r}, "
                                  f"e.g. {missing[:5]}")
        cache: dict[Path, list[Record]] = {}
        for r in range(R):
            path, row = where[r]
            if path not in cache:
                if len(cache) >= 2:
                    cache.pop(next(iter(cache)))
                arrays = read_arrays(path)
                arrays.pop("run", None)
                cache[path] = _unpack(arrays)
            yield cache[path][row]

    def remove(self) -> None:
        """Delete the folder (the run's result is safely written), lock file included.

        The folder is first renamed to a temporary name, in one step: from
        then on no process sees a run in ``out_dir`` but the finished one,
        and a kill while the files are removed leaves a temporary folder,
        removed by the next run there (:func:`~slidernet.io.netcdf.remove_temporaries`).
        """
        gone = self.dir.with_name(f".{self.dir.name}.{secrets.token_hex(4)}.tmp")
        try:
            os.rename(self.dir, gone)
        except FileNotFoundError:
            return
        # The folder now holds the finished run alone: its lock file goes at once, before the files are
        # removed (which can take seconds), so that a kill from here on leaves no lock file beside
        # result.nc; the lock itself is held until close(), and whoever locks the folder meanwhile finds
        # the finished run.
        self._lock.path.unlink(missing_ok=True)
        shutil.rmtree(gone, ignore_errors=True)


def read_identity_file(path: Path, types: Mapping[str, type], what: str) -> dict[str, Any]:
    """A JSON file that identifies a run or a sweep, checked: a JSON object with these keys of these types.

    Parameters
    ----------
    path : Path
    types : mapping of str to type
        Each key the file must hold, and the type of its value (a bool is
        never an int here).
    what : str
        What the file identifies, for the message ("a run", "a sweep").

    Raises
    ------
    CheckpointError
        If the file cannot be read, is not JSON, or lacks a key or has one
        of another type (``{}``, ``[]``, a damaged file), in one line naming
        it.
    """
    try:
        stored = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise CheckpointError(f"The file {str(path)!r} cannot be read ({exc}); start again with --overwrite.") \
            from None
    if not isinstance(stored, dict):
        wrong = f"a JSON {type(stored).__name__}, not an object"
    else:
        bad = [key for key, kind in types.items()
               if not isinstance(stored.get(key), kind) or isinstance(stored.get(key), bool)]
        wrong = f"no valid {', '.join(bad)}" if bad else ""
    if wrong:
        raise CheckpointError(f"The file {str(path)!r} does not identify {what} ({wrong}): it is damaged, or was "
                              "written by another program or an earlier slidernet. Start again with --overwrite.")
    return stored


def _read_identity(path: Path) -> dict[str, Any]:
    """A run.json, checked: its keys and their types, and its digest (a flipped bit changes it)."""
    types = {"config": dict, "seed": int, "realizations": int, "slidernet_version": str, "slidernet_code": str,
             "inputs": dict, "digest": str}
    stored = read_identity_file(path, types, "a run")
    if run_digest(stored) != stored["digest"]:
        raise CheckpointError(f"The checkpoint {str(path)!r} is damaged: its contents do not match their digest. "
                              "Start again with --overwrite.")
    return stored


def changed_inputs(then: Mapping[str, Any], now: Mapping[str, Any]) -> str:
    """The input files whose contents differ between two identities' ``inputs``, in words ('' if none).

    >>> changed_inputs({"network.path": {"path": "a.txt", "sha256": "1f2e"}},
    ...                {"network.path": {"path": "a.txt", "sha256": "9c3b"}})
    "'a.txt' (network.path: SHA-256 1f2e then, 9c3b now)"
    """
    def sha(entry: Any) -> str:
        return str(entry.get("sha256"))[:12] if isinstance(entry, Mapping) else "none"

    differ = [what for what in sorted(set(then) | set(now)) if then.get(what) != now.get(what)]
    return "; ".join(f"{(now.get(w) or then.get(w) or {}).get('path')!r} ({w}: SHA-256 {sha(then.get(w))} then, "
                     f"{sha(now.get(w))} now)" for w in differ)


def changed_code(then: Mapping[str, Any], now: Mapping[str, Any]) -> str:
    """How the slidernet that wrote ``then`` differs from ``now``'s, in words ('' if it does not).

    Both hold ``slidernet_version`` and ``slidernet_code`` (the digest of
    the package's sources, :func:`slidernet._version.code_digest`): a run's
    identity, or a result's attributes.

    >>> print(changed_code({"slidernet_version": "0.1.0", "slidernet_code": "9c3b71d0a2e4f5"},
    ...                    {"slidernet_version": "0.1.0", "slidernet_code": "1f2e88a04bc6d7"}))
    ... # doctest: +NORMALIZE_WHITESPACE
    was computed by other code than this (slidernet 0.1.0 both times, but the digest of its sources is
    9c3b71d0a2e4 there and 1f2e88a04bc6 here: an edited or another install)
    """
    if then.get("slidernet_version") != now["slidernet_version"]:
        return f"was written by slidernet {then.get('slidernet_version')}, this is {now['slidernet_version']}"
    if then.get("slidernet_code") != now["slidernet_code"]:
        return (f"was computed by other code than this (slidernet {now['slidernet_version']} both times, but the "
                f"digest of its sources is {str(then.get('slidernet_code'))[:12]} there and "
                f"{now['slidernet_code'][:12]} here: an edited or another install)")
    return ""


def _foreign(path: Path) -> CheckpointError:
    return CheckpointError(
        f"The checkpoint {str(path)!r} belongs to another run (another configuration, input file or seed) than "
        f"its folder's run.json: it is never read. Remove it, or start again with --overwrite.")


def _recompute(path: Path, exc: CheckpointError, what: str) -> None:
    """Remove a damaged checkpoint file, saying so: what it held is computed again, to the same bits."""
    warnings.warn(f"{exc} It is removed; {what}.", CheckpointWarning, stacklevel=4)
    path.unlink(missing_ok=True)


def check_output_dir(out: Path) -> None:
    """Refuse an output directory that is not a folder, cannot become one, or has a name netCDF cannot take.

    The one check every output folder shares, made before any work: ``out``
    or one of its parents is a file, a symbolic link to nothing, to a file
    or in a loop (each named for what it is); its name is not UTF-8 text
    (the netCDF library names its files in UTF-8: the run would fail when
    it writes its result, at its end).

    Raises
    ------
    OutputError
        In one line, naming the path and what it is.
    """
    for path in (out, *out.parents):
        what = not_a_folder(path)
        if what is not None and path == out:
            raise OutputError(f"The output directory {str(out)!r} {what}; name a folder.")
        if what is not None:
            raise OutputError(f"The output directory {str(out)!r} cannot be made: {str(path)!r} {what}.")
        if path.is_dir():
            break
    text = not_utf8(out.absolute())
    if text is not None:
        raise OutputError(f"The output directory {str(out)!r} {text}, and netCDF files are named in UTF-8. "
                          "Rename it, or name another folder.")


# -- records <-> flat arrays ---------------------------------------------------
def _pack(records: list[Record]) -> dict[str, np.ndarray]:
    """Stack records into named arrays; dict-valued entries (ragged) are concatenated with offsets."""
    out: dict[str, np.ndarray] = {}
    for key, value in records[0].items():
        if isinstance(value, dict):
            sizes = [len(next(iter(rec[key].values()))) for rec in records]
            out[f"{key}/offsets"] = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
            for sub in value:
                out[f"{key}/{sub}"] = np.concatenate([np.asarray(rec[key][sub]) for rec in records])
        else:
            out[key] = np.stack([np.asarray(rec[key]) for rec in records])
    return out


def _unpack(arrays: dict[str, np.ndarray]) -> list[Record]:
    """Inverse of :func:`_pack`."""
    B = arrays["realization"].size
    records: list[Record] = [{} for _ in range(B)]
    ragged = {k.split("/")[0] for k in arrays if "/" in k}
    for key, value in arrays.items():
        if key == "realization" or "/" in key:
            continue
        for b in range(B):
            item = value[b]
            records[b][key] = item.item() if item.ndim == 0 and value.dtype == bool else item
    for key in ragged:
        off = arrays[f"{key}/offsets"]
        subs = [k.split("/", 1)[1] for k in arrays if k.startswith(f"{key}/") and not k.endswith("/offsets")]
        for b in range(B):
            records[b][key] = {s: arrays[f"{key}/{s}"][off[b]:off[b + 1]] for s in subs}
    return records
