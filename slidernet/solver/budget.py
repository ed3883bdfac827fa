"""What a run will cost, known before it starts: its memory, whether float64 can resolve it, its time.

Three checks that :func:`slidernet.run` (and ``slidernet sweep``) make before
any work, each from the configuration and, for the last two, the scene:

- :func:`memory_estimate` and :func:`check_memory`: the bytes the run will
  hold, from the configuration alone (before the network is built, which
  may itself not fit), against the machine's memory (:func:`machine_memory`);
  a run that cannot fit is refused with :class:`~slidernet.errors.SizeError`.
- :func:`check_precision`: the forces of the kernels are sums of terms of
  size |g_i| |theta| / Ntilde; where their rounding reaches 1/64 of the gap
  mu_s - mu_d that a slip works across, the run is refused with
  :class:`~slidernet.errors.PrecisionError`, naming the parameter that makes
  the terms large or the gap small.
- :func:`slips_per_tau` and :func:`warn_if_slow`: the slips of one thermal
  step, followed from the driven nodes through the network, give the slips
  per tau_th; at a stated rate of slips per second, a run that would take more than an hour gets one
  :class:`~slidernet.errors.SlowRunWarning`, with the estimate.

Every constant below was measured on the project's 2-core dev machine; the
command is given with it, and the ensembles guide (docs/guides/ensembles-and-hpc.md,
"Before a run") gives the figures and the estimates' errors.
"""

from __future__ import annotations

import math
import os
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from slidernet.config import Config
from slidernet.errors import PrecisionError, SizeError, SlowRunWarning
from slidernet.solver.backends import BACKENDS
from slidernet.solver.scene import Scene, record_times
from slidernet.solver.streams import draw_thetas

# ---------------------------------------------------------------------------
# memory

#: Bytes per node of the scene, by kind of network: the peak of building the network, K and g, measured by
#: ``python benchmarks/memory_budget.py`` as the growth of the peak resident memory between two sizes (chains
#: of 2e5 and 2e6 nodes, lattices of 2e5 and 2e6, irregular networks of 1e5 and 1e6). A graph file counts as
#: an irregular network (its reading through networkx comes on top).
SCENE_BYTES = {"two_slider": 240.0, "chain": 240.0, "square": 128.0, "triangular": 144.0, "irregular": 793.0,
               "graph": 793.0}
#: Bytes per node of one realization's state (forces, displacements, thresholds, heaps), the same command
#: (lattices of 2e5 and 2e6 nodes, two realizations).
STATE_BYTES = 46.0
#: Bytes per thermal step of a running realization: theta(t_q), drawn for the whole run at once (8 bytes
#: a step; the same command).
THETA_BYTES = 9.0
#: Bytes per value of a draw buffer (``solver.batch`` values each: the thresholds', with tilt tests the tilt
#: thresholds' and uniforms', with ``mu_shs`` the pull's thresholds'), measured by the peak resident memory
#: of one realization of a chain of 8 with solver.batch = 2^22 and 2^25: 8.0 bytes per value and buffer
#: (24.0 with the tilt tests' two more).
DRAW_BYTES = 8.0
#: Bytes per realization and recorded time of the records held (n, mu_max, x_G, the tilt sums, the network's
#: series, and the dataset assembled from them), the same command (record = "all", 2e5 and 2e6 steps).
RECORD_BYTES = 216.0
#: Bytes per realization of the ensemble's bookkeeping (its task, its record's arrays and their dataset),
#: held in memory (False) or with an output folder (True), the same command (2e3 and 1e4 realizations).
REALIZATION_BYTES = {False: 7200.0, True: 5000.0}
#: Realizations an output folder holds at once before writing them (``slidernet.analysis.observables.CHUNK``).
STREAMED = 1024


@dataclass(frozen=True)
class MemoryEstimate:
    """The bytes a run will hold at its peak, by part (each a lower bound: Python's own objects come on top).

    Attributes
    ----------
    network : float
        The scene: network, K, g (built once; local workers share it).
    running : float
        The realizations running at once, one per worker: their state and theta(t_q).
    records : float
        The records held: every realization's in memory, ``STREAMED`` at a time with an output folder.
    ensemble : float
        The bookkeeping of every realization of the run.
    what : dict of str to str
        For each part, what makes it large, in words, with the configuration keys to change.
    """

    network: float
    running: float
    records: float
    ensemble: float
    what: dict[str, str]

    @property
    def total(self) -> float:
        """The whole estimate, bytes."""
        return self.network + self.running + self.records + self.ensemble

    def largest(self) -> str:
        """The name of the largest part."""
        parts = {"network": self.network, "running": self.running, "records": self.records,
                 "ensemble": self.ensemble}
        return max(parts, key=parts.__getitem__)


