"""The inertial solver as a backend of :class:`~slidernet.solver.Realization`: ``[dynamics]`` from a configuration.

A scene with ``[dynamics]`` runs on :class:`InertiaBackend` (1D, the pair
included: kernel ``inertia``) or :class:`Inertia2DBackend` (kernel
``inertia_2d``), through the interface of
:mod:`slidernet.solver.backends`. The realization keeps what it keeps for
the quasi-static kernels (streams, theta(t_q), the thresholds ``mu``, the
scalars of ``state``, the records), so that records, tilt tests at the
recorded times, checkpoints, resume and Dask work unchanged; the backend
keeps the motion (displacements, velocities, the moving set) and turns the
kernel's logs of slips and avalanches into the quasi-static solver's
observables as they come:

- ``n``, ``mu_max``, ``x_G`` are written by the kernel at the recorded
  times, ``n_records`` is counted where a stop redraws a threshold
  (:func:`~slidernet.kernels.heap.replace_threshold`), and ``mu_mean``,
  ``mu_min``, ``y_G`` and ``contact_age`` are read at the recorded times
  (the kernel is run from one recorded time to the next);
- ``node_slips``, ``avalanche_count`` (the starts of each motion from rest
  to rest, binned as the quasi-static avalanches are) and the event
  catalogue (``events``: one row per slip, at its start, with its
  displacement) are read from the logs after every return of the kernel;
- a contact's age counts from the end of its node's last slip, when the
  node came to rest on it.

The state at a recorded time may hold moving nodes (a motion that crosses
t_q); the network tilt test then tests that configuration as it stands,
every node held where it is (docs/guides/inertia.md), and so does the
dynamic tilt test of ``[dynamics] tilt_rate``
(:mod:`slidernet.solver.inertia_tilt`), each velocity set to zero.
"""

from __future__ import annotations

import warnings
from abc import ABC, abstractmethod
from typing import Any, ClassVar

import numpy as np

from slidernet import kernels
from slidernet.errors import SnapshotError
from slidernet.kernels import inertia as kin
from slidernet.kernels import inertia_2d as k2d
from slidernet.kernels.heap import mu_stats, write_ages
from slidernet.kernels.inertia_phase import new_work
from slidernet.solver.inertia import LOG_ROWS, new_log, new_motion, runaway_error
from slidernet.solver.inertia_2d import Run, new_out, new_scalars
from slidernet.solver.inertia_2d import new_motion as new_motion_2d
from slidernet.solver.scene import Scene
from slidernet.solver.snapshot import take


def avalanche_sizes(ends: np.ndarray, carry: int) -> np.ndarray:
    """The sizes (slips) of the avalanches that ended in a chunk of the slip log.

    Parameters
    ----------
    ends : ndarray of int64, shape (A,)
        For each avalanche that ended in the chunk, the slips logged in the
        chunk by its end (non-decreasing).
    carry : int
        Slips logged before the chunk by an avalanche still running then.

    Returns
    -------
    ndarray of int64, shape (A,)

    Examples
    --------
    >>> avalanche_sizes(np.array([2, 2, 5]), 3)
    array([5, 0, 3])
    """
    starts = np.concatenate([[0], ends[:-1]]) if ends.size else ends
    sizes = (ends - starts).astype(np.int64)
    if sizes.size:
        sizes[0] += carry
    return sizes


def log2_bins(sizes: np.ndarray) -> np.ndarray:
    """Counts of the sizes s >= 1 in the quasi-static avalanche bins floor(log2 s), shape (N_AVALANCHE_BINS,).

    >>> log2_bins(np.array([1, 2, 3, 4, 0]))[:4]
    array([1, 2, 1, 0])
    """
    s = sizes[sizes > 0]
    return np.bincount(np.floor(np.log2(s)).astype(np.int64), minlength=kernels.N_AVALANCHE_BINS)


# The motion's arrays a snapshot leaves out: the realization's thresholds (saved as its own), and the dynamic tilt
# test's watch (empty in a run).
_NOT_SAVED = ("mu", "first", "times")

# What a backend's kernel call returns when a log is full: the digest empties it and the kernel goes on.
_FULL = -1


