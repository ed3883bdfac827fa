"""The scene: everything derived once from a configuration (network, operators, kernel choice, recorded times)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np
import scipy.sparse as sp

from slidernet.config import Config, InjectConfig, build_network, choose_kernel, choose_tilt_at
from slidernet.errors import ConfigError
from slidernet.kernels import Chain, Plane, Settings, tilt_net
from slidernet.kernels.assembly import diagonal_positions
from slidernet.model.network import Network
from slidernet.solver.creep import CreepSpec, reference_slip


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


def _operators(net: Network) -> tuple[str, Chain | Plane]:
    """The kernel family of a network and the operators the kernel runs on.

    1D: the CSR rows of K (:class:`~slidernet.kernels.state.Chain`). 2D:
    the block rows of its 2x2 blocks as ids into a table of blocks
    (:class:`~slidernet.kernels.state.Plane`; a lattice keeps each distinct
    block once, :meth:`Network.stiffness_table`).
    Entries of g below 1e-12 of its largest entry are set to exactly zero:
    in a uniform lattice the interior loads cancel up to rounding, and a
    node with g_i = 0 is never driven directly (it stays out of the driving
    heaps).
    """
    # Every part is checked finite before it is used (a NaN or inf g was zeroed by the rule above, and ran a
    # network that never moved): an overflow is judged by the part it struck, without numpy's warnings.
    with np.errstate(over="ignore", invalid="ignore"):
        if net.dim == 1:
            K = net.stiffness_matrix()
            _check_finite("K", K.data)
        else:
            indptr, indices, K_id, K_table = net.stiffness_table()
            _check_finite("K", K_table)
        g = net.thermal_load()
        _check_finite("g", g)
        _check_finite("w", net.normal_load.sum())
    gmax = np.abs(g).max() if g.size else 0.0
    g = np.where(np.abs(g) > 1e-12 * gmax, g, 0.0)
    normal_load = net.normal_load.astype(np.float64)
    w = net.normal_load / net.normal_load.sum()
    unit_load = bool((net.normal_load == 1.0).all())
    if net.dim == 1:
        return "csr", Chain(
            indptr=K.indptr.astype(np.int64),
            indices=K.indices.astype(np.int64),
            K_data=K.data.astype(np.float64),
            K_diag=K.diagonal().astype(np.float64),
            g=g.astype(np.float64),
            normal_load=normal_load,
            w=w,
            unit_load=unit_load,
        )
    return "vec", _plane(indptr, indices, K_id, K_table, g.reshape(-1, 2).astype(np.float64), normal_load, w,
                         unit_load)


#: The parts of a network's operators that overflow float64 in a scene it cannot hold: what each is made of,
#: and the keys of [network] that make it large (a graph's own values come from its file).
OPERATOR_PARTS = {
    "K": ("the stiffness matrix K", "its entries sum k e e^T over a node's springs", ("k",)),
    "g": ("the thermal load g", "it sums k L kappa over a node's springs", ("k", "kappa")),
    "w": ("the normal loads", "their sum weighs x_G", ("normal_load",)),
}


class _Overflow(Exception):
    """A part of a network's operators is not finite; ``part`` is its key in :data:`OPERATOR_PARTS` (turned
    into the ConfigError of :func:`_overflow_message`, which names the configuration's keys)."""

    def __init__(self, part: str) -> None:
        super().__init__(part)
        self.part = part


def _check_finite(part: str, values: np.ndarray | float) -> None:
    if not np.isfinite(values).all():
        raise _Overflow(part)


def _overflow_message(exc: _Overflow, cfg: Config) -> str:
    """The refusal of an overflow, naming the keys of the configuration that make the part large."""
    name, made, keys = OPERATOR_PARTS[exc.part]
    given = [f"'network.{key}'" for key in keys if getattr(cfg.network, key) is not None]
    if cfg.network.kind == "graph":
        given.append("the values of 'network.path'")
    cause = ", ".join(given) if given else "the network's values"
    return (f"This network's operators overflow float64: {name} holds inf or NaN ({made}), from {cause}. "
            f"Use smaller values (k enters the physics only as k / Ntilde: a smaller k with a smaller Ntilde "
            f"is the same scene).")