def network_size(cfg: Config) -> int:
    """The number of sliders of the configured network, known without building it (a graph file is read)."""
    size = cfg.network.size()
    if size is None:  # a graph: its file says
        size = cfg.network.build().n_nodes
    return int(size)


def recorded_times(cfg: Config) -> int:
    """How many times a realization records, without listing them (``record = "all"``: steps + 1)."""
    if cfg.record == "all":
        return cfg.steps + 1
    return int(record_times(cfg.steps, cfg.record, cfg.log_points_per_decade).size)


def memory_estimate(cfg: Config, workers: int = 1, *, streamed: bool = False) -> MemoryEstimate:
    """The memory a run of ``cfg`` will hold at its peak, from the configuration alone.

    Parameters
    ----------
    cfg : Config
        The run.
    workers : int
        Realizations running at once (local worker processes; 1 in process).
    streamed : bool
        The records go to an output folder, ``STREAMED`` realizations at a time,
        instead of staying in memory.

    Returns
    -------
    MemoryEstimate
        Bytes by part. The constants are this module's (measured); the event
        catalogue's rows are not counted (their number is known only after
        the run; at most ``solver.max_events`` per realization).

    Examples
    --------
    >>> from slidernet.config import load_config
    >>> cfg = load_config({"steps": 10**6, "realizations": 100, "record": "all",
    ...                    "network": {"kind": "chain", "n": 1000, "Ntilde": 1e-7},
    ...                    "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
    ...                    "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6}})
    >>> est = memory_estimate(cfg, workers=2)
    >>> est.largest(), round(est.records / 1e9, 1)  # 100 realizations x 1e6 + 1 recorded times x 216 B
    ('records', 21.6)
    """
    R = cfg.realizations
    nodes = network_size(cfg)
    running = min(int(workers), R)
    times = recorded_times(cfg)
    held = min(R, STREAMED + running) if streamed else R
    tilt = 2 if "mu_eff" in cfg.observables else 0
    pull = 1 if "mu_shs" in cfg.observables else 0
    buffers = 1 + tilt + pull
    batch = cfg.solver.batch
    records_hint = "the records of each realization at each recorded time ('record', 'steps', 'realizations'" + (
        ")" if streamed else "; an output folder, --out, writes them 1024 realizations at a time)")
    return MemoryEstimate(
        network=SCENE_BYTES[cfg.network.kind] * nodes,
        running=running * (STATE_BYTES * nodes + THETA_BYTES * (cfg.steps + 1) + DRAW_BYTES * buffers * batch),
        records=RECORD_BYTES * held * times,
        ensemble=REALIZATION_BYTES[streamed] * R,
        what={
            "network": f"the network of {nodes:,} sliders, about {SCENE_BYTES[cfg.network.kind]:.0f} bytes each "
                       f"({_size_keys(cfg)})",
            "running": f"the {running} realization(s) running at once, each drawing theta for all of its "
                       f"{cfg.steps:,} steps, {THETA_BYTES:.0f} bytes a step, holding {STATE_BYTES:.0f} bytes "
                       f"a slider and {batch:,} draws of mu_s in its buffer"
                       + (" and two more of the tilt tests" if tilt else "")
                       + (" and one more of the slide-hold-slide pull" if pull else "")
                       + " ('steps', 'solver.batch'; fewer workers)",
            "records": f"{held:,} realizations x {times:,} recorded times, about {RECORD_BYTES:.0f} bytes each: "
                       + records_hint,
            "ensemble": f"the bookkeeping of {R:,} realizations, about {REALIZATION_BYTES[streamed]:.0f} bytes "
                        f"each ('realizations')",
        },
    )


def _size_keys(cfg: Config) -> str:
    return {"chain": "'network.n'", "irregular": "'network.n'", "square": "'network.shape'",
            "triangular": "'network.shape'", "graph": "'network.path'", "two_slider": "'network.kind'"}[
        cfg.network.kind]


