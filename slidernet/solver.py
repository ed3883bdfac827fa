"""The quasi-static, event-driven solver: from a validated config to raw records.

Data flow for one realization (see ARCHITECTURE.md)::

    SeedSequence child r --spawn(3)--> [driver, thresholds, tilt]
    driver.thetas(rng_driver, steps)      -> theta(t_q), q = 0..steps
    dist.sample(rng_thresholds, N)        -> initial mu_s, then batches
    kernel (pair or csr) over the thetas  -> records at the recorded times

No time stepping: within each linear segment of theta the kernel jumps from
one rearrangement to the next by solving eq. `critique` exactly.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from slidernet import kernels
from slidernet.config import Config
from slidernet.errors import AvalancheError, TiltTestError
from slidernet.network import Network, chain, two_slider
from slidernet.registry import checked_output


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


def build_network(cfg: Config) -> Network:
    """The network of the configured scene."""
    if cfg.network.kind == "two_slider":
        return two_slider(cfg.network.Ntilde)
    return chain(cfg.network.n, Ntilde=cfg.network.Ntilde)


@dataclass
class Scene:
    """Everything a realization needs, derived once from a :class:`Config`.

    Attributes
    ----------
    kernel : {"pair", "csr"}
        The specialized kernel picked for this scene.
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
    do_tilt: bool
    max_avalanche: int
    batch: int
    csr: dict[str, np.ndarray] = field(default_factory=dict)

    @classmethod
    def from_config(cls, cfg: Config) -> Scene:
        """Build the scene and pick its kernel (``solver.kernel = "auto"``)."""
        net = build_network(cfg)
        kernel = cfg.solver.kernel
        if kernel == "auto":
            kernel = "pair" if net.is_two_slider() else "csr"
        K = net.stiffness_matrix()
        g = net.thermal_load()
        csr = {
            "indptr": K.indptr.astype(np.int64),
            "indices": K.indices.astype(np.int64),
            "kdata": K.data.astype(np.float64),
            "kdiag": K.diagonal().astype(np.float64),
            "g": g.astype(np.float64),
            "normal_load": net.normal_load.copy(),
            "w": net.normal_load / net.normal_load.sum(),
            "driven": np.flatnonzero(g != 0).astype(np.int64),
        }
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
            do_tilt="mu_eff" in cfg.observables,
            max_avalanche=cfg.solver.max_avalanche,
            batch=cfg.solver.batch,
            csr=csr,
        )


def realization_streams(seed_seq: np.random.SeedSequence) -> dict[str, np.random.Generator]:
    """The three independent streams of one realization, in their documented order.

    ``seed_seq.spawn(3)`` gives, in order: the driver, the thresholds of the
    horizontal evolution, and the virtual tilt test. The tilt test never
    touches the other two, so requesting ``mu_eff`` leaves n, mu_max and x_G
    unchanged to the bit.
    """
    names = ("driver", "thresholds", "tilt")
    return {
        name: np.random.Generator(np.random.PCG64(child))
        for name, child in zip(names, seed_seq.spawn(3), strict=True)
    }


def draw_thetas(scene: Scene, rng: np.random.Generator) -> np.ndarray:
    """theta(t_q) from the driver plugin, checked: shape (steps + 1,), finite."""
    thetas = checked_output(scene.driver.thetas(rng, scene.steps), (scene.steps + 1,), "driver",
                            scene.driver_name, f"thetas(rng, {scene.steps})")
    return thetas


def _refill(buf: np.ndarray, pos: int, draw: Callable[[int], np.ndarray], batch: int) -> np.ndarray:
    """``buf`` from ``pos`` on, topped up with a new batch when fewer than ``batch`` remain.

    Keeping the unread tail makes the stream of draws the same whatever
    point the kernel stopped at. A buffer that still holds a batch is left
    alone: refilling it anyway would make it grow without bound (the tilt
    test's uniforms are read only in its rare creep branch).
    """
    if buf.size - pos >= batch:
        return buf[pos:]
    return np.concatenate([buf[pos:], draw(batch)])