def _plane(indptr: np.ndarray, indices: np.ndarray, K_id: np.ndarray, K_table: np.ndarray, g: np.ndarray,
           normal_load: np.ndarray, w: np.ndarray, unit_load: bool) -> Plane:
    """The 2D operators from K's block rows (``indptr``, ``indices``) and their blocks ``K_table[K_id]``."""
    indptr = indptr.astype(np.int64, copy=False)
    indices = indices.astype(np.int32, copy=False)
    K_id = K_id.astype(np.int32, copy=False)
    per_entry = K_table.shape[0] == K_id.size and bool((K_id == np.arange(K_id.size)).all())
    diag = diagonal_positions(indptr, indices)
    if diag.size and diag.min() < 0:
        # The kernels read K_ii at diag[i] without a sign test (kernels.state.nonneg).
        raise ValueError(f"row {int(np.argmin(diag))} of K has no diagonal block")
    return Plane(indptr=indptr, indices=indices, K_id=K_id, K_table=K_table,
                 diag=diag, g=g, normal_load=normal_load, w=w, unit_load=unit_load,
                 block_per_entry=per_entry)


def stiffness_matrix(operators: Chain | Plane) -> sp.csr_matrix | sp.bsr_matrix:
    """K as a scipy.sparse matrix from a kernel's operators (CSR in 1D, 2 x 2 blocks in 2D).

    For checks and inspection: in 2D it writes out one block per entry,
    which the kernels never need (224 MB at a million nodes).
    """
    n = operators.indptr.size - 1
    if isinstance(operators, Chain):
        return sp.csr_matrix((operators.K_data, operators.indices, operators.indptr), shape=(n, n))
    return sp.bsr_matrix((operators.K_table[operators.K_id], operators.indices, operators.indptr),
                         shape=(2 * n, 2 * n))


# Scene.slip_mode: the 2D slip along a straight line, or the exactly integrated 2D motion (solver.slip).
SLIP_STRAIGHT = 0
SLIP_EXACT = 1

#: At most this many draws wait in the buffers of a scene whose 2D slips are integrated exactly: the kernel
#: returns to Python at every refill, and only there is a stop request (Ctrl-C, SIGTERM) seen. Such a slip
#: costs about 0.3 ms (an irregular network of 16, 2026-11-28), and up to a few tenths of a second under a
#: huge drive, where 65 536 slips between two refills (the default solver.batch) kept one SIGTERM from
#: stopping a run for minutes; 32 cost 1-4 % of the run's time there. No result depends on the batch.
EXACT_SLIP_BATCH = 32


class TiltOperators(NamedTuple):
    """What the network tilt test runs on (:func:`slidernet.kernels.tilt_net.tilt_test_network`)."""

    net: Plane  # block-CSR rows of K with 2 x 2 blocks, 1D padded with zeros
    f_ext: np.ndarray  # (N, 2) external forces, in N
    f_bar: float  # sum_i f_ext,i,x / sum_i N_i
    pair_rule: bool  # the appendix's creep rule applies (a 1D pair)
    test: Callable[..., float]  # the compiled test of the scene's slip rule (tilt_test_network or its _exact)


class ShsOperators(NamedTuple):
    """What the slide-hold-slide pull runs on (:func:`slidernet.kernels.tilt_net.shs_test_network`)."""

    net: Plane  # the tilt test's operators with each node's pull spring, gamma <k> N_i, in its K_ii along x
    f_ext: np.ndarray  # (N, 2) external forces, in N
    f_bar: float  # sum_i f_ext,i,x / sum_i N_i
    pull: float  # gamma <k>, in k0 per unit normal load: the stage's load per unit normal load is pull (X - U)
    test: Callable[..., float]  # the compiled pull of the scene's slip rule (shs_test_network or its _exact)


#: The inertial solver's kernel of each dimension (a scene with [dynamics] runs on it, whatever the network).
INERTIAL_KERNELS = {1: "inertia", 2: "inertia_2d"}


class Dynamics(NamedTuple):
    """The ``[dynamics]`` table as the inertial solver takes it."""

    tau_ratio: float  # tau_dyn / tau_th
    rtol: float  # 2D: relative error per step
    max_step: float  # 2D: longest step, tau_dyn
    tilt_rate: float | None = None  # the dynamic tilt test's ramp, per tau_dyn; None: the quasi-static test


