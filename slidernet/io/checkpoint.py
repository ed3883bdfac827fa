"""Checkpoints of one realization in the middle of its run, resumed to the same bits.

A checkpoint is one file holding a :class:`~slidernet.solver.snapshot.Snapshot`
of a realization (:meth:`Realization.snapshot
<slidernet.solver.Realization.snapshot>`: its whole state, random streams
included, as JSON values and named numeric arrays). :func:`save_realization`
writes it to one ``.npz`` file (numpy's zip of ``.npy`` arrays; nothing is
pickled), atomically; :func:`load_realization` builds the realization afresh
from its scene and seed and restores the snapshot into it
(:meth:`Realization.restore <slidernet.solver.Realization.restore>`).
Advancing the loaded realization gives the bits an uninterrupted run gives.
This module knows the file, not the kernels: what a snapshot holds is the
realization's business.

File layout (keys of the ``.npz``; every array numeric):

``header``
    uint8, the UTF-8 JSON text of: ``format`` and ``version`` of the layout,
    ``meta`` (the caller's, e.g. config hash, realization index, version),
    ``numpy``, and the snapshot's header (``scene``, ``thetas``, ``rngs``,
    ``tilted``, ``step``, ``n``: see :mod:`slidernet.solver.snapshot`).
every other key
    The snapshot's arrays, by their names (``state/<field>``, ``mu``,
    ``buffers/<name>``, ``surplus/<name>``, ``out/<name>``, ``backend/<name>``).

A file of another ``version`` is refused with a message naming both.
"""

from __future__ import annotations

import json
import os
import zipfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from slidernet.errors import CheckpointError, OutputError, SnapshotError
from slidernet.io.netcdf import atomic_output, reason
from slidernet.solver import Realization, Scene
from slidernet.solver.snapshot import Snapshot

FORMAT = "slidernet-checkpoint"
# 2: the threshold streams' surplus (surplus/<name>) and the tilt_uniforms stream.
# 3: the kernel's own state under backend/<name>, written and read by its backend.
# 4: named state (state/<field>, buffers/<name>, the backend's nodes/ and heaps/).
# 5: the driving events from tournament trees (heaps/tkey, twin, toff, leaf; one heap row, not three),
#    and the scene's fingerprint digests K as the 2D kernels hold it (block ids and their table).
# 6: sliding away (state/moving_id, n_moving, slid_away, slid_away_at; backend nodes/moving).
VERSION = 6


def save_realization(real: Realization, path: str | Path, meta: dict[str, Any]) -> Path:
    """Write the state of ``real`` to one ``.npz`` file, atomically.

    The file is written next to ``path`` under a temporary name, flushed to
    disk, then renamed over ``path``: an interrupted save leaves the previous
    checkpoint as it was. Call it between two :meth:`Realization.advance`
    calls.

    Parameters
    ----------
    real : Realization
        The realization, between two calls of its ``advance``.
    path : str or Path
        The checkpoint file (``.npz`` by convention; no suffix is added).
    meta : dict
        JSON-serializable values that identify the run (config hash,
        realization index, slidernet version, ...), checked by
        :func:`load_realization`.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    CheckpointError
        If ``meta`` is not JSON-serializable.
    OutputError
        If the file cannot be written (a full disk, the file size limit),
        naming it.
    RuntimeError
        If ``real`` holds a piece of state that its snapshot does not know.

    Examples
    --------
    >>> import tempfile
    >>> from slidernet.config import load_config
    >>> cfg = load_config({"steps": 30, "network": {"Ntilde": 1e-7}, "driver": {"name": "gaussian_steps",
    ...     "sigma_theta": 1e-6}, "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6,
    ...     "std": 0.01}}})
    >>> scene, ss = Scene.from_config(cfg), np.random.SeedSequence(7)
    >>> real = Realization(scene, ss).advance(10)
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = save_realization(real, Path(folder) / "r0.npz", {"realization": 0})
    ...     resumed = load_realization(scene, ss, path, {"realization": 0})
    >>> resumed.step
    10
    >>> resumed.advance().result()["n"].tolist() == real.advance().result()["n"].tolist()
    True
    """
    snap = real.snapshot()
    header: dict[str, Any] = {"format": FORMAT, "version": VERSION, "meta": meta, "numpy": np.__version__,
                              **snap.header}
    try:
        text = json.dumps(header, sort_keys=True, allow_nan=False)
    except (TypeError, ValueError) as exc:
        raise CheckpointError(f"The checkpoint meta must be JSON-serializable: {exc}.") from None
    arrays = {"header": np.frombuffer(text.encode("utf-8"), dtype=np.uint8)}
    arrays.update(snap.arrays)
    return write_arrays(path, arrays)