def machine_memory() -> int | None:
    """This machine's memory in bytes, or the smaller limit of its control group (a batch job's); None if unknown.

    The physical memory (``os.sysconf``), lowered to the cgroup's ``memory.max`` (v2) or
    ``memory.limit_in_bytes`` (v1) where one is set: the memory a job of a batch system may use.
    """
    total: int | None = None
    try:
        total = int(os.sysconf("SC_PHYS_PAGES")) * int(os.sysconf("SC_PAGE_SIZE"))
    except (AttributeError, ValueError, OSError):  # not a POSIX system
        pass
    for limit_file in ("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"):
        try:
            text = Path(limit_file).read_text().strip()
        except OSError:
            continue
        if text.isdigit():  # "max" where there is no limit
            total = int(text) if total is None else min(total, int(text))
    return total


def check_memory(estimate: MemoryEstimate, *, available: int | None = None) -> None:
    """Refuse a run whose estimated memory exceeds the machine's, with one line giving both.

    Parameters
    ----------
    estimate : MemoryEstimate
        The run's (:func:`memory_estimate`). A sweep checks each point as it starts it.
    available : int, optional
        The machine's memory in bytes (default: :func:`machine_memory`; no
        check where it is unknown).

    Raises
    ------
    SizeError
        Naming the estimate, the machine's memory and the largest part, with
        the keys that make it large.
    """
    available = machine_memory() if available is None else available
    if available is None or estimate.total <= available:
        return
    part = estimate.largest()
    raise SizeError(
        f"This run needs about {_bytes(estimate.total)} of memory, more than this machine's {_bytes(available)}: "
        f"most of it for {estimate.what[part]}. The estimate counts the arrays slidernet allocates (docs/guides/"
        f"ensembles-and-hpc.md, 'Before a run')."
    )


def _bytes(n: float) -> str:
    """A size in words: '23.4 GB', '480 TB' (powers of 1000)."""
    for unit, scale in (("EB", 1e18), ("PB", 1e15), ("TB", 1e12), ("GB", 1e9), ("MB", 1e6)):
        if n >= scale:
            return f"{n / scale:.3g} {unit}"
    return f"{n:.3g} bytes"


# ---------------------------------------------------------------------------
# the scales of a scene: theta, the thermal loads, the gap a slip works across

#: Thermal steps of the driver drawn to measure theta's scale (from a generator of its own: the run's
#: streams are not touched).
SAMPLE_STEPS = 1 << 16

@dataclass(frozen=True)
class Scales:
    """The sizes that decide a scene's precision and its rate of slips.

    Attributes
    ----------
    theta : float
        max |theta(t_q)| / Ntilde over ``SAMPLE_STEPS`` steps of the driver.
    step : float
        The mean |theta(t_q+1) - theta(t_q)| / Ntilde over the same steps.
    load : ndarray, shape (N,)
        |g_i|, the thermal load of each node (its norm in 2D), in N per unit theta / Ntilde.
    normal_load : ndarray, shape (N,)
        N_i, in units of N.
    f_ext : float
        max |f_ext,i|, in N.
    gap : float
        The median of mu_s - mu_d under the truncated law (a median: it exists where a power law has
        no mean; for the study's laws it is the mean).
    mu_s : float
        The median of mu_s.
    """

    theta: float
    step: float
    load: np.ndarray
    normal_load: np.ndarray
    f_ext: float
    gap: float
    mu_s: float


def scales(cfg: Config, scene: Scene) -> Scales:
    """The :class:`Scales` of a scene: a short sample of its driver, the median of its law of mu_s.

    The law is asked for its median (``ppf(0.5)``), never sampled: a plugin's draws belong to the run.
    """
    net = scene.network
    thetas = draw_thetas(scene, np.random.default_rng(0), min(scene.steps, SAMPLE_STEPS)) / net.Ntilde
    g = np.asarray(scene.operators.g, dtype=np.float64).reshape(net.n_nodes, -1)
    with np.errstate(all="ignore"):
        mu = float(scene.distribution.ppf(0.5))
    f_ext = np.asarray(net.f_ext, dtype=np.float64).reshape(net.n_nodes, -1)
    return Scales(theta=float(np.abs(thetas).max()), step=float(np.abs(np.diff(thetas)).mean()),
                  load=np.sqrt((g * g).sum(axis=1)), normal_load=np.asarray(net.normal_load, dtype=np.float64),
                  f_ext=float(np.sqrt((f_ext * f_ext).sum(axis=1)).max(initial=0.0)),
                  gap=mu - scene.mu_d, mu_s=mu)


# ---------------------------------------------------------------------------
# precision

