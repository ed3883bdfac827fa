"""One backend per kernel: the state a kernel keeps for a realization, and the kernel that advances it.

A :class:`~slidernet.solver.realization.Realization` holds what every scene
has (its streams, theta(t_q), the thresholds, the scalars ``state``, the
draw buffers and the records) and one backend, picked once by the
scene's kernel (:data:`BACKENDS`, the only place that reads a kernel's
name). The realization, the tilt tests and the checkpoints talk to the
backend through one interface and never ask which kernel it is, the way
HOOMD-blue separates a simulation's State from its Operations:

- ``run(real, thetas)``: call the compiled kernel; returns its status code;
- ``forces(real)``, ``displacements(real)``: the state in physical form;
- ``last_slip(real)``: each node's last slip time, where the scene keeps it;
- ``recompute(real)``: reset incremental forces from the displacements;
- ``flush_events(real)``, ``events(real)``: the event catalogue;
- ``records(T)``, ``result(real)``: the kernel's own records and results;
- ``snapshot(real)``, ``restore(real, arrays)``: its state as named arrays
  (part of :meth:`Realization.snapshot <slidernet.solver.Realization.snapshot>`).

The realization is passed in as whatever has the attributes of
:class:`Host`: the backends never import the realization's module.

Backends:

- :class:`PairBackend` (``pair``): the paper's two sliders, scalars only;
- :class:`ChainBackend` (``csr``): any 1D network, CSR rows of K;
- :class:`PlaneBackend` (``vec``): any 2D network, 2 x 2 blocks of K;
- with ``[dynamics]``, the inertial solver's :class:`~slidernet.solver.inertia_backends.InertiaBackend`
  (``inertia``, 1D) and :class:`~slidernet.solver.inertia_backends.Inertia2DBackend` (``inertia_2d``).

The two network backends run the same driving loop, :func:`slidernet.kernels.network.run_network`,
on their operators (:class:`~slidernet.kernels.Chain` or :class:`~slidernet.kernels.Plane`). Each
backend picks its kernel's compiled variant once, from the scene (the appendix's tilt test
before every rearrangement, the exact 2D slip), so that nothing else is compiled.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from typing import Any, ClassVar, Protocol

import numpy as np

from slidernet import kernels
from slidernet.errors import SnapshotError
from slidernet.kernels.heap import theta_time
from slidernet.solver.inertia_backends import Inertia2DBackend, InertiaBackend
from slidernet.solver.scene import EVENT_CHUNK, SLIP_EXACT, Scene
from slidernet.solver.snapshot import take


class Host(Protocol):
    """What a backend reads and writes of the realization that holds it (a
    :class:`~slidernet.solver.Realization`)."""

    state: np.ndarray  # (1,) of dtype kernels.STATE
    mu: np.ndarray  # (N,) thresholds mu_s
    thetas: np.ndarray  # (steps + 1,) theta(t_q) / Ntilde
    series: kernels.Series

    @property
    def buffers(self) -> kernels.Draws: ...

    @property
    def step(self) -> int: ...


class PairBackend:
    """The paper's two sliders (kernel ``run_pair``): the state is scalars, no per-node array.

    The spring's length change u (``state["u"]``) and theta give the force
    F = theta - u at every use, so there is no force to keep, no drift, and
    nothing to save beyond the realization's own state.
    """

    kernel: ClassVar[str] = "pair"
    #: Slips per second of one worker, at least the measured 109.5 M/s (``python benchmarks/bench_vs_c.py``,
    #: README), rounded up: the slow-run estimate of :mod:`slidernet.solver.budget` is a lower bound of a time.
    slips_per_second: ClassVar[float] = 1.1e8

    def __init__(self, scene: Scene, real: Host) -> None:
        self.scene = scene
        self._run = kernels.run_pair_tilt if scene.do_tilt else kernels.run_pair

    @staticmethod
    def parts(scene: Scene) -> list[str]:
        """What this backend compiles for ``scene``, in words (the compile notice's list)."""
        return ["pair", "pair tilt test"] if scene.do_tilt else ["pair"]

    def records(self, T: int) -> dict[str, np.ndarray]:
        """Records this kernel writes beyond every scene's (none)."""
        return {}

    def run(self, real: Host, thetas: np.ndarray) -> int:
        scene = self.scene
        return self._run(thetas, scene.out_steps, real.mu, real.state, real.buffers, real.series, scene.settings())

    def forces(self, real: Host) -> np.ndarray:
        st = real.state[0]
        F = st["theta"] - st["u"]
        return np.array([-F, F])

    def displacements(self, real: Host) -> np.ndarray:
        # Slider 1 and 2 about the centre of mass; u = theta(0) at rest.
        st = real.state[0]
        half = 0.5 * (st["u"] - real.thetas[0])
        xg = st["x_G"]
        return np.array([[xg - half], [xg + half]])

    def recompute(self, real: Host) -> float:
        return 0.0

    def last_slip(self, real: Host) -> np.ndarray:
        """Each node's last slip time: none kept (a scene that needs them runs on a network kernel)."""
        return np.zeros(0)

    def flush_events(self, real: Host) -> None:  # pragma: no cover - the scene never asks it
        raise RuntimeError("the pair kernel keeps no event catalogue")

    def result(self, real: Host) -> dict[str, Any]:
        return {}

    def snapshot(self, real: Host) -> dict[str, np.ndarray]:
        return {}

    def restore(self, real: Host, arrays: dict[str, np.ndarray]) -> None:
        pass


class NetworkBackend:
    """A network kernel's state: force offsets, displacements, heaps, avalanche counts, event catalogue.

    The force on node i is F_i = a_i + g_i theta; the kernels update ``a``
    incrementally and ``u`` keeps the displacements (units of Ntilde l0),
    shape (N,) in 1D and (N, 2) in 2D.
    """

    kernel: ClassVar[str]
    #: Slips per second of one worker, rounded up from the fastest measured network (``python
    #: benchmarks/bench_vs_c.py``, README: 6.55 M/s on a triangular 32 x 32 lattice; 4.58 M/s at 1e6 nodes,
    #: 1.24 M/s on irregular networks of 1e6): the slow-run estimate of :mod:`slidernet.solver.budget`.
    slips_per_second: ClassVar[float] = 1e7

    def __init__(self, scene: Scene, real: Host) -> None:
        self.scene = scene
        N = scene.network.n_nodes
        g = scene.operators.g
        strong = scene.strengthening is not None
        # a = F - theta g with u = 0: every spring at rest at theta(0), plus the external load.
        fields = dict(a=-g * real.thetas[0] + self._f_ext(), u=np.zeros_like(g), mu=real.mu,
                      node_slips=np.zeros(N, np.int64),
                      avalanche_count=np.zeros(kernels.N_AVALANCHE_BINS, np.int64),
                      # Read only where the scene can slide away: 0-length elsewhere.
                      moving=np.full(N if scene.slide_away else 0, -1, np.int64),
                      # Read and written only where the scene keeps the contacts' ages (Scene.keeps_ages).
                      last_slip=np.zeros(N if scene.keeps_ages else 0))
        # With strengthening, the type the *_aging kernels are compiled for: its drawn thresholds and its law.
        self.nodes: kernels.Nodes | kernels.AgingNodes = (
            kernels.AgingNodes(**fields, mu0=real.mu.copy(), law=np.array(scene.strengthening, np.float64))
            if strong else kernels.Nodes(**fields))
        # The unstable heap, and the driving trees over the driven nodes (g_i != 0).
        self.heaps = kernels.Heaps.empty(1, N, driven=np.any(g.reshape(N, -1) != 0.0, axis=1))
        # The event catalogue: the kernel fills a buffer of EVENT_CHUNK rows (fewer where
        # max_events is smaller), Python keeps the full ones, at most max_events rows in all.
        rows = min(EVENT_CHUNK, scene.max_events) if scene.catalogue else 0
        self.catalogue = kernels.Catalogue(np.zeros((rows, 2), np.int64), np.zeros((rows, 3)))
        self.event_chunks: list[tuple[np.ndarray, np.ndarray]] = []
        self.events_complete = True
        real.state["ev_on"] = int(scene.catalogue)
        self.rebuild_heaps(real)

    def _f_ext(self) -> np.ndarray:
        """The external forces in the shape of ``a``: (N,) in 1D, (N, 2) in 2D."""
        f_ext = self.scene.network.f_ext
        return f_ext[:, 0].copy() if self.scene.network.dim == 1 else f_ext.copy()

    def records(self, T: int) -> dict[str, np.ndarray]:
        return {"mu_mean": np.zeros(T), "mu_min": np.zeros(T)}

    # The compiled kernel of the network's geometry and the scene's variant, and the one that builds its heaps.
    _run: Callable[..., int]
    _init_heaps: Callable[..., None]

    def rebuild_heaps(self, real: Host) -> None:
        self._init_heaps(self.scene.operators, real.state, self.nodes, self.heaps, state_time(real))

    def run(self, real: Host, thetas: np.ndarray) -> int:
        scene = self.scene
        return self._run(thetas, scene.out_steps, scene.operators, real.state, self.nodes, self.heaps,
                               real.buffers, self.catalogue, real.series, scene.settings())

    def forces(self, real: Host) -> np.ndarray:
        return self.nodes.a + self.scene.operators.g * real.state["theta"][0]

    def displacements(self, real: Host) -> np.ndarray:
        return self.nodes.u.reshape(self.scene.network.n_nodes, -1)

    def last_slip(self, real: Host) -> np.ndarray:
        """Each node's last slip time, in tau_th (0: never slipped), shape (N,); 0-length unless the scene keeps
        the ages (``Scene.keeps_ages``)."""
        return self.nodes.last_slip

    def recompute(self, real: Host) -> float:
        g = self.scene.operators.g
        a, u = self.nodes.a, self.nodes.u
        fresh = -self._K_times(u) - g * real.thetas[0]
        fresh += self._f_ext()
        drift = float(np.abs(fresh - a).max())
        a[...] = fresh
        real.state["since_recompute"] = 0
        self.rebuild_heaps(real)
        return drift

    def _K_times(self, u: np.ndarray) -> np.ndarray:
        """K u, in the shape of u."""
        return self.scene.K @ u

    def flush_events(self, real: Host) -> None:
        """Keep the full catalogue buffer and start a new one; stop at ``solver.max_events``.

        The new buffer holds at most the rows left under the cap, so the
        kernel asks again exactly when the cap is reached: the catalogue
        then stops, with one warning, and the run goes on.
        """
        k = int(real.state["ev_pos"][0])
        cat = self.catalogue
        self.event_chunks.append((cat.ids[:k].copy(), cat.values[:k].copy()))
        real.state["ev_pos"] = 0
        kept = sum(c[0].shape[0] for c in self.event_chunks)
        rows = min(EVENT_CHUNK, self.scene.max_events - kept)
        if rows != cat.ids.shape[0]:
            self.catalogue = kernels.Catalogue(np.zeros((rows, 2), np.int64), np.zeros((rows, 3)))
        if rows == 0:
            real.state["ev_on"] = 0
            self.events_complete = False
            warnings.warn(
                f"The event catalogue reached solver.max_events = {self.scene.max_events} events at step "
                f"{real.step}; later slips are not catalogued (the run goes on).",
                RuntimeWarning, stacklevel=5,
            )

    def events(self, real: Host) -> dict[str, np.ndarray]:
        """The catalogue so far (see :meth:`Realization.events`)."""
        k = int(real.state["ev_pos"][0])
        chunks = [*self.event_chunks, (self.catalogue.ids[:k], self.catalogue.values[:k])]
        ev_i = np.concatenate([c[0] for c in chunks])
        ev_f = np.concatenate([c[1] for c in chunks])
        Ntilde = self.scene.network.Ntilde
        return {"time": ev_f[:, 0].copy(), "node": ev_i[:, 0].copy(), "avalanche": ev_i[:, 1].copy(),
                "dx": ev_f[:, 1] * Ntilde, "dy": ev_f[:, 2] * Ntilde}

    def result(self, real: Host) -> dict[str, Any]:
        res: dict[str, Any] = {"avalanche_count": self.nodes.avalanche_count.copy(),
                               "node_slips": self.nodes.node_slips.copy(),
                               "mu_s": real.mu.copy()}
        if self.scene.catalogue:
            res["events"] = self.events(real)
            res["events_complete"] = self.events_complete
        return res

    def snapshot(self, real: Host) -> dict[str, np.ndarray]:
        """The backend's state as named numeric arrays (the catalogue buffer up to its last written row)."""
        arrays = {**self._named_arrays()}
        k = int(real.state["ev_pos"][0])
        # Rows past ev_pos are stale: the kernel writes a row before anything reads it.
        arrays["events/buffer_ids"] = self.catalogue.ids[:k]
        arrays["events/buffer_values"] = self.catalogue.values[:k]
        arrays["events/buffer_rows"] = np.array(self.catalogue.ids.shape[0], np.int64)
        arrays["events/complete"] = np.array(self.events_complete, np.int64)
        chunks = self.event_chunks
        arrays["events/chunk_rows"] = np.array([c[0].shape[0] for c in chunks], dtype=np.int64)
        arrays["events/chunks_ids"] = np.concatenate([np.zeros((0, 2), np.int64)] + [c[0] for c in chunks])
        arrays["events/chunks_values"] = np.concatenate([np.zeros((0, 3))] + [c[1] for c in chunks])
        return arrays

    def _named_arrays(self) -> dict[str, np.ndarray]:
        """The per-node state and the heaps, by name (``nodes/a``, ``heaps/key``, ...); ``mu`` is the
        realization's own."""
        named = {f"nodes/{name}": a for name, a in self.nodes._asdict().items() if name != "mu"}
        named.update({f"heaps/{name}": a for name, a in self.heaps._asdict().items()})
        return named

    def restore(self, real: Host, arrays: dict[str, np.ndarray]) -> None:
        """Overwrite the state from :meth:`snapshot`'s arrays (each one checked).

        Call it after the realization's counters are restored: the catalogue's
        write position is ``real.state["ev_pos"]``.
        """
        # In place: the kernels get arrays of exactly the layout and dtype they were compiled for.
        for name, target in self._named_arrays().items():
            if target.size == 0 and name not in arrays:
                continue  # kept by scenes that ask for it only; absent from snapshots written before it existed
            target[...] = take(arrays, name, target)
        k = int(real.state["ev_pos"][0])
        rows = int(take(arrays, "events/buffer_rows", dtype=np.int64, ndim=0))
        if not 0 <= k <= rows:
            raise SnapshotError(f"is inconsistent: {k} catalogue rows are written in a buffer of {rows}")
        self.catalogue = kernels.Catalogue(np.zeros((rows, 2), np.int64), np.zeros((rows, 3)))
        self.catalogue.ids[:k] = take(arrays, "events/buffer_ids", self.catalogue.ids[:k])
        self.catalogue.values[:k] = take(arrays, "events/buffer_values", self.catalogue.values[:k])
        counts = take(arrays, "events/chunk_rows", dtype=np.int64, ndim=1)
        ev_i = take(arrays, "events/chunks_ids", dtype=np.int64, ndim=2)
        ev_f = take(arrays, "events/chunks_values", dtype=np.float64, ndim=2)
        total = int(counts.sum())
        if (counts < 0).any() or ev_i.shape != (total, 2) or ev_f.shape != (total, 3):
            raise SnapshotError(f"is inconsistent: the catalogue chunks of {counts.tolist()} rows are "
                                f"{ev_i.shape} and {ev_f.shape}")
        cuts = np.cumsum(counts)[:-1]
        self.event_chunks = [(i.copy(), f.copy()) for i, f in zip(np.split(ev_i, cuts), np.split(ev_f, cuts),
                                                                   strict=True)] if counts.size else []
        self.events_complete = bool(take(arrays, "events/complete", dtype=np.int64, ndim=0))


class ChainBackend(NetworkBackend):
    """Any 1D network (``solver.kernel = "csr"``): CSR rows of K, scalar forces."""

    kernel: ClassVar[str] = "csr"

    def __init__(self, scene: Scene, real: Host) -> None:
        # The appendix's test and strengthening never meet (the configuration refuses it).
        if scene.strengthening is not None:
            self._run, self._init_heaps = kernels.run_chain_aging, kernels.init_chain_heaps_aging
        else:
            self._run = kernels.run_chain_tilt if scene.do_tilt else kernels.run_chain
            self._init_heaps = kernels.init_chain_heaps
        super().__init__(scene, real)

    @staticmethod
    def parts(scene: Scene) -> list[str]:
        """What this backend compiles for ``scene``, in words (the compile notice's list)."""
        if scene.strengthening is not None:
            return ["1D network with contact strengthening"]
        return ["1D network", "appendix's tilt test"] if scene.do_tilt else ["1D network"]


class PlaneBackend(NetworkBackend):
    """Any 2D network (``solver.kernel = "vec"``): 2 x 2 blocks of K, vector forces, the centre of mass
    along y too."""

    kernel: ClassVar[str] = "vec"

    def __init__(self, scene: Scene, real: Host) -> None:
        exact = scene.slip_mode == SLIP_EXACT
        if scene.strengthening is not None:
            self._run = kernels.run_plane_exact_aging if exact else kernels.run_plane_aging
            self._init_heaps = kernels.init_plane_heaps_aging
        else:
            self._run = kernels.run_plane_exact if exact else kernels.run_plane
            self._init_heaps = kernels.init_plane_heaps
        super().__init__(scene, real)

    @staticmethod
    def parts(scene: Scene) -> list[str]:
        """What this backend compiles for ``scene``, in words (the compile notice's list)."""
        parts = ["2D network with contact strengthening" if scene.strengthening is not None else "2D network"]
        return [*parts, "exact 2D slip"] if scene.slip_mode == SLIP_EXACT else parts

    def records(self, T: int) -> dict[str, np.ndarray]:
        return {**super().records(T), "y_G": np.zeros(T)}

    def _K_times(self, u: np.ndarray) -> np.ndarray:
        # Over the kernels' block table: scipy would need one block per entry written out.
        out = np.empty_like(u)
        kernels.stiffness_times(self.scene.operators, u, out)
        return out


def state_time(real: Host) -> float:
    """The time of the realization's state, in tau_th: q plus the fraction of step q that theta has covered
    (q where theta stands still in the step, or at its start)."""
    st = real.state[0]
    # The kernels' own formula, run as Python: nothing to compile for it.
    return float(theta_time.py_func(real.thetas, int(st["q"]), st["theta"]))


# The one place where a kernel's name is read: the scene's choice picks the backend.
BACKENDS: dict[str, type[PairBackend] | type[NetworkBackend] | type[InertiaBackend] | type[Inertia2DBackend]] = {
    b.kernel: b for b in (PairBackend, ChainBackend, PlaneBackend, InertiaBackend, Inertia2DBackend)
}


def backend_for(scene: Scene, real: Host) -> PairBackend | NetworkBackend | InertiaBackend | Inertia2DBackend:
    """The backend of ``scene``'s kernel, with its state built for ``real``."""
    return BACKENDS[scene.kernel](scene, real)