class Realization:
    """One realization: its random streams, its state and its records.

    Constructing it draws theta(t_q) and the initial thresholds; work happens
    in :meth:`advance`. Between calls the state is fully relaxed (every node
    stable), which the property tests check through :meth:`forces`.

    Parameters
    ----------
    scene : Scene
        The scene, shared by all realizations.
    seed_seq : numpy.random.SeedSequence
        This realization's own seed (a child of the run's seed).
    """

    def __init__(self, scene: Scene, seed_seq: np.random.SeedSequence) -> None:
        self.scene = scene
        self.rngs = realization_streams(seed_seq)
        net = scene.network
        self.thetas = draw_thetas(scene, self.rngs["driver"]) / net.Ntilde
        dist = scene.distribution
        self.mu = dist.sample(self.rngs["thresholds"], net.n_nodes).astype(np.float64)
        self.mu_buf = dist.sample(self.rngs["thresholds"], scene.batch)
        if scene.do_tilt:
            self.tmu = dist.sample(self.rngs["tilt"], scene.batch)
            self.tu = self.rngs["tilt"].random(scene.batch)
        else:
            self.tmu = np.empty(0)
            self.tu = np.empty(0)
        T = scene.rec_times.size
        self.out = {
            "n": np.zeros(T, np.int64),
            "mu_max": np.zeros(T),
            "x_G": np.zeros(T),
            "n_records": np.zeros(T, np.int64),
            "f_sum": np.zeros(T),
            "f_sq": np.zeros(T),
            "f_count": np.zeros(T, np.int64),
        }
        self.ist, self.fst = kernels.empty_state()
        self.fst[kernels.THETA] = self.thetas[0]
        self.fst[kernels.U] = self.thetas[0]  # the spring at rest at theta(0): u = theta(0)
        self.fst[kernels.MU_MAX] = self.mu.max()
        self.ist[kernels.ARGMAX] = int(np.argmax(self.mu))
        if scene.kernel == "csr":
            # a = F - theta g with u = 0: every spring at rest at theta(0).
            self.a = -scene.csr["g"] * self.thetas[0]
            self.u = np.zeros(net.n_nodes)
            self.heap = np.zeros(net.n_nodes, np.int64)
            self.pos = np.full(net.n_nodes, -1, np.int64)
            self.key = np.zeros(net.n_nodes)

    @property
    def step(self) -> int:
        """The number of thermal steps done so far."""
        return int(self.ist[kernels.Q])

    @property
    def n(self) -> int:
        """Cumulative number of rearrangements."""
        return int(self.ist[kernels.N_SLIPS])

    @property
    def thresholds(self) -> np.ndarray:
        """Current mu_s of every node, shape (N,)."""
        return self.mu.copy()

    @property
    def theta(self) -> float:
        """Current dilation theta (dimensionless)."""
        return float(self.fst[kernels.THETA] * self.scene.network.Ntilde)

    @property
    def x_G(self) -> float:
        """Current centre-of-mass displacement, in l0."""
        return float(self.fst[kernels.XG] * self.scene.network.Ntilde)

    def forces(self) -> np.ndarray:
        """Spring forces on every node, in units of N, shape (N,)."""
        theta = self.fst[kernels.THETA]
        if self.scene.kernel == "pair":
            F = theta - self.fst[kernels.U]
            return np.array([-F, F])
        return self.a + self.scene.csr["g"] * theta

    def _call_kernel(self, thetas: np.ndarray) -> int:
        sc, c, out = self.scene, self.scene.csr, self.out
        if sc.kernel == "pair":
            return kernels.run_pair(
                thetas, sc.rec_times, self.mu, self.ist, self.fst, self.mu_buf, self.tmu,
                self.tu, sc.mu_d, sc.do_tilt, sc.max_avalanche, out["n"], out["mu_max"],
                out["x_G"], out["n_records"], out["f_sum"], out["f_sq"], out["f_count"],
            )
        return kernels.run_csr(
            thetas, sc.rec_times, self.mu, self.ist, self.fst, self.a, self.u, self.mu_buf,
            self.tmu, self.tu, sc.mu_d, sc.do_tilt, sc.max_avalanche, c["indptr"],
            c["indices"], c["kdata"], c["kdiag"], c["g"], c["normal_load"], c["w"],
            c["driven"], self.heap, self.pos, self.key, out["n"], out["mu_max"], out["x_G"],
            out["n_records"], out["f_sum"], out["f_sq"], out["f_count"],
        )

    def advance(self, to_step: int | None = None) -> Realization:
        """Run the thermal steps up to ``to_step`` (default: the last one)."""
        sc = self.scene
        to_step = sc.steps if to_step is None else int(to_step)
        if not self.step <= to_step <= sc.steps:
            raise ValueError(f"to_step must lie in [{self.step}, {sc.steps}]; got {to_step}")
        # The kernel stops at the end of the array it is given.
        thetas = self.thetas[: to_step + 1]
        dist = sc.distribution
        ist = self.ist

        def draw_mu(size: int) -> np.ndarray:
            return dist.sample(self.rngs["thresholds"], size)

        def draw_tmu(size: int) -> np.ndarray:
            return dist.sample(self.rngs["tilt"], size)

        while True:
            status = self._call_kernel(thetas)
            if status == kernels.DONE:
                return self
            if status == kernels.NEED_MU:
                self.mu_buf = _refill(self.mu_buf, ist[kernels.MU_POS], draw_mu, sc.batch)
                ist[kernels.MU_POS] = 0
            elif status == kernels.NEED_TILT:
                self.tmu = _refill(self.tmu, ist[kernels.TMU_POS], draw_tmu, sc.batch)
                self.tu = _refill(self.tu, ist[kernels.TU_POS], self.rngs["tilt"].random, sc.batch)
                ist[kernels.TMU_POS] = 0
                ist[kernels.TU_POS] = 0
            elif status == kernels.AVALANCHE_LIMIT:
                i = int(ist[kernels.ERR_NODE])
                raise AvalancheError(
                    f"An avalanche did not end after {sc.max_avalanche} slips "
                    f"(solver.max_avalanche) during step {ist[kernels.Q]}: node {i} is still "
                    f"unstable with F = {float(self.forces()[i])!r} N, "
                    f"mu_s = {float(self.mu[i])!r}, theta = {self.theta!r}."
                )
            elif status == kernels.TILT_LIMIT:
                raise TiltTestError(
                    f"The tilt test did not reach sliding within {kernels.TILT_MAX_ITER} "
                    f"iterations at step {ist[kernels.Q]}."
                )
            else:  # pragma: no cover - a new status code without a handler is a bug
                raise RuntimeError(f"unknown kernel status {status}")

    def result(self) -> dict[str, np.ndarray]:
        """The records at ``scene.rec_times`` (x_G converted to l0).

        Returns
        -------
        dict of str to ndarray
            ``n``, ``n_records`` (int64), ``mu_max``, ``x_G`` (in l0) of shape
            (T,), the tilt-test sums ``f_sum``, ``f_sq``, ``f_count`` per
            record bin, shape (T,), and the scalar ``n_events``.
        """
        res = {k: v.copy() for k, v in self.out.items()}
        res["x_G"] *= self.scene.network.Ntilde
        res["n_events"] = np.int64(self.ist[kernels.N_EVENTS])
        return res


def simulate(scene: Scene, seed_seq: np.random.SeedSequence) -> dict[str, np.ndarray]:
    """Run one whole realization; see :meth:`Realization.result` for the records."""
    return Realization(scene, seed_seq).advance().result()