#: The largest share of the gap (mu_s - mu_d) N_i that the rounding of a force, eps times its largest term,
#: may reach. Chains of 8 stopped in avalanches that never end (AvalancheError, 1e8 slips in one step) at
#: 28 % (after 8 s) and at 2.8 % (after 71 s); at 0.28 % one ran 100 s without (``python
#: benchmarks/precision_limit.py``). 1/64 = 1.6 % lies below the smallest share measured to stop.
PRECISION_SHARE = 1.0 / 64


def check_precision(cfg: Config, scene: Scene, found: Scales | None = None) -> None:
    """Refuse a scene whose forces float64 cannot resolve, naming the parameter that causes it.

    Inside the kernels a force is F_i = a_i + g_i theta / Ntilde (a = -K u + ...): its terms grow with
    |g_i| |theta| / Ntilde and |f_ext,i|, and float64 rounds it to about eps = 2^-52 times them. A slip
    works across the gap (mu_s - mu_d) N_i between the static and the dynamic threshold. Where the
    rounding reaches :data:`PRECISION_SHARE` of that gap, the slips are no longer resolved: the run
    stops in an avalanche that never ends, or computes wrong slips.

    Raises
    ------
    PrecisionError
        With the size of the terms, their rounding, the gap, and the parameter to change.
    """
    s = scales(cfg, scene) if found is None else found
    terms = float(s.load.max(initial=0.0)) * s.theta + s.f_ext + s.mu_s * float(s.normal_load.max())
    rounding = np.finfo(np.float64).eps * terms
    gap = s.gap * float(s.normal_load.min())
    if rounding <= PRECISION_SHARE * gap:  # False for a NaN on either side: refused as the worst case
        return
    raise PrecisionError(
        f"float64 cannot resolve this run's slips: its forces are sums of terms up to {terms:.3g} N, rounded to "
        f"about {rounding:.3g} N, which is {rounding / gap:.3g} of the gap (mu_s - mu_d) N_i = {gap:.3g} N that "
        f"a slip works across (beyond 1/64 runs stop in avalanches that never end). Lost floating-point "
        f"precision; the cause: {precision_cause(cfg, s)}."
    )


def precision_cause(cfg: Config, s: Scales) -> str:
    """The parameter that makes a scene's force terms large, or its gap small, in words (for a message).

    Each candidate is measured against the paper's scene (|theta| / Ntilde of order 10, thermal loads
    of order 1, unit normal loads, mu_s - mu_d of order 0.1); the one furthest from it is named.
    """
    net = cfg.network
    load = float(s.load.max(initial=0.0))
    spring = ("'network.kappa'" if abs(net.kappa or 1.0) > (net.k or 1.0) else "'network.k'") \
        if cfg.network.kind != "graph" else "the springs' k and kappa in 'network.path'"
    nmin = float(s.normal_load.min())
    candidates = {
        f"'driver' with 'network.Ntilde' (|theta| / Ntilde reaches {s.theta:.3g}; sigma_theta / Ntilde "
        f"sets it)": s.theta / 10.0,
        f"{spring} (thermal loads g = k L kappa up to {load:.3g})": load,
        f"'network.normal_load' (down to {nmin:.3g} N)": 1.0 / nmin if nmin > 0 else math.inf,
        f"'friction.static' with 'friction.mu_d' (mu_s - mu_d of {s.gap:.3g}: draws close to mu_d)":
            0.1 / s.gap if s.gap > 0 else math.inf,
        f"'network.f_ext' or 'network.incline' (loads up to {s.f_ext:.3g} N)": s.f_ext,
    }
    # NaN (a thermal load or a law's median that is not a number) is the worst case, not the one max() skips.
    return max(candidates, key=lambda c: math.inf if math.isnan(candidates[c]) else candidates[c])


# ---------------------------------------------------------------------------
# time

#: Estimated seconds above which a run gets a SlowRunWarning.
SLOW_SECONDS = 3600.0

#: Seconds per node of building a scene (the network, K, g and their checks), by kind of network: measured by
#: ``python benchmarks/setup_cost.py`` on the 2-core dev machine (2026-11-28), the larger of the times per node
#: at its two sizes (chains and lattices of 1e6 and 5e6 nodes, irregular networks of 1e5 and 1e6), rounded
#: up. A network of 5e7 sliders takes longer to build than to drive for a few steps. A graph file counts as
#: an irregular network.
SETUP_SECONDS = {"two_slider": 0.0, "chain": 0.5e-6, "square": 0.35e-6, "triangular": 0.4e-6, "irregular": 12e-6,
                 "graph": 12e-6}


