"""Checkpoints of one realization in the middle of its run, resumed to the same bits.

Between two calls of :meth:`Realization.advance` a realization is at a clean
point: its whole state is in arrays, in the states of its random streams and
in the surplus of its threshold streams (the accepted draws a
:class:`~slidernet.plugins.distributions.TruncatedStream` has drawn but not yet
handed out). :func:`save_realization` writes that state to one ``.npz`` file
(numpy's zip of ``.npy`` arrays; nothing is pickled) and
:func:`load_realization` rebuilds the realization from its scene and seed and
overwrites its state from the file. Advancing the loaded realization gives
the bits an uninterrupted run gives.

File layout (keys of the ``.npz``; every array numeric):

``header``
    uint8, the UTF-8 JSON text of: ``format`` and ``version`` of the layout,
    ``meta`` (the caller's, e.g. config hash, realization index, version),
    ``scene`` (a fingerprint of the scene: kernel, sizes, batch, ... and
    digests of K, g, the loads and the recorded times), ``thetas`` (a digest
    of theta(t_q)), ``rngs`` (the ``bit_generator.state`` of the driver,
    thresholds, tilt and tilt_uniforms streams), ``step`` and ``n`` (for information),
    ``tilted`` and ``numpy``.
``state/<field>``
    The realization's scalars, one 0-d array per field of
    :data:`slidernet.kernels.STATE` (``q``, ``n_slips``, ``theta``, ...), version 4 on.
``mu``
    The thresholds mu_s of the nodes.
``buffers/<name>``
    The draws waiting for the kernel (:class:`slidernet.kernels.Draws`):
    ``mu``, ``tilt_mu``, ``tilt_u`` (version 4 on).
``surplus/<name>``
    float64, the surplus of the ``thresholds`` and ``tilt`` threshold
    streams (``Realization.draws``), in order (version 2 on).
``out/<name>``
    The records written so far (every key of ``Realization.out``).
``backend/<name>``
    The kernel's own state, as its backend writes and reads it
    (:mod:`slidernet.solver.backends`, version 3 on): nothing for the pair
    kernel; for the network kernels the per-node state (``nodes/a``,
    ``nodes/u``, ``nodes/node_slips``, ``nodes/avalanche_count``), the heaps
    (``heaps/node``, ``heaps/key``, ``heaps/slot``, ``heaps/size``, the driving trees
    ``heaps/tkey``, ``heaps/twin``, ``heaps/toff``, ``heaps/leaf`` from version 5 on), the
    catalogue rows in the kernel's buffer (``events/buffer_ids``,
    ``events/buffer_values``: its first ``ev_pos`` rows;
    ``events/buffer_rows``, its size), the chunks already handed to Python
    (``events/chunks_ids``, ``events/chunks_values``, ``events/chunk_rows``)
    and ``events/complete``.
"""

from __future__ import annotations

import hashlib
import json
import os
import zipfile
from pathlib import Path
from typing import Any

import numpy as np

from slidernet import kernels
from slidernet.errors import CheckpointError
from slidernet.io import atomic_output
from slidernet.solver import Realization, Scene

FORMAT = "slidernet-checkpoint"
# 2: the threshold streams' surplus (surplus/<name>) and the tilt_uniforms stream.
# 3: the kernel's own state under backend/<name>, written and read by its backend.
# 4: named state (state/<field>, buffers/<name>, the backend's nodes/ and heaps/).
# 5: the driving events from tournament trees (heaps/tkey, twin, toff, leaf; one heap row, not three),
#    and the scene's fingerprint digests K as the 2D kernels hold it (block ids and their table).
# 6: sliding away (state/moving_id, n_moving, slid_away, slid_away_at; backend nodes/moving).
VERSION = 6

# Attributes written to the file (by name, or with special handling below).
_SAVED = {"state", "mu", "buffers", "out", "rngs", "draws", "backend", "_tilted"}
# Attributes the constructor rebuilds, and why that is exact.
_REBUILT = {
    "scene": "passed to load_realization",
    "series": "the kernels' view of out: the same arrays, restored in place",
    "thetas": "redrawn by the constructor from the driver stream; its digest is checked",
    "_mu_batches": "a generator reading draws['thresholds'], whose surplus and Generator are restored in place",
    "_tilt_work": "scratch arrays of the network tilt test, reset by every test",
}