def load_realization(scene: Scene, seed_seq: np.random.SeedSequence, path: str | Path,
                     expect_meta: dict[str, Any] | None = None) -> Realization:
    """Rebuild a realization from its scene, its seed and a checkpoint file.

    The realization is constructed as usual, then its state (arrays, records,
    event catalogue, random streams) is overwritten from the file, which is
    read with ``allow_pickle=False``.

    Parameters
    ----------
    scene : Scene
        The scene of the run (built afresh from the same config).
    seed_seq : numpy.random.SeedSequence
        The realization's seed, as given to the saved realization.
    path : str or Path
        A file written by :func:`save_realization`.
    expect_meta : dict, optional
        Every key must be in the file's meta with an equal value (after a
        JSON round trip); keys the file has beyond these are not checked.

    Returns
    -------
    Realization
        At the saved step; :meth:`Realization.advance` goes on from there.

    Raises
    ------
    CheckpointError
        If the file is truncated, corrupt or not a checkpoint, if its meta
        differs from ``expect_meta``, or if it was written for another scene
        or another theta(t_q). ``FileNotFoundError`` if there is no file.
    """
    path = Path(path)
    header, arrays = _read(path)
    if expect_meta is not None:
        _check_meta(path, header.get("meta"), expect_meta)
    real = Realization(scene, seed_seq)
    try:
        real.restore(Snapshot(header, arrays))
    except SnapshotError as exc:
        raise CheckpointError(f"The checkpoint {str(path)!r} {exc}.") from None
    except (KeyError, TypeError, ValueError) as exc:  # e.g. a Generator state numpy refuses
        raise CheckpointError(f"The checkpoint {str(path)!r} is inconsistent: {exc!r}.") from None
    return real


def checkpoint_info(path: str | Path) -> dict[str, Any]:
    """The header of a checkpoint: its ``meta``, ``step``, ``n`` and the rest (see the module docstring).

    Reads and checks the whole file (a corrupt one raises :class:`CheckpointError`).
    """
    return _read(Path(path))[0]


def write_arrays(path: str | Path, arrays: dict[str, np.ndarray]) -> Path:
    """Write named numeric arrays to one ``.npz`` file, atomically and durably (the file of every checkpoint).

    The file is written under a temporary name, flushed to disk, then
    renamed over ``path``: an interrupted write leaves the previous file as
    it was, and a machine failure after the return loses nothing.

    Raises
    ------
    CheckpointError
        If an array is not numeric (``np.savez`` would pickle it, and
        :func:`read_arrays` refuses pickles).
    OutputError
        If the file cannot be written (a full disk, the file size limit:
        ``ulimit -f``), naming it and the OS's reason.
    """
    odd = sorted(key for key, a in arrays.items() if a.dtype.kind not in "biuf")
    if odd:
        raise CheckpointError(f"The checkpoint arrays {odd} are not numeric.")
    path = Path(path)
    try:
        with atomic_output(path) as tmp:
            with open(tmp, "wb") as fh:  # a file object: np.savez would append ".npz" to a name
                np.savez(fh, **arrays)
                fh.flush()
                # The rename is atomic, but only data on disk survives a machine failure.
                os.fsync(fh.fileno())
    except OSError as exc:
        raise OutputError(f"Cannot write the checkpoint file {str(path)!r}: {reason(exc)}.") from None
    _fsync_folder(path.parent)
    return path