#: Generations of slips followed from one driving step (each moves the front of relieved load one spring
#: further); beyond them the estimate counts nothing more, so it is a lower bound for a scene whose front
#: would run further (a step of theta / Ntilde far above the paper's, which plausibility refuses).
SPREAD_GENERATIONS = 256
#: A node loaded by less than this share of mu_d N_i in a generation passes nothing on (its relieved share,
#: about (pi/4) x^2, is below 1e-6 of mu_d N_i).
SPREAD_CUTOFF = 1e-3


def relieved(x: np.ndarray) -> np.ndarray:
    """The force a node relieves by slipping, per thermal step, in units of mu_d N_i, for a drive x.

    x is the mean change of the node's force in a thermal step in units of mu_d N_i. After a slip
    the node's force sits inside a stick band of width about W = 2 mu_d N_i (from the level a forward
    slip leaves to the threshold of a backward one). A large step (x >> 1) reverses the drive half of
    the time and spends W crossing the band: x - 1 is relieved. A small one (x << 1) drives a random
    walk reflected at the band's edges, which relieves s^2 / W per step (the walk's local time at its
    edges; s^2 = (pi/2) x^2 (mu_d N_i)^2 for Gaussian steps): (pi/4) x^2. One function with both
    limits and no constant of its own:

    .. math:: f(x) = \\frac{x^2}{x + 4/\\pi} \\quad (\\to \\tfrac{\\pi}{4} x^2 \\text{ and } x - 1.27).

    >>> relieved(np.array([0.0, 1.0, 100.0])).round(3).tolist()
    [0.0, 0.44, 98.743]
    """
    return relieved_force(np.asarray(x, dtype=np.float64), 1.0)