@dataclass
class Scene:
    """Everything a realization needs, derived once from a :class:`Config`.

    Attributes
    ----------
    kernel : {"pair", "csr", "vec", "inertia", "inertia_2d"}
        The specialized kernel picked for this scene: ``pair`` for the
        paper's two sliders, ``csr`` for other 1D networks, ``vec`` in 2D;
        with ``[dynamics]``, the inertial solver's ``inertia`` (1D, the pair
        included) or ``inertia_2d``.
    operators : Chain or Plane
        The network's operators the kernels run on (see ``_operators``).
    K : scipy.sparse matrix
        The stiffness matrix (a property, built from ``operators`` on first use).
    slide_away : bool
        The mean load along x per unit normal load, :func:`mean_load`,
        exceeds mu_d: a realization can slide away, and the kernels watch for it.
    records_slide : bool
        The result has ``slid_away_at``: with ``slide_away``, and on any incline.
    """

    network: Network
    distribution: Any
    driver: Any
    driver_name: str
    distribution_name: str
    mu_d: float
    steps: int
    out_steps: np.ndarray
    kernel: str
    tilt_at: str | None
    max_avalanche: int
    batch: int
    recompute_every: int
    slip_mode: int  # SLIP_STRAIGHT or SLIP_EXACT (solver.slip)
    catalogue: bool = False  # the kernel keeps the event catalogue (for 'events' or 'creep')
    tilt_loads: bool = False  # the network tilt tests record their loads (kernels.tilt_net.TILT_LOADS)
    max_events: int = 0
    contact_age: bool = False  # the network kernel keeps each node's last slip time (observable 'contact_age')
    # friction.strengthening as the kernels take it, (beta, tau_c, exponent; 0: the log law); None: off
    strengthening: tuple[float, float, float] | None = None
    keep_events: bool = True  # the catalogue's rows go into the result (observable 'events')
    creep: CreepSpec | None = None  # the creep observables' settings (observable 'creep')
    slide_away: bool = False
    records_slide: bool = False
    slip_factor: float = 2.0  # 1 + friction.overshoot: a slip's length over (|F_i| - mu_d N_i) / K_ii
    tilt_min_slips: int = 1  # the network tilt test's sliding rule (the [tilt] table)
    tilt_min_shift: float = 0.0  # ... and the centre of mass's displacement it needs, in Ntilde l0
    shs_stiffness: float | None = None  # [shs] stiffness gamma with the observable mu_shs; None: no pull
    tilt_repeats: int = 1  # network tilt tests per recorded time ([tilt] repeats)
    inject: InjectConfig | None = None  # the aging injected into the tested copy ([tilt] inject); None: none
    operators: Chain | Plane | None = None
    dynamics: Dynamics | None = None  # [dynamics]: the inertial solver's settings; None: quasi-static
    _tilt_operators: TiltOperators | None = field(default=None, repr=False)
    _shs_operators: ShsOperators | None = field(default=None, repr=False)
    _K: Any = field(default=None, repr=False)

    @property
    def K(self) -> sp.csr_matrix | sp.bsr_matrix:
        """The stiffness matrix as a scipy.sparse matrix (built on first use; see :func:`stiffness_matrix`)."""
        if self._K is None:
            self._K = stiffness_matrix(self.operators)
        return self._K

    @property
    def counts_capped(self) -> bool:
        """True if the network tilt test asks more than the default sliding rule ([tilt]): its tests that meet
        the avalanche cap before the rule (rule 4 of :mod:`slidernet.kernels.tilt_net`) are counted in
        ``tilt_capped``, not sampled. Under the default rule that cap's sample is the rule's own (a part
        sliding alone above mu_d)."""
        return self.tilt_at == "records" and (self.tilt_min_slips > 1 or self.tilt_min_shift > 0.0)

    @property
    def keeps_ages(self) -> bool:
        """True if the network kernel keeps each node's last slip time: for the observable 'contact_age',
        strengthening contacts, or an injection into the oldest contacts (``[tilt] inject``, select < 1)."""
        return (self.contact_age or self.strengthening is not None
                or (self.inject is not None and self.inject.select < 1.0))

    @property
    def do_tilt(self) -> bool:
        """True if the kernel makes the appendix's tilt test before every rearrangement."""
        return self.tilt_at == "rearrangements"

    def tilt_operators(self) -> TiltOperators:
        """The operators of the network tilt test (built on first use; 1D padded to 2D)."""
        if self._tilt_operators is None:
            self._tilt_operators = _tilt_operators(self.network, self.operators, self.slip_mode)
        return self._tilt_operators

    def shs_operators(self) -> ShsOperators:
        """The operators of the slide-hold-slide pull (built on first use): the tilt test's, with the pull
        springs."""
        if self._shs_operators is None:
            self._shs_operators = _shs_operators(self.network, self.tilt_operators(), float(self.shs_stiffness),
                                                 self.slip_mode)
        return self._shs_operators

    def settings(self) -> Settings:
        """The run's constants, as the kernels take them."""
        return Settings(mu_d=float(self.mu_d), max_slips=int(self.max_avalanche),
                        recompute_every=int(self.recompute_every), slide_away=bool(self.slide_away),
                        slip_factor=float(self.slip_factor), tilt_min_slips=int(self.tilt_min_slips),
                        tilt_min_shift=float(self.tilt_min_shift))

    @classmethod
    def from_config(cls, cfg: Config, network: Network | None = None) -> Scene:
        """Build the scene and pick its kernel (``solver.kernel = "auto"``)."""
        net = build_network(cfg) if network is None else network
        try:
            family, operators = _operators(net)
        except _Overflow as exc:
            raise ConfigError(_overflow_message(exc, cfg)) from None
        catalogue = cfg.needs_catalogue()
        two_slider = net.is_two_slider()
        kernel = choose_kernel(cfg.solver.kernel, two_slider, net.dim, cfg.needs_node_state())
        dyn = cfg.dynamics
        if dyn is not None:
            kernel = INERTIAL_KERNELS[net.dim]
            if mean_load(net) > cfg.friction.mu_d:
                raise ConfigError(
                    f"With [dynamics] (the inertial solver) the load along x per unit normal load "
                    f"({mean_load(net)!r}) must not exceed mu_d = {cfg.friction.mu_d!r}: the network would slide "
                    "away, which only the quasi-static solver records.")
        elif kernel != family and not (kernel == "pair" and two_slider):
            raise ConfigError(
                f"The 'solver.kernel' value {kernel!r} cannot run this network; use {family!r}."
            )
        tilt_at = None
        if "mu_eff" in cfg.observables:
            try:
                tilt_at = choose_tilt_at(cfg.mu_eff_at, cfg.pair_tilt_applies(net))
            except ValueError as exc:  # a network given here that the configuration's checks never saw
                raise ConfigError(f"The 'mu_eff_at' field: {exc}.") from None
        slide_away = mean_load(net) > cfg.friction.mu_d
        tilt = cfg.tilt_settings()
        min_shift = 0.0
        if tilt_at == "records":
            check_tilt_rule(tilt.min_slips, tilt.min_displacement, net.normal_load, cfg.solver.max_avalanche)
        if tilt.min_displacement > 0.0:
            # In mean slip lengths of one slider held by one spring (the creep observables' reference slip),
            # given to the kernel in its lengths, Ntilde l0.
            min_shift = tilt.min_displacement * reference_slip(
                float(cfg.distribution().mean_max(1)), cfg.friction.mu_d, net.normal_load, net.k, 1.0,
                cfg.friction.slip_factor())
        scene = cls(
            network=net,
            distribution=cfg.distribution(),
            driver=cfg.driver_plugin(),
            driver_name=cfg.driver.name,
            distribution_name=cfg.friction.static.name,
            mu_d=cfg.friction.mu_d,
            steps=cfg.steps,
            out_steps=record_times(cfg.steps, cfg.record, cfg.log_points_per_decade),
            kernel=kernel,
            tilt_at=tilt_at,
            tilt_loads="tilt_loads" in cfg.observables and tilt_at == "records",
            max_avalanche=cfg.solver.max_avalanche,
            batch=(min(cfg.solver.batch, EXACT_SLIP_BATCH) if cfg.solver.slip == "exact" and net.dim == 2
                   else cfg.solver.batch),
            recompute_every=cfg.solver.recompute_every,
            slip_mode=SLIP_EXACT if cfg.solver.slip == "exact" else SLIP_STRAIGHT,
            catalogue=catalogue,
            contact_age="contact_age" in cfg.observables,
            strengthening=(None if cfg.friction.strengthening is None
                           else cfg.friction.strengthening.constants()),
            max_events=cfg.solver.max_events,
            keep_events="events" in cfg.observables,
            creep=creep_spec(cfg, net) if "creep" in cfg.observables else None,
            slide_away=slide_away,
            records_slide=slide_away or cfg.network.incline is not None,
            slip_factor=cfg.friction.slip_factor(),
            tilt_min_slips=tilt.min_slips,
            tilt_min_shift=min_shift,
            tilt_repeats=tilt.repeats if tilt_at == "records" else 1,
            # Where a test it raises runs (Config.injected_tests, the one rule).
            inject=tilt.inject if cfg.injected_tests() else None,
            shs_stiffness=cfg.shs_settings().stiffness if "mu_shs" in cfg.observables else None,
            operators=operators,
            dynamics=None if dyn is None else Dynamics(float(dyn.tau_ratio), float(dyn.rtol), float(dyn.max_step),
                                                 None if dyn.tilt_rate is None else float(dyn.tilt_rate)),
        )
        if scene.shs_stiffness is not None:
            scene.shs_operators()  # built now: pull springs that float64 cannot hold are refused before any work
        return scene