class _Inertial(ABC):
    """What both inertial backends share: the digest of the logs, the records read at the recorded times, the
    event catalogue, and their part of a snapshot."""

    kernel: ClassVar[str]
    #: Slips per second of one worker, an upper bound of the measured rates (docs/guides/performance.md): the
    #: slow-run estimate of :mod:`slidernet.solver.budget` is a lower bound of a time.
    slips_per_second: ClassVar[float]

    def __init__(self, scene: Scene, real: Any) -> None:
        self.scene = scene
        N = scene.network.n_nodes
        self.dyn = scene.dynamics
        self.node_slips = np.zeros(N, np.int64)
        self.last_stop = np.zeros(N)
        self.avalanche_count = np.zeros(kernels.N_AVALANCHE_BINS, np.int64)
        # [slips of the running avalanche logged so far, avalanches ended, recorded times read]
        self.counters = np.zeros(3, np.int64)
        self.event_chunks: list[tuple[np.ndarray, np.ndarray]] = []
        self.events_complete = True

    @staticmethod
    def parts(scene: Scene) -> list[str]:
        """What this backend compiles for ``scene``, in words (the compile notice's list)."""
        return [f"inertial solver ({scene.network.dim}D)"]

    def records(self, T: int) -> dict[str, np.ndarray]:
        out = {"mu_mean": np.zeros(T), "mu_min": np.zeros(T)}
        return {**out, "y_G": np.zeros(T)} if self.scene.network.dim == 2 else out

    # The kernel's own parts, one method each in the two backends.
    RUNAWAY: ClassVar[int]  # its return code of a runaway
    u: np.ndarray  # the displacements, Ntilde l0, shape (N,) or (N, 2)
    motion: Any  # the kernel's Motion: per-node state, and the running mu_max ``best``
    work: Any  # the kernel's Work: the scratch of a phase, saved with the motion

    @abstractmethod
    def _call(self, real: Any, thetas: np.ndarray, steps: int) -> int:
        """Run the kernel from where it stands to step ``steps`` or its first return: DONE, NEED_MU, _FULL
        or RUNAWAY."""

    @abstractmethod
    def _slip_rows(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The slips logged since the last clear: node, start, end (tau_th), du_x, du_y (Ntilde l0)."""

    @abstractmethod
    def _avalanche_ends(self) -> np.ndarray:
        """For each avalanche ended since the last clear, the slips logged since then by its end."""

    @abstractmethod
    def _clear_logs(self) -> None: ...

    @abstractmethod
    def _time(self) -> float:
        """The kernel's time t, tau_th."""

    def _best(self) -> np.ndarray:
        """(mu_max, its holder, n_records), shape (3,)."""
        return self.motion.best

    @abstractmethod
    def _runaway_node(self) -> int: ...

    @abstractmethod
    def _scalars(self) -> dict[str, int]:
        """The kernel's step ``q``, ``n``, read position ``pos`` and next record ``next_out``."""

    def _state_arrays(self) -> dict[str, np.ndarray]:
        """Every array of the motion and the kernel's scalars, by name (``mu`` is the realization's own)."""
        arrays = {f"motion/{name}": a for name, a in self.motion._asdict().items() if name not in _NOT_SAVED}
        arrays.update({f"work/{name}": a for name, a in self.work._asdict().items()})
        return {**arrays, **self._kernel_scalars()}

    @abstractmethod
    def _kernel_scalars(self) -> dict[str, np.ndarray]:
        """The kernel's integer and float scalars, by their snapshot names."""

    @abstractmethod
    def forces(self, real: Any) -> np.ndarray:
        """The spring and external forces on every node, N, shape (N,) or (N, 2)."""

    def run(self, real: Any, thetas: np.ndarray) -> int:
        """Run the kernel to the end of ``thetas`` (returns DONE) or to an empty threshold buffer (NEED_MU),
        stopping at every recorded time on the way to read what the kernel does not write."""
        scene, st = self.scene, real.state
        end = thetas.size - 1
        while True:
            k = int(self.counters[2])
            upto = min(end, int(scene.out_steps[k])) if k < scene.out_steps.size else end
            code = self._call(real, thetas, upto)
            self._digest(real)
            self._sync(real, thetas)
            if code == kernels.NEED_MU:
                return code
            if code == self.RUNAWAY:
                raise runaway_error(self._runaway_node(), self._time())
            if code == _FULL:
                continue  # emptied by the digest
            while self.counters[2] < int(st["next_out"][0]):
                self._read_record(real, int(self.counters[2]))
                self.counters[2] += 1
            if upto == end:
                return kernels.DONE

    def _read_record(self, real: Any, k: int) -> None:
        """What the kernel does not write at recorded time k: n_records, mu_mean, mu_min, y_G, contact_age."""
        real.out["n_records"][k] = int(self._best()[2])
        real.out["mu_mean"][k], real.out["mu_min"][k] = mu_stats(real.mu)
        if "y_G" in real.out:
            real.out["y_G"][k] = float(self.scene.operators.w @ self.u[:, 1])
        if self.scene.contact_age:
            write_ages(float(self.scene.out_steps[k]), self.last_stop, real.series, k)

    def _digest(self, real: Any) -> None:
        """Turn the slips and avalanches logged since the last return into counts, ages and events."""
        node, start, end, dux, duy = self._slip_rows()
        ends = self._avalanche_ends()
        np.add.at(self.node_slips, node, 1)
        self.last_stop[node] = end
        sizes = avalanche_sizes(ends, int(self.counters[0]))
        self.avalanche_count += log2_bins(sizes)
        done = int(ends[-1]) if ends.size else 0
        # The running avalanche's slips: those after the last end, plus those carried if none ended.
        self.counters[0] = (node.size - done) + (0 if ends.size else int(self.counters[0]))
        first = int(self.counters[1])
        self.counters[1] += ends.size
        if self.scene.catalogue and node.size:
            # Each slip's avalanche, counted from 1 (motions from rest to rest, in order).
            which = first + 1 + np.searchsorted(ends, np.arange(node.size), side="right")
            self._catalogue(real, node, which, start, dux, duy)
        self._clear_logs()

    def _catalogue(self, real: Any, node: np.ndarray, which: np.ndarray, start: np.ndarray, dux: np.ndarray,
                   duy: np.ndarray) -> None:
        if not self.events_complete:
            return
        kept = sum(c[0].shape[0] for c in self.event_chunks)
        room = self.scene.max_events - kept
        rows = min(room, node.size)
        ids = np.stack([node[:rows], which[:rows]], axis=1).astype(np.int64)
        values = np.stack([start[:rows], dux[:rows], duy[:rows]], axis=1)
        self.event_chunks.append((ids, values))
        if rows < node.size:
            self.events_complete = False
            warnings.warn(
                f"The event catalogue reached solver.max_events = {self.scene.max_events} events at step "
                f"{real.step}; later slips are not catalogued (the run goes on).", RuntimeWarning, stacklevel=6)

    def _sync(self, real: Any, thetas: np.ndarray) -> None:
        """The realization's scalars from the kernel's: its step, n, theta, x_G, mu_max, the read position."""
        st = real.state
        scalars = self._scalars()
        q = int(scalars["q"])
        theta = thetas[q] if q + 1 >= thetas.size else thetas[q] + (thetas[q + 1] - thetas[q]) * (self._time() - q)
        st["q"], st["n_slips"], st["mu_pos"] = scalars["q"], scalars["n"], scalars["pos"]
        st["next_out"] = scalars["next_out"]
        st["theta"] = theta
        st["x_G"] = float(self.scene.operators.w @ self.u.reshape(self.u.shape[0], -1)[:, 0])
        best = self._best()
        st["mu_max"], st["argmax"], st["n_records"] = best[0], int(best[1]), int(best[2])
        st["n_events"] = int(self.counters[1])

    def displacements(self, real: Any) -> np.ndarray:
        return self.u.reshape(self.scene.network.n_nodes, -1)

    def last_slip(self, real: Any) -> np.ndarray:
        """Each node's last slip's end, in tau_th (0: never slipped), shape (N,)."""
        return self.last_stop

    def recompute(self, real: Any) -> float:
        return 0.0  # the inertial kernels return no RECOMPUTE: nothing calls this

    def flush_events(self, real: Any) -> None:  # pragma: no cover - the inertial kernels return no NEED_EVENTS
        raise RuntimeError("the inertial backends keep their catalogue themselves")

    def events(self, real: Any) -> dict[str, np.ndarray]:
        """The catalogue so far (see :meth:`Realization.events`; ``avalanche`` counts motions from rest to rest
        from 1, ``time`` is the slip's start)."""
        ev_i = np.concatenate([np.zeros((0, 2), np.int64)] + [c[0] for c in self.event_chunks])
        ev_f = np.concatenate([np.zeros((0, 3))] + [c[1] for c in self.event_chunks])
        Ntilde = self.scene.network.Ntilde
        return {"time": ev_f[:, 0].copy(), "node": ev_i[:, 0].copy(), "avalanche": ev_i[:, 1].copy(),
                "dx": ev_f[:, 1] * Ntilde, "dy": ev_f[:, 2] * Ntilde}

    def result(self, real: Any) -> dict[str, Any]:
        res: dict[str, Any] = {"avalanche_count": self.avalanche_count.copy(),
                               "node_slips": self.node_slips.copy(), "mu_s": real.mu.copy()}
        if self.scene.catalogue:
            res["events"] = self.events(real)
            res["events_complete"] = self.events_complete
        return res

    def snapshot(self, real: Any) -> dict[str, np.ndarray]:
        arrays = dict(self._state_arrays())
        arrays.update({"digest/node_slips": self.node_slips, "digest/last_stop": self.last_stop,
                       "digest/avalanche_count": self.avalanche_count, "digest/counters": self.counters,
                       "events/complete": np.array(self.events_complete, np.int64)})
        chunks = self.event_chunks
        arrays["events/chunk_rows"] = np.array([c[0].shape[0] for c in chunks], dtype=np.int64)
        arrays["events/chunks_ids"] = np.concatenate([np.zeros((0, 2), np.int64)] + [c[0] for c in chunks])
        arrays["events/chunks_values"] = np.concatenate([np.zeros((0, 3))] + [c[1] for c in chunks])
        return arrays

    def restore(self, real: Any, arrays: dict[str, np.ndarray]) -> None:
        own = {**self._state_arrays(), "digest/node_slips": self.node_slips, "digest/last_stop": self.last_stop,
               "digest/avalanche_count": self.avalanche_count, "digest/counters": self.counters}
        # In place: the kernel gets arrays of exactly the layout and dtype it was compiled for.
        for name, target in own.items():
            target[...] = take(arrays, name, target)
        ev_i = take(arrays, "events/chunks_ids", dtype=np.int64, ndim=2)
        ev_f = take(arrays, "events/chunks_values", dtype=np.float64, ndim=2)
        counts = take(arrays, "events/chunk_rows", dtype=np.int64, ndim=1)
        if (counts < 0).any() or ev_i.shape != (int(counts.sum()), 2) or ev_f.shape != (int(counts.sum()), 3):
            raise SnapshotError(f"is inconsistent: the catalogue chunks of {counts.tolist()} rows are "
                                f"{ev_i.shape} and {ev_f.shape}")
        self.event_chunks = [(ev_i, ev_f)] if counts.size else []
        self.events_complete = bool(take(arrays, "events/complete", dtype=np.int64, ndim=0))


class InertiaBackend(_Inertial):
    """The inertial solver of 1D networks (kernel ``inertia``: :func:`slidernet.kernels.inertia.run_inertia`)."""

    kernel: ClassVar[str] = "inertia"
    #: Upper bound of the measured 0.66 us per slip of the pair (``python benchmarks/inertia_speed.py``).
    slips_per_second: ClassVar[float] = 2e6
    RUNAWAY: ClassVar[int] = kin.RUNAWAY

    def __init__(self, scene: Scene, real: Any) -> None:
        super().__init__(scene, real)
        net = scene.operators
        N = scene.network.n_nodes
        self.motion = new_motion(real.mu, net.normal_load)
        self.u = self.motion.u
        self.work = new_work(N)
        self.log = new_log(0, LOG_ROWS)._replace(
            out_n=real.out["n"], out_mu_max=real.out["mu_max"], out_xg=real.out["x_G"])
        self.istate = np.zeros(10, np.int64)
        self.fstate = np.zeros(6)
        self.f_ext = np.ascontiguousarray(scene.network.f_ext[:, 0], dtype=np.float64)

    def _call(self, real: Any, thetas: np.ndarray, steps: int) -> int:
        self.istate[kin.I_POS] = real.state["mu_pos"][0]
        code = kin.run_inertia(self.scene.operators, self.f_ext, float(self.scene.mu_d), self.dyn.tau_ratio,
                               thetas, self.scene.out_steps, steps, self.motion, self.work, self.log,
                               real.buffers.mu, self.istate, self.fstate)
        return _FULL if code == kernels.NEED_EVENTS else code

    def _slip_rows(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        S = int(self.istate[kin.I_SLIPS])
        log = self.log
        return (log.slip_node[:S], log.slip_start[:S], log.slip_end[:S], log.slip_du[:S], np.zeros(S))

    def _avalanche_ends(self) -> np.ndarray:
        return self.log.av_slips[: int(self.istate[kin.I_AVAL])]

    def _clear_logs(self) -> None:
        self.istate[kin.I_SLIPS] = 0
        self.istate[kin.I_AVAL] = 0

    def _time(self) -> float:
        return float(self.fstate[kin.F_T])

    def _runaway_node(self) -> int:
        return int(self.istate[kin.I_NODE])

    def forces(self, real: Any) -> np.ndarray:
        # As the kernel forms them: F = -K u + (theta - theta(0)) g + f_ext.
        return (-(self.scene.K @ self.u) + self.scene.operators.g * (real.state["theta"][0] - real.thetas[0])
                + self.f_ext)

    def _scalars(self) -> dict[str, np.ndarray]:
        i = self.istate
        return {"q": i[kin.I_Q], "n": i[kin.I_N], "pos": i[kin.I_POS], "next_out": i[kin.I_REC]}

    def _kernel_scalars(self) -> dict[str, np.ndarray]:
        return {"kernel/istate": self.istate, "kernel/fstate": self.fstate}


class Inertia2DBackend(_Inertial):
    """The inertial solver of 2D networks (kernel ``inertia_2d``:
    :func:`slidernet.kernels.inertia_2d.run_inertia_2d`)."""

    kernel: ClassVar[str] = "inertia_2d"
    #: Upper bound of the measured 68-94 us per slip at 16-1024 nodes (``python benchmarks/inertia_2d_speed.py``).
    slips_per_second: ClassVar[float] = 2e4
    RUNAWAY: ClassVar[int] = k2d.RUNAWAY

    def __init__(self, scene: Scene, real: Any) -> None:
        super().__init__(scene, real)
        self.motion, self.work = new_motion_2d(scene, real.mu, real.thetas[0])
        self.u = self.motion.u
        self.out = new_out(real.out["n"], real.out["mu_max"], real.out["x_G"])
        self.floats, self.ints = new_scalars(self.dyn.max_step)

    def _call(self, real: Any, thetas: np.ndarray, steps: int) -> int:
        dyn = self.dyn
        run = Run(mu_d=float(self.scene.mu_d), tau=dyn.tau_ratio, rtol=dyn.rtol, atol=1e-2 * dyn.rtol,
                      max_step=dyn.max_step, steps=int(steps))
        self.ints[k2d.POS] = real.state["mu_pos"][0]
        code = k2d.run_inertia_2d(thetas, self.scene.out_steps, self.scene.operators, self.motion, self.work,
                                  self.out, run, self.floats, self.ints, real.buffers.mu)
        return {k2d.DONE: kernels.DONE, k2d.NEED_MU: kernels.NEED_MU, k2d.NEED_OUT: _FULL}.get(code, code)

    def _slip_rows(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        S = int(self.ints[k2d.N_SLIPS])
        f = self.out.slip_f[:S]
        return self.out.slip_node[:S], f[:, 0], f[:, 1], f[:, 3], f[:, 4]

    def _avalanche_ends(self) -> np.ndarray:
        return np.cumsum(self.out.av_n[: int(self.ints[k2d.N_AV])]) - int(self.counters[0])

    def _clear_logs(self) -> None:
        self.ints[k2d.N_SLIPS] = 0
        self.ints[k2d.N_AV] = 0

    def _time(self) -> float:
        return float(self.floats[k2d.T])

    def _runaway_node(self) -> int:
        return int(self.ints[k2d.RUNAWAY_NODE])

    def forces(self, real: Any) -> np.ndarray:
        # The kernel's own: F = a + g theta, a updated as the nodes move.
        return self.motion.a + self.scene.operators.g * real.state["theta"][0]

    def _scalars(self) -> dict[str, np.ndarray]:
        i = self.ints
        return {"q": i[k2d.Q], "n": i[k2d.N], "pos": i[k2d.POS], "next_out": i[k2d.NEXT_OUT]}

    def _kernel_scalars(self) -> dict[str, np.ndarray]:
        return {"kernel/floats": self.floats, "kernel/ints": self.ints}