def save_realization(real: Realization, path: str | Path, meta: dict[str, Any]) -> Path:
    """Write the state of ``real`` to one ``.npz`` file, atomically.

    The file is written next to ``path`` under a temporary name, flushed to
    disk, then renamed over ``path``: an interrupted save leaves the previous
    checkpoint as it was. Call it between two :meth:`Realization.advance`
    calls.

    Parameters
    ----------
    real : Realization
        The realization, at a step boundary.
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
        If ``meta`` is not JSON-serializable, or ``real`` holds an attribute
        this module does not know how to save (a new piece of state).

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
    unknown = sorted(set(vars(real)) - _SAVED - set(_REBUILT))
    if unknown:
        raise CheckpointError(
            f"The realization holds {unknown} that slidernet.io.checkpoint neither saves nor rebuilds; "
            "add each to checkpoint._SAVED (and save it) or to checkpoint._REBUILT."
        )
    header: dict[str, Any] = {
        "format": FORMAT,
        "version": VERSION,
        "meta": meta,
        "scene": _fingerprint(real.scene),
        "thetas": _digest(real.thetas),
        "rngs": {name: rng.bit_generator.state for name, rng in real.rngs.items()},
        "step": real.step,
        "n": real.n,
        "tilted": int(real._tilted),
        "numpy": np.__version__,
    }
    try:
        text = json.dumps(header, sort_keys=True, allow_nan=False)
    except (TypeError, ValueError) as exc:
        raise CheckpointError(f"The checkpoint meta must be JSON-serializable: {exc}.") from None
    arrays = {"header": np.frombuffer(text.encode("utf-8"), dtype=np.uint8)}
    for name in kernels.STATE.names:
        arrays[f"state/{name}"] = real.state[name][0]
    arrays["mu"] = real.mu
    for name, values in real.buffers._asdict().items():
        arrays[f"buffers/{name}"] = values
    for name, values in real.backend.to_arrays(real).items():
        arrays[f"backend/{name}"] = np.asarray(values)
    for name, stream in real.draws.items():
        arrays[f"surplus/{name}"] = stream.surplus
    for name, values in real.out.items():
        arrays[f"out/{name}"] = values
    odd = sorted(key for key, a in arrays.items() if a.dtype.kind not in "biuf")
    if odd:  # np.savez would pickle them, and load_realization refuses pickles
        raise CheckpointError(f"The checkpoint arrays {odd} are not numeric.")
    path = Path(path)
    with atomic_output(path) as tmp:
        with open(tmp, "wb") as fh:  # a file object: np.savez would append ".npz" to a name
            np.savez(fh, **arrays)
            fh.flush()
            # The rename is atomic, but only data on disk survives a machine failure.
            os.fsync(fh.fileno())
    _fsync_folder(path.parent)
    return path


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
    _check_same(path, "scene", header.get("scene"), _fingerprint(scene))
    real = Realization(scene, seed_seq)
    if header.get("thetas") != _digest(real.thetas):
        raise CheckpointError(
            f"The checkpoint {str(path)!r} was saved with other theta(t_q) for this seed: the driver (or its "
            "input file, or numpy) has changed, or this is another realization's seed."
        )
    try:
        _restore(real, header, arrays)
    except KeyError as exc:
        raise CheckpointError(f"The checkpoint {str(path)!r} is inconsistent: its header has no {exc}.") from None
    except (TypeError, ValueError) as exc:
        raise CheckpointError(f"The checkpoint {str(path)!r} is inconsistent: {exc}.") from None
    return real


def checkpoint_info(path: str | Path) -> dict[str, Any]:
    """The header of a checkpoint: its ``meta``, ``step``, ``n`` and the rest (see the module docstring).

    Reads and checks the whole file (a corrupt one raises :class:`CheckpointError`).
    """
    return _read(Path(path))[0]


def _read(path: Path) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    """The header and the arrays of a checkpoint file, every array read (so every CRC checked)."""
    with open(path, "rb") as fh:
        if fh.read(6) == b"\x93NUMPY":
            raise CheckpointError(f"The file {str(path)!r} is a single .npy array, not a slidernet checkpoint.")
    try:
        # numpy reads a member only up to the length its .npy header gives, and zipfile checks a
        # CRC only at the end of a member: a damaged header length would go unnoticed (found by
        # flipping bytes). testzip reads every member to its end.
        with zipfile.ZipFile(path) as zf:
            damaged = zf.testzip()
        if damaged is not None:
            raise zipfile.BadZipFile(f"bad CRC-32 for {damaged!r}")
        with np.load(path, allow_pickle=False) as npz:
            arrays = {name: npz[name] for name in npz.files}
    except (PermissionError, IsADirectoryError):
        raise
    except Exception as exc:
        # Damage surfaces as many exception types: flipping random bytes of a checkpoint gave
        # BadZipFile, EOFError, NotImplementedError (zipfile), ValueError and TokenError (the .npy header).
        raise _unreadable(path, exc) from None
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


def _check_same(path: Path, what: str, saved: Any, here: dict[str, Any]) -> None:
    saved = saved if isinstance(saved, dict) else {}
    for key, value in here.items():
        if saved.get(key) != value:
            raise CheckpointError(
                f"The checkpoint {str(path)!r} was written for another {what}: its {key!r} is "
                f"{saved.get(key)!r} there and {value!r} here."
            )


def _fingerprint(scene: Scene) -> dict[str, Any]:
    """What a continuation depends on in the scene, beyond the seed (JSON values)."""
    net, ops = scene.network, scene.operators
    # The kernel's own form of K: 1D CSR values, 2D block ids into the table of blocks.
    K_arrays = (ops.indptr, ops.indices, ops.K_data) if isinstance(ops, kernels.Chain) else \
        (ops.indptr, ops.indices, ops.K_id, ops.K_table)
    return {
        "kernel": scene.kernel,
        "n_nodes": int(net.n_nodes),
        "dim": int(net.dim),
        "Ntilde": float(net.Ntilde),
        "mu_d": float(scene.mu_d),
        "steps": int(scene.steps),
        "out_steps": _digest(scene.out_steps),
        "tilt_at": scene.tilt_at,
        "catalogue": bool(scene.catalogue),
        "max_events": int(scene.max_events),
        "batch": int(scene.batch),
        "recompute_every": int(scene.recompute_every),
        "max_avalanche": int(scene.max_avalanche),
        "slip_mode": int(scene.slip_mode),
        "distribution": scene.distribution_name,
        "driver": scene.driver_name,
        "K": _digest(*K_arrays),
        "loads": _digest(scene.operators.g, net.normal_load, net.f_ext),
    }


def _digest(*arrays: np.ndarray) -> str:
    """A hash of the arrays' dtypes, shapes and bytes (hex)."""
    # sha256: twice blake2b's speed here (1.2 against 0.5 GB/s), and K of a 1e5-node lattice is 30 MB.
    h = hashlib.sha256()
    for a in arrays:
        a = np.ascontiguousarray(a)
        h.update(f"{a.dtype.str}{a.shape}".encode())
        h.update(a.data)
    return h.hexdigest()[:32]