def creep_spec(cfg: Config, net: Network) -> CreepSpec:
    """The creep observables' settings: the driver's period, the transient, the reference slip and threshold."""
    settings = cfg.creep_settings()
    try:
        mu_s_mean = float(cfg.distribution().mean_max(1))
    except Exception as exc:  # a plugin law without the quantile functions the mean is integrated from
        raise ConfigError(
            f"The 'creep' observable needs the mean of p(mu_s) for its reference slip, and the distribution "
            f"{cfg.friction.static.name!r} gives none: {exc}"
        ) from None
    slip = reference_slip(mu_s_mean, cfg.friction.mu_d, net.normal_load, net.k, net.Ntilde,
                          cfg.friction.slip_factor())
    period = getattr(cfg.driver_plugin(), "period", None)
    return CreepSpec(period=None if period is None else float(period), transient=float(settings.transient),
                     slip=slip, threshold=settings.event_fraction * slip,
                     weights=(net.normal_load / net.normal_load.sum()).astype(np.float64))


def mean_load(net: Network) -> float:
    """f_bar = sum_i f_ext,i,x / sum_i N_i: the load along x per unit normal load (tan(incline) on an incline).

    Above mu_d, an avalanche that sets every node in motion is the network
    sliding away (docs/model.md, 'Sliding away').

    >>> from slidernet.model.network import chain
    >>> round(mean_load(chain(3, Ntilde=1e-7, normal_load=2.0, f_ext=1.1)), 12)
    0.55
    """
    return float(net.f_ext[:, 0].sum() / net.normal_load.sum())


