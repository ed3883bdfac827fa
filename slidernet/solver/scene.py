"""The scene: everything derived once from a configuration (network, operators, kernel choice, recorded times)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from slidernet.config import Config, build_network, choose_kernel
from slidernet.errors import ConfigError
from slidernet.model.network import Network


def record_times(steps: int, record: str | list[int], per_decade: int = 20) -> np.ndarray:
    """Recorded times in tau_th, always including 0 and ``steps``.

    >>> record_times(100, "log", per_decade=2).tolist()
    [0, 1, 3, 10, 32, 100]
    >>> record_times(3, "all").tolist()
    [0, 1, 2, 3]
    """
    if record == "all":
        t = np.arange(steps + 1)
    elif record == "log":
        decades = np.log10(steps) if steps > 1 else 0.0
        npts = max(int(np.ceil(decades * per_decade)) + 1, 2)
        t = np.round(np.logspace(0.0, decades, npts)).astype(np.int64)
    else:
        t = np.asarray(record, dtype=np.int64)
    return np.unique(np.concatenate([[0, steps], t])).astype(np.int64)


EVENT_CHUNK = 1 << 16  # rows of the event-catalogue buffer the kernel fills between returns


def _operators(net: Network) -> tuple[str, Any, dict[str, np.ndarray]]:
    """The kernel family of a network, its stiffness matrix K and the arrays the kernel runs on.

    1D: the CSR rows of K. 2D: the block-CSR rows of its 2x2 blocks, which
    share memory with the returned ``scipy.sparse.bsr_matrix``. Entries of g
    below 1e-12 of its largest entry are set to exactly zero: in a uniform
    lattice the interior loads cancel up to rounding, and a node with g_i = 0
    is never driven directly (it stays out of the driving heaps).
    """
    g = net.thermal_load()
    gmax = np.abs(g).max() if g.size else 0.0
    g = np.where(np.abs(g) > 1e-12 * gmax, g, 0.0)
    common = {
        "normal_load": net.normal_load.astype(np.float64),
        "w": net.normal_load / net.normal_load.sum(),
    }
    if net.dim == 1:
        K = net.stiffness_matrix()
        return "csr", K, {
            **common,
            "indptr": K.indptr.astype(np.int64),
            "indices": K.indices.astype(np.int64),
            "kdata": K.data.astype(np.float64),
            "kdiag": K.diagonal().astype(np.float64),
            "g": g.astype(np.float64),
        }
    K = net.stiffness_blocks()
    indptr = K.indptr.astype(np.int64)
    indices = K.indices.astype(np.int64)
    row = np.repeat(np.arange(net.n_nodes), np.diff(indptr))
    g2 = g.reshape(-1, 2).astype(np.float64)
    return "vec", K, {
        **common,
        "indptr": indptr,
        "indices": indices,
        "kblk": K.data,
        "diagpos": np.flatnonzero(indices == row).astype(np.int64),
        "g": g2,
        "driven": (g2 != 0).any(axis=1),  # informative: the kernel reads g itself
        "unit_load": bool((net.normal_load == 1.0).all()),
    }


@dataclass
class Scene:
    """Everything a realization needs, derived once from a :class:`Config`.

    Attributes
    ----------
    kernel : {"pair", "csr", "vec"}
        The specialized kernel picked for this scene: ``pair`` for the
        paper's two sliders, ``csr`` for other 1D networks, ``vec`` in 2D.
    ops : dict of str to ndarray
        The arrays the network kernels run on (see ``_operators``).
    K : scipy.sparse matrix or None
        The stiffness matrix, for the periodic recomputation of the forces.
    """

    network: Network
    distribution: Any
    driver: Any
    driver_name: str
    distribution_name: str
    mu_d: float
    steps: int
    rec_times: np.ndarray
    kernel: str
    tilt_at: str | None
    max_avalanche: int
    batch: int
    recompute_every: int
    slip_mode: int
    catalogue: bool = False
    max_events: int = 0
    ops: dict[str, np.ndarray] = field(default_factory=dict)
    K: Any = None
    _tilt_ops: dict[str, Any] | None = field(default=None, repr=False)

    @property
    def do_tilt(self) -> bool:
        """True if the kernel makes the appendix's tilt test before every rearrangement."""
        return self.tilt_at == "rearrangements"

    def tilt_ops(self) -> dict[str, Any]:
        """The arrays of the network tilt test (built on first use; 1D padded to 2D)."""
        if self._tilt_ops is None:
            self._tilt_ops = _tilt_operators(self.network)
        return self._tilt_ops

    @classmethod
    def from_config(cls, cfg: Config, network: Network | None = None) -> Scene:
        """Build the scene and pick its kernel (``solver.kernel = "auto"``)."""
        net = build_network(cfg) if network is None else network
        family, K, ops = _operators(net)
        catalogue = "events" in cfg.observables
        kernel = choose_kernel(cfg.solver.kernel, net.is_two_slider(), net.dim, catalogue)
        if kernel != family and not (kernel == "pair" and net.is_two_slider()):
            raise ConfigError(
                f"The 'solver.kernel' value {kernel!r} cannot run this network; use {family!r}."
            )
        tilt_at = None
        if "mu_eff" in cfg.observables:
            pair = pair_tilt_applies(net)
            tilt_at = cfg.mu_eff_at if cfg.mu_eff_at != "auto" else ("rearrangements" if pair else "records")
            if tilt_at == "rearrangements" and not pair:
                raise ConfigError(
                    "The 'mu_eff_at' field: the tilt test before every rearrangement (the appendix) "
                    "needs a 1D pair of sliders with unit normal loads and no f_ext; use 'records'."
                )
        return cls(
            network=net,
            distribution=cfg.distribution(),
            driver=cfg.driver_plugin(),
            driver_name=cfg.driver.name,
            distribution_name=cfg.friction.static.name,
            mu_d=cfg.friction.mu_d,
            steps=cfg.steps,
            rec_times=record_times(cfg.steps, cfg.record, cfg.log_points_per_decade),
            kernel=kernel,
            tilt_at=tilt_at,
            max_avalanche=cfg.solver.max_avalanche,
            batch=cfg.solver.batch,
            recompute_every=cfg.solver.recompute_every,
            slip_mode=1 if cfg.solver.slip == "exact" else 0,
            catalogue=catalogue,
            max_events=cfg.solver.max_events,
            ops=ops,
            K=K,
        )