def check_arrays(path: str | Path) -> None:
    """Check every CRC-32 of an ``.npz`` file by reading each of its members to the end, in constant memory.

    numpy reads a member only up to the length its ``.npy`` header gives, and
    zipfile checks a CRC only at the end of a member: a damaged header
    length would go unnoticed by ``np.load`` alone (found by flipping bytes).

    Raises
    ------
    CheckpointError
        If the file is truncated, corrupt, or not a zip file, naming it.
    """
    path = Path(path)
    try:
        with open(path, "rb") as fh:
            if fh.read(6) == b"\x93NUMPY":
                raise CheckpointError(
                    f"The file {str(path)!r} is a single .npy array, not a slidernet checkpoint.")
        with zipfile.ZipFile(path) as zf:
            damaged = zf.testzip()
        if damaged is not None:
            raise zipfile.BadZipFile(f"bad CRC-32 for {damaged!r}")
    except (CheckpointError, PermissionError, IsADirectoryError, FileNotFoundError):
        raise
    except Exception as exc:
        # Damage surfaces as many exception types: flipping random bytes of a checkpoint gave
        # BadZipFile, EOFError, NotImplementedError (zipfile), ValueError and TokenError (the .npy header).
        raise _unreadable(path, exc) from None


def read_arrays(path: str | Path, names: Sequence[str] | None = None) -> dict[str, np.ndarray]:
    """The arrays of an ``.npz`` file written by :func:`write_arrays`, read without pickle.

    Parameters
    ----------
    path : path
    names : sequence of str, optional
        Read only these members (each must be there); None: every member,
        after :func:`check_arrays` has checked the whole file.

    Raises
    ------
    CheckpointError
        If the file is truncated or corrupt, or lacks a member asked for.
    """
    path = Path(path)
    if names is None:
        check_arrays(path)
    try:
        with np.load(path, allow_pickle=False) as npz:
            return {name: npz[name] for name in (npz.files if names is None else names)}
    except (PermissionError, IsADirectoryError, FileNotFoundError):
        raise
    except Exception as exc:
        raise _unreadable(path, exc) from None


def _read(path: Path) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    """The header and the arrays of a checkpoint file, every array read (so every CRC checked)."""
    arrays = read_arrays(path)
    raw = arrays.pop("header", None)
    try:
        header = json.loads(raw.tobytes().decode("utf-8")) if raw is not None and raw.dtype == np.uint8 else None
    except (UnicodeDecodeError, ValueError):
        header = None
    if not isinstance(header, dict) or header.get("format") != FORMAT:
        raise CheckpointError(f"The file {str(path)!r} is not a slidernet checkpoint (no valid header).")
    if header.get("version") != VERSION:
        raise CheckpointError(
            f"The checkpoint {str(path)!r} has layout version {header.get('version')!r}; "
            f"this slidernet reads version {VERSION}. Finish that run with the slidernet that wrote it, "
            "or start it again (--overwrite)."
        )
    return header, arrays


def _unreadable(path: Path, exc: BaseException) -> CheckpointError:
    return CheckpointError(
        f"The checkpoint {str(path)!r} cannot be read: it is truncated or corrupt "
        f"({type(exc).__name__}: {exc})."
    )


def _check_meta(path: Path, saved: Any, expect: dict[str, Any]) -> None:
    # The round trip compares what JSON can store: a tuple expected matches the list saved.
    expect = json.loads(json.dumps(expect))
    saved = saved if isinstance(saved, dict) else {}
    for key, want in expect.items():
        if key not in saved:
            raise CheckpointError(f"The checkpoint {str(path)!r} has no meta entry {key!r} (expected {want!r}).")
        if saved[key] != want:
            raise CheckpointError(
                f"The checkpoint {str(path)!r} belongs to another run: its meta {key!r} is "
                f"{saved[key]!r}, expected {want!r}."
            )


def _fsync_folder(folder: Path) -> None:
    """Put the rename itself on disk (POSIX; a no-op where folders cannot be opened)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)