def _tilt_operators(net: Network, operators: Chain | Plane, slip_mode: int) -> TiltOperators:
    """K's block rows with 2 x 2 blocks for the network tilt test: in 2D the scene's own, in 1D
    padded with zeros; no thermal load (the test holds theta fixed). The test's compiled variant
    follows the slip rule: 1D slips are straight lines."""
    d = net.dim
    N = net.n_nodes
    normal_load = net.normal_load.astype(np.float64)
    if d == 2:
        plane = operators._replace(g=np.zeros((N, 2)))
    else:
        indptr, indices, K_id, K_table = net.stiffness_table()
        blocks = np.zeros((K_table.shape[0], 2, 2))
        blocks[:, :1, :1] = K_table
        plane = _plane(indptr, indices, K_id, blocks, np.zeros((N, 2)), normal_load,
                       normal_load / normal_load.sum(), bool((normal_load == 1.0).all()))
    f_ext = np.zeros((N, 2))
    f_ext[:, :d] = net.f_ext
    test = tilt_net.tilt_test_network_exact if slip_mode == SLIP_EXACT else tilt_net.tilt_test_network
    return TiltOperators(net=plane, f_ext=f_ext, f_bar=mean_load(net), pair_rule=N == 2 and d == 1, test=test)


def _shs_operators(net: Network, tilt: TiltOperators, stiffness: float, slip_mode: int) -> ShsOperators:
    """The tilt test's operators with every node's pull spring gamma <k> N_i added to its K_ii along x.

    A lattice keeps its table of distinct blocks: the diagonal blocks with their pull springs are added to
    it, each distinct one once (a few with equal normal loads). Any other network has a block per entry and
    gets its own copy.
    """
    plane = tilt.net
    pull = stiffness * float(np.mean(net.k))
    spring = pull * plane.normal_load
    diagonal_xx = plane.K_table[:, 0, 0] + spring.max()
    if not spring.min() >= np.finfo(np.float64).tiny or not np.isfinite(diagonal_xx).all():
        # A zero pull would be the tilt test's (the kernel's pull = 0); a subnormal one, or one that overflows
        # K_ii, leaves no digits to the slips or the stage's travel f / pull.
        raise ConfigError(
            f"The 'shs.stiffness' value {stiffness!r} gives pull springs gamma <k> N_i from "
            f"{float(spring.min())!r} to {float(spring.max())!r} k0 (<k> = {float(np.mean(net.k))!r}), which "
            f"float64 cannot hold beside the network's springs; use a stiffness nearer 1.")
    table = plane.K_table.copy()
    K_id = plane.K_id.copy()
    if plane.block_per_entry:
        table[plane.diag, 0, 0] += spring
    else:
        diagonal = table[K_id[plane.diag]]
        diagonal[:, 0, 0] += spring
        blocks, which = np.unique(diagonal, axis=0, return_inverse=True)
        K_id[plane.diag] = table.shape[0] + which.reshape(-1)
        table = np.concatenate([table, blocks])
    test = tilt_net.shs_test_network_exact if slip_mode == SLIP_EXACT else tilt_net.shs_test_network
    return ShsOperators(net=plane._replace(K_table=table, K_id=K_id), f_ext=tilt.f_ext, f_bar=tilt.f_bar,
                        pull=pull, test=test)