def _take(arrays: dict[str, np.ndarray], key: str, like: np.ndarray | None = None, *,
          dtype: Any = None, ndim: int | None = None) -> np.ndarray:
    """``arrays[key]``, checked against ``like``'s dtype and shape (or ``dtype`` and ``ndim``)."""
    if key not in arrays:
        raise ValueError(f"it has no array {key!r}")
    a = arrays[key]
    dtype = like.dtype if like is not None else np.dtype(dtype)
    if a.dtype != dtype or (like is not None and a.shape != like.shape) or (ndim is not None and a.ndim != ndim):
        want = like.shape if like is not None else f"{ndim} dimensions"
        raise ValueError(f"array {key!r} is {a.dtype}{a.shape}, expected {dtype} {want}")
    return a


def _restore(real: Realization, header: dict[str, Any], arrays: dict[str, np.ndarray]) -> None:
    """Overwrite the state of a freshly constructed ``real`` (same scene and seed) from a checkpoint."""
    # In place: the kernels get arrays of exactly the layout and dtype they were compiled for.
    for name in kernels.STATE.names:
        real.state[name] = _take(arrays, f"state/{name}", dtype=kernels.STATE[name], ndim=0)
    real.mu[...] = _take(arrays, "mu", real.mu)
    real.buffers = kernels.Draws(*(np.array(_take(arrays, f"buffers/{name}", dtype=np.float64, ndim=1), order="C")
                                   for name in kernels.Draws._fields))
    saved_out = {key.removeprefix("out/") for key in arrays if key.startswith("out/")}
    if saved_out != set(real.out):
        raise ValueError(f"its records are {sorted(saved_out)}, this scene's are {sorted(real.out)}")
    for name, target in real.out.items():
        target[...] = _take(arrays, f"out/{name}", target)
    own = {key.removeprefix("backend/"): a for key, a in arrays.items() if key.startswith("backend/")}
    real.backend.from_arrays(real, own, _take)
    real._tilted = int(header["tilted"])
    if set(header["rngs"]) != set(real.rngs):
        raise ValueError(f"its streams are {sorted(header['rngs'])}, a realization's are {sorted(real.rngs)}")
    for name, rng in real.rngs.items():
        # In place: the threshold streams hold these very Generators.
        rng.bit_generator.state = header["rngs"][name]
    saved_streams = {key.removeprefix("surplus/") for key in arrays if key.startswith("surplus/")}
    if saved_streams != set(real.draws):
        raise ValueError(f"its threshold streams are {sorted(saved_streams)}, a realization's are "
                         f"{sorted(real.draws)}")
    for name, stream in real.draws.items():
        stream.restore(_take(arrays, f"surplus/{name}", dtype=np.float64, ndim=1))


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