def relieved_force(size: np.ndarray, hold: np.ndarray | float) -> np.ndarray:
    """:func:`relieved` (size / hold) times hold, in N: the force relieved by a node whose force changes by
    ``size`` a step, with hold = mu_d N_i; finite wherever size is (a hold of 1e-300 N included)."""
    size = np.asarray(size, dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(size > 0, size / (1.0 + (4.0 / np.pi) * hold / size), 0.0)


def _couplings(ops, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For the nodes ``rows``: (source, neighbour, coupling block -K_ij of shape (d, d)) of each off-diagonal
    entry of their rows of K (the kernels' operators; a lattice's blocks are read from its table)."""
    indptr = ops.indptr
    counts = indptr[rows + 1] - indptr[rows]
    src = np.repeat(rows, counts)
    starts = np.repeat(indptr[rows] - np.concatenate(([0], np.cumsum(counts)[:-1])), counts)
    p = np.arange(src.size) + starts
    dst = ops.indices[p].astype(np.int64)
    off = dst != src
    p, src, dst = p[off], src[off], dst[off]
    if hasattr(ops, "K_data"):  # 1D: 1 x 1 blocks
        return src, dst, -ops.K_data[p].reshape(-1, 1, 1)
    return src, dst, -ops.K_table[ops.K_id[p]]


def slips_per_tau(cfg: Config, scene: Scene, found: Scales | None = None) -> float:
    """Estimated rearrangements per tau_th of one realization: the slips of one driving step, followed
    through the network.

    A thermal step changes the force on node i by g_i times the mean |Δθ| / Ntilde (a vector in 2D); in
    units of mu_d N_i that is its drive x_i. The node slips and relieves :func:`relieved` (x_i) mu_d N_i
    (the drive, less what the stick band takes when the drive reverses), each slip taking
    2 (mu_s - mu_d) N_i off (mu_s the law's median). Its slips load its neighbours through K: the slip
    delta_i that relieves R_i through the springs to its neighbours, K_A delta_i = R_i, puts -K_ij delta_i
    on each. So the load not held by friction travels as a front, one spring a generation, losing
    about mu_d N_i at each node it crosses; loads arriving from two sides add as vectors (the two ends of
    a chain push its middle in opposite directions). A generation passes load to nodes not yet reached,
    and, once, between the nodes first reached together (in an irregular network every node is driven,
    and its neighbours take its relief). The rate is the sum over generations and nodes of

    .. math:: \\frac{f(x_i)\\, \\mu_d N_i}{2 (\\mu_s - \\mu_d) N_i},

    for the paper's two sliders one node's share (their one spring relieves both). No constant is fitted:
    against the study's measured slips per tau_th (docs/guides/aging-networks.md; ``python
    benchmarks/slip_rate_estimate.py``, which fails outside a factor 2) it is 0.59 to 1.66 times the
    measured rate over chains of 2 to 16 and irregular networks of 16 to 4096 at sigma_theta / Ntilde =
    1 and 10 (it was 0.09 to 1.96 without the band's loss and the front); the performance guide gives the
    table. Beyond :data:`SPREAD_GENERATIONS` generations nothing more is counted.
    """
    s = scales(cfg, scene) if found is None else found
    if not s.gap > 0:
        return math.inf
    ops = scene.operators
    N = scene.network.n_nodes
    hold = scene.mu_d * s.normal_load
    per_slip = 2.0 * s.gap * s.normal_load
    g = np.asarray(ops.g, dtype=np.float64).reshape(N, -1) * s.step
    if scene.network.is_two_slider():
        return float((relieved_force(s.load * s.step, hold) / per_slip).max())
    # nodes loaded in this generation and their loads; the generation each node was first reached
    nodes = np.flatnonzero(s.load > 0)
    load = g[nodes]
    first = np.full(N, np.iinfo(np.int64).max)
    first[nodes] = 0
    total = 0.0
    for gen in range(SPREAD_GENERATIONS):
        size = np.sqrt((load * load).sum(axis=1))
        x = size / hold[nodes]
        keep = x > SPREAD_CUTOFF
        nodes, load, size, x = nodes[keep], load[keep], size[keep], x[keep]
        if nodes.size == 0:
            break
        relief = relieved_force(size, hold[nodes])
        total += float((relief / per_slip[nodes]).sum())
        R = load * (relief / size)[:, None]
        src, dst, C = _couplings(ops, nodes)
        passes = (first[dst] > first[src]) | ((first[dst] == first[src]) & (first[src] == gen))
        src, dst, C = src[passes], dst[passes], C[passes]
        local = np.searchsorted(nodes, src)
        K_A = np.zeros((nodes.size, *C.shape[1:]))
        np.add.at(K_A, local, C)
        delta = np.einsum("nab,nb->na", np.linalg.pinv(K_A), R)
        nodes, inverse = np.unique(dst, return_inverse=True)
        load = np.zeros((nodes.size, g.shape[1]))
        np.add.at(load, inverse, np.einsum("eab,eb->ea", C, delta[local]))
        first[nodes] = np.minimum(first[nodes], gen + 1)
    return total


def warn_if_slow(cfg: Config, scene: Scene, workers: int = 1, found: Scales | None = None) -> float:
    """Warn once (:class:`~slidernet.errors.SlowRunWarning`) if the run would take more than an hour.

    The estimate is ``realizations x steps x`` :func:`slips_per_tau`, at the backend's ``slips_per_second`` per
    worker (the pair kernel's, or the network kernels'), on ``min(workers, realizations)`` workers, plus the
    time to build the scene, :data:`SETUP_SECONDS` per node.

    Returns
    -------
    float
        The estimated seconds.
    """
    rate = slips_per_tau(cfg, scene, found)
    slips = rate * cfg.steps * cfg.realizations
    per_second = BACKENDS[scene.kernel].slips_per_second
    parallel = min(int(workers), cfg.realizations)
    setup = SETUP_SECONDS[cfg.network.kind] * scene.network.n_nodes
    seconds = slips / (per_second * parallel) + setup
    if seconds > SLOW_SECONDS:
        warnings.warn(
            f"This run would take about {_duration(seconds)}: about {rate:.3g} slips per tau_th (the slips of a "
            f"thermal step followed through the network) x {cfg.steps:,} steps x {cfg.realizations:,} "
            f"realizations = {slips:.3g} slips, "
            f"at {per_second:.3g} slips/s on each of {parallel} worker(s)"
            + (f", and {_duration(setup)} to build the network of {scene.network.n_nodes:,} sliders"
               if setup > 0.1 * seconds else "")
            + ". A smaller sigma_theta / Ntilde, fewer steps or realizations shorten it.",
            SlowRunWarning, stacklevel=3)
    return seconds


def _duration(seconds: float) -> str:
    if not math.isfinite(seconds):
        return "for ever"
    for unit, scale in (("years", 3.156e7), ("days", 86400.0), ("hours", 3600.0)):
        if seconds >= scale:
            return f"{seconds / scale:.3g} {unit}"
    return f"{seconds / 60:.3g} minutes"


def check_run(cfg: Config, scene: Scene, workers: int = 1) -> float:
    """The checks of a scene before its run: :func:`check_precision`, then :func:`warn_if_slow`; returns its
    estimated seconds (the run's progress compares its pace with them)."""
    found = scales(cfg, scene)
    check_precision(cfg, scene, found)
    return warn_if_slow(cfg, scene, workers, found)