def tilt_avalanche_cap(n_nodes: int) -> int:
    """Slips of one tilt-test avalanche after which a part of the network slides alone (rule 4 of
    :mod:`slidernet.kernels.tilt_net`): 100 slips per node, and at least 1e5."""
    return max(100 * n_nodes, 100_000)


def check_tilt_rule(min_slips: int, min_displacement: float, normal_load: np.ndarray, max_avalanche: int) -> None:
    """Refuse a sliding rule ([tilt]) that the network tilt test's caps cannot let it meet, naming both numbers.

    The rule is met within one avalanche, which ends at :func:`tilt_avalanche_cap` slips (rule 4) and
    whose test ends at ``solver.max_avalanche`` slips in all. ``min_slips = m`` needs at least
    N (m - 1) + 1 slips (every node slipped m times, or m - 1 and about to slip again);
    ``min_displacement = X`` about X / max_i w_i (X N with equal normal loads): a slip of node i moves
    the centre of mass by about w_i mean slip lengths, w_i = N_i / sum N. A rule nearer a cap is left
    to the run, which counts the tests that met the cap first (``tilt_capped``).

    >>> check_tilt_rule(3, 0.0, np.ones(6), 10**8)
    >>> check_tilt_rule(20_000, 0.0, np.ones(6), 10**8)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    slidernet.errors.ConfigError: The [tilt] table asks each of the 6 sliders to slip min_slips = 20000 ...
    """
    n_nodes = int(normal_load.size)
    cap = tilt_avalanche_cap(n_nodes)
    caps = sorted([(cap, f"the {cap} slips after which the network tilt test takes a part of the network to "
                         f"slide on its own (max(100 N, 1e5))"),
                   (max_avalanche, f"solver.max_avalanche = {max_avalanche}, the slips of a whole test")])
    limit, what = caps[0]
    needed = n_nodes * (min_slips - 1) + 1
    if needed > limit:
        raise ConfigError(
            f"The [tilt] table asks each of the {n_nodes} sliders to slip min_slips = {min_slips} times in one "
            f"avalanche: at least {n_nodes} x {min_slips - 1} + 1 = {needed} slips, more than {what}. Ask fewer."
        )
    share = float(normal_load.max() / normal_load.sum())
    estimate = min_displacement / share
    if estimate > limit:
        raise ConfigError(
            f"The [tilt] table asks the centre of mass to move by min_displacement = {min_displacement:g} mean "
            f"slip lengths in one avalanche: about {estimate:.3g} slips (a slip of a slider moves it by about "
            f"its share N_i / sum N <= {share:.3g} of a slip length), more than {what}. Ask less."
        )