def pair_tilt_applies(net: Network) -> bool:
    """True if the appendix's two-slider tilt test (``kernels.tilt_test_pair``) applies to ``net``.

    It is written for two sliders of unit normal load on a line, with no force
    but the spring's.
    """
    return (net.n_nodes == 2 and net.dim == 1 and bool((net.normal_load == 1.0).all())
            and not net.f_ext.any())


def _tilt_operators(net: Network) -> dict[str, Any]:
    """Block-CSR rows of K with 2 x 2 blocks (1D padded with zeros) for the network tilt test."""
    K = net.stiffness_blocks()
    indptr = K.indptr.astype(np.int64)
    indices = K.indices.astype(np.int64)
    blocks = np.zeros((indices.size, 2, 2))
    d = net.dim
    blocks[:, :d, :d] = K.data
    row = np.repeat(np.arange(net.n_nodes), np.diff(indptr))
    f_ext = np.zeros((net.n_nodes, 2))
    f_ext[:, :d] = net.f_ext
    return {
        "indptr": indptr,
        "indices": indices,
        "kblk": blocks,
        "diagpos": np.flatnonzero(indices == row).astype(np.int64),
        "f_ext": f_ext,
        "f_bar": float(f_ext[:, 0].sum() / net.normal_load.sum()),
        "pair_rule": net.n_nodes == 2 and d == 1,
    }


def tilt_avalanche_cap(n_nodes: int) -> int:
    """Slips of one tilt-test avalanche after which a part of the network slides alone (rule 4 of
    :mod:`slidernet.kernels.tilt_net`): 100 slips per node, and at least 1e5."""
    return max(100 * n_nodes, 100_000)
