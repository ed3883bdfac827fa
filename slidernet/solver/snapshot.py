"""A realization's whole state as plain data: :class:`Snapshot`, and the checks its restore shares.

:meth:`Realization.snapshot <slidernet.solver.Realization.snapshot>` gives a
:class:`Snapshot`: JSON values (``header``) and named numeric arrays
(``arrays``), nothing pickled. :meth:`Realization.restore
<slidernet.solver.Realization.restore>` puts it back into a realization
built afresh from the same scene and seed, which then goes on to the bits an
uninterrupted run gives. Whoever stores a snapshot (the checkpoint files of
:mod:`slidernet.io.checkpoint`) writes and reads these two parts and needs to
know nothing of kernels.

Keys of ``arrays``:

``state/<field>``
    The realization's scalars, one 0-d array per field of
    :data:`slidernet.kernels.STATE` (``q``, ``n_slips``, ``theta``, ...).
``mu``
    float64 (N,): the thresholds mu_s of the nodes.
``buffers/<name>``, ``surplus/<name>``
    The random side (:class:`~slidernet.solver.streams.Streams`): the
    draws waiting for the kernels (``mu``, ``tilt_mu``, ``tilt_u``,
    ``shs_mu``) and the surplus of the ``thresholds``, ``tilt`` and ``shs``
    threshold streams.
``out/<name>``
    The records written so far.
``backend/<name>``
    The kernel's own state, as its backend writes and reads it
    (:mod:`slidernet.solver.backends`): nothing for the pair kernel; for
    the network kernels ``nodes/...``, ``heaps/...`` and ``events/...``.

Keys of ``header``: ``scene`` (:func:`scene_fingerprint`), ``thetas`` (a
digest of theta(t_q)), ``rngs`` (each Generator's ``bit_generator.state``),
``tilted`` (recorded times whose network tilt test and slide-hold-slide pull are done), ``step`` and
``n`` (for information).
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from typing import Any

import numpy as np

from slidernet.errors import SnapshotError
from slidernet.solver.scene import Scene


@dataclass(frozen=True)
class Snapshot:
    """The whole state of a realization between two calls of ``advance``.

    Attributes
    ----------
    header : dict
        JSON values (see the module docstring).
    arrays : dict of str to numpy.ndarray
        Numeric arrays by name (see the module docstring).
    """

    header: dict[str, Any]
    arrays: dict[str, np.ndarray]


def digest(*arrays: np.ndarray) -> str:
    """A hash of the arrays' dtypes, shapes and bytes (32 hex digits).

    >>> digest(np.zeros(2)) == digest(np.zeros(2)), digest(np.zeros(2)) == digest(np.zeros(3))
    (True, False)
    """
    # sha256: twice blake2b's speed here (1.2 against 0.5 GB/s), and K of a 1e5-node lattice is 30 MB.
    h = hashlib.sha256()
    for a in arrays:
        a = np.ascontiguousarray(a)
        h.update(f"{a.dtype.str}{a.shape}".encode())
        h.update(a.data)
    return h.hexdigest()[:32]


# The arrays of K in the kernels' own form, in this order where the operators have them: 1D CSR values
# (Chain), 2D block ids into the table of distinct blocks (Plane).
_K_FIELDS = ("indptr", "indices", "K_data", "K_id", "K_table")


def scene_fingerprint(scene: Scene) -> dict[str, Any]:
    """What continuing a realization depends on in its scene, beyond the seed (JSON values).

    Two scenes with equal fingerprints give the same bits from the same
    state: kernel, sizes, settings, and digests of K, the loads and the
    recorded times.
    """
    net, ops = scene.network, scene.operators
    return {
        "kernel": scene.kernel,
        "n_nodes": int(net.n_nodes),
        "dim": int(net.dim),
        "Ntilde": float(net.Ntilde),
        "mu_d": float(scene.mu_d),
        "steps": int(scene.steps),
        "out_steps": digest(scene.out_steps),
        "tilt_at": scene.tilt_at,
        "catalogue": bool(scene.catalogue),
        "max_events": int(scene.max_events),
        "batch": int(scene.batch),
        "recompute_every": int(scene.recompute_every),
        "max_avalanche": int(scene.max_avalanche),
        "slip_mode": int(scene.slip_mode),
        "slip_factor": float(scene.slip_factor),
        "tilt_min_slips": int(scene.tilt_min_slips),
        "tilt_min_shift": float(scene.tilt_min_shift),
        # Only where contacts strengthen: a scene without it keeps the fingerprint of earlier snapshots.
        **({} if scene.strengthening is None else {"strengthening": list(scene.strengthening)}),
        # Likewise [tilt] repeats and inject, only where set.
        **({} if scene.tilt_repeats == 1 else {"tilt_repeats": int(scene.tilt_repeats)}),
        **({} if scene.inject is None else {"inject": scene.inject.model_dump(mode="json")}),
        # Only with the slide-hold-slide pull, likewise.
        **({} if scene.shs_stiffness is None else {"shs_stiffness": float(scene.shs_stiffness)}),
        # And the inertial solver's settings, with [dynamics].
        # tilt_rate only where set: the fingerprints of the runs before it existed stay as they were.
        **({} if scene.dynamics is None else {"dynamics": [float(x) for x in scene.dynamics if x is not None]}),
        "distribution": scene.distribution_name,
        "driver": scene.driver_name,
        "K": digest(*(getattr(ops, name) for name in _K_FIELDS if name in ops._fields)),
        "loads": digest(ops.g, net.normal_load, net.f_ext),
    }


# Entries added to the fingerprint after snapshots were written without them, and the value such a snapshot had.
_FINGERPRINT_DEFAULTS = {"slip_factor": 2.0, "tilt_min_slips": 1, "tilt_min_shift": 0.0}


def check_fingerprint(saved: Any, scene: Scene) -> None:
    """Refuse a snapshot written for another scene, naming the first entry that differs."""
    saved = saved if isinstance(saved, dict) else {}
    for key, value in scene_fingerprint(scene).items():
        if saved.get(key, _FINGERPRINT_DEFAULTS.get(key)) != value:
            raise SnapshotError(f"was written for another scene: its {key!r} is {saved.get(key)!r} there and "
                                f"{value!r} here")


def take(arrays: dict[str, np.ndarray], key: str, like: np.ndarray | None = None, *,
         dtype: Any = None, ndim: int | None = None) -> np.ndarray:
    """``arrays[key]``, checked against ``like``'s dtype and shape (or ``dtype`` and ``ndim``).

    Raises
    ------
    SnapshotError
        If the array is missing, or of another dtype or shape.

    Examples
    --------
    >>> take({"mu": np.zeros(2)}, "mu", np.ones(2)).tolist()
    [0.0, 0.0]
    >>> take({}, "mu", np.ones(2))
    Traceback (most recent call last):
    ...
    slidernet.errors.SnapshotError: is inconsistent: it has no array 'mu'
    """
    if key not in arrays:
        raise SnapshotError(f"is inconsistent: it has no array {key!r}")
    a = arrays[key]
    dtype = like.dtype if like is not None else np.dtype(dtype)
    if a.dtype != dtype or (like is not None and a.shape != like.shape) or (ndim is not None and a.ndim != ndim):
        want = like.shape if like is not None else f"{ndim} dimensions"
        raise SnapshotError(f"is inconsistent: array {key!r} is {a.dtype}{a.shape}, expected {dtype} {want}")
    return a
