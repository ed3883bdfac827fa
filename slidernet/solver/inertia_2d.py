"""The compiled inertial solver of 2D networks: one realization under the equations of motion.

A thin driver of :func:`slidernet.kernels.inertia_2d.run_inertia_2d`: it
draws theta(t_q) and the thresholds exactly as the quasi-static solver and
the reference integrator (:mod:`slidernet.validation.dynamics`) do, feeds the
kernel its buffers, and returns the reference's dict of outputs, so the two
compare slip for slip. The equations, rules, units and the integration
scheme are in the kernel's module docstring.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from slidernet.errors import ConfigError, param_error
from slidernet.kernels import inertia_2d as kern
from slidernet.solver.inertia import runaway_error
from slidernet.solver.scene import Scene
from slidernet.solver.streams import horizontal_draws, realization_streams

# The slip and avalanche buffers' rows between two returns of the kernel.
OUT_CHUNK = 4096

# Defaults of the scheme: Dormand-Prince 5(4) with a relative error per step of RTOL in u and v (absolute
# 1e-2 RTOL in Ntilde l0, as the reference's), steps of at most MAX_STEP tau_dyn.
RTOL = 1e-10
MAX_STEP = 0.1


class Out(NamedTuple):
    """What :func:`~slidernet.kernels.inertia_2d.run_inertia_2d` writes: the records at the output steps, the
    slip and avalanche buffers."""

    n: np.ndarray  # (T,) int64
    mu_max: np.ndarray  # (T,)
    x_G: np.ndarray  # (T,) Ntilde l0
    slip_f: np.ndarray  # (C, 6): start, end (tau_th), duration (tau_th), du_x, du_y, path (Ntilde l0)
    slip_node: np.ndarray  # (C,) int64
    av_f: np.ndarray  # (C, 6): start, end (tau_th), work, dissipation, dE, dropped kinetic energy
    av_n: np.ndarray  # (C,) int64 starts


class Run(NamedTuple):
    """The run's constants, as the kernel reads them."""

    mu_d: float
    tau: float  # tau_dyn / tau_th
    rtol: float
    atol: float
    max_step: float  # tau_dyn
    steps: int


def new_motion(scene: Scene, mu: np.ndarray, theta0: float) -> tuple[kern.Motion, kern.Work]:
    """The nodes at rest at u = 0 with thresholds ``mu`` (shape (N,), held, not copied: the kernel writes its
    draws there) and theta(0) = ``theta0`` (Ntilde), their stable ranges computed; and the scratch of a phase."""
    net = scene.operators
    n_nodes = mu.size
    nnz = net.indices.size
    f_ext = np.asarray(scene.network.f_ext, dtype=np.float64).reshape(n_nodes, 2)
    top = int(np.argmax(mu))
    mo = kern.Motion(
        u=np.zeros((n_nodes, 2)), v=np.zeros((n_nodes, 2)), a=f_ext - net.g * theta0,
        sigma=np.zeros((n_nodes, 2)), mu=mu, lim=mu * net.normal_load, crit=np.zeros((n_nodes, 2)),
        moving=np.zeros(n_nodes, np.int8), armed=np.zeros(n_nodes, np.int8), start_t=np.zeros(n_nodes),
        start_clock=np.zeros(n_nodes), start_u=np.zeros((n_nodes, 2)), path=np.zeros(n_nodes),
        mark=np.full(n_nodes, -1, np.int64), wmark=np.full(n_nodes, -1, np.int64),
        best=np.array([mu[top], top, 0.0]), first=np.zeros((0, 2)), times=np.zeros(0))
    wk = kern.Work(
        M=np.zeros(n_nodes, np.int64), W=np.zeros(n_nodes, np.int64), mptr=np.zeros(n_nodes + 1, np.int64),
        mcol=np.zeros(nnz, np.int64), mblk=np.zeros(nnz, np.int64), wptr=np.zeros(n_nodes + 1, np.int64),
        wcol=np.zeros(nnz, np.int64), wblk=np.zeros(nnz, np.int64), F0=np.zeros((n_nodes, 2)),
        FW=np.zeros((n_nodes, 2)), Y=np.zeros((n_nodes, kern.N_COMP)), Yt=np.zeros((n_nodes, kern.N_COMP)),
        Ks=np.zeros((7, n_nodes, kern.N_COMP)),
        cand=np.zeros(n_nodes, np.int64), over=np.zeros(n_nodes))
    for j in range(n_nodes):
        kern.node_crit(net, mo, j)
    return mo, wk


def new_out(n: np.ndarray, mu_max: np.ndarray, x_G: np.ndarray) -> Out:
    """The kernel's output: the records ``n``, ``mu_max``, ``x_G`` (shape (T,), held, not copied) and
    empty slip and avalanche buffers of OUT_CHUNK rows."""
    return Out(n=n, mu_max=mu_max, x_G=x_G, slip_f=np.zeros((OUT_CHUNK, 6)),
               slip_node=np.zeros(OUT_CHUNK, np.int64), av_f=np.zeros((OUT_CHUNK, 6)),
               av_n=np.zeros(OUT_CHUNK, np.int64))


def new_scalars(max_step: float) -> tuple[np.ndarray, np.ndarray]:
    """The kernel's float and integer scalars at the start of a realization (the first step: 0.01 tau_dyn
    or ``max_step``)."""
    floats = np.zeros(kern.N_FLOATS)
    floats[kern.H] = min(0.01, max_step)
    return floats, np.zeros(kern.N_INTS, np.int64)


class Inertia2D:
    """The compiled inertial solver of a 2D network (a lattice, an irregular network, any 2D graph).

    Constructing it validates and stores the settings; :meth:`run` runs one
    realization with the same theta(t_q) and thresholds as
    :func:`slidernet.solver.simulate` and
    :class:`~slidernet.validation.dynamics.Dynamics` on the same seed.

    Parameters
    ----------
    scene : Scene
        A scene of a 2D network.
    tau_ratio : float
        tau_dyn / tau_th, finite and > 0.
    rtol : float
        Relative tolerance per step of the Dormand-Prince 5(4) scheme, in
        [1e-14, 1e-3]; the absolute one is ``1e-2 * rtol`` Ntilde l0 (and
        per tau_dyn).
    max_step : float
        Largest step, tau_dyn, > 0: an event that comes and goes within one
        step (a stuck neighbour's ``|F_j|`` above its threshold and below again)
        is not seen.

    Examples
    --------
    A triangular lattice of 3 x 3 over two thermal steps: the counts are the
    reference integrator's.

    >>> from slidernet.config import load_config
    >>> scene = Scene.from_config(load_config({
    ...     "steps": 2, "record": "all", "network": {"kind": "triangular", "shape": [3, 3], "Ntilde": 1e-7},
    ...     "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
    ...     "driver": {"name": "gaussian_steps", "sigma_theta": 1e-7}}))
    >>> out = Inertia2D(scene, tau_ratio=1e-4).run(np.random.SeedSequence(0))
    >>> out["n"].shape, int(out["moving_at_end"])
    ((3,), 0)
    """

    def __init__(self, scene: Scene, tau_ratio: float, rtol: float = RTOL, max_step: float = MAX_STEP) -> None:
        owner = "Inertia2D"
        if scene.network.dim != 2:
            raise ConfigError(f"Inertia2D runs 2D networks; this scene's network is {scene.network.dim}D.")
        if isinstance(tau_ratio, bool) or not isinstance(tau_ratio, (int, float)) or not (
                math.isfinite(tau_ratio) and tau_ratio > 0):
            raise param_error("tau_ratio", owner, "a finite number > 0", tau_ratio)
        if isinstance(rtol, bool) or not isinstance(rtol, (int, float)) or not 1e-14 <= rtol <= 1e-3:
            raise param_error("rtol", owner, "a number in [1e-14, 1e-3]", rtol)
        if isinstance(max_step, bool) or not isinstance(max_step, (int, float)) or not (
                math.isfinite(max_step) and max_step > 0):
            raise param_error("max_step", owner, "a finite number > 0 (tau_dyn)", max_step)
        self.scene = scene
        self.tau_ratio = float(tau_ratio)
        self.rtol = float(rtol)
        self.max_step = float(max_step)

    def run(self, seed_seq: np.random.SeedSequence, steps: int | None = None) -> dict:
        """Run one realization through ``steps`` thermal steps (default: the scene's).

        Returns
        -------
        dict
            The keys of :meth:`slidernet.validation.dynamics.Dynamics.run`
            (without ``states``), in its units: ``t``, ``n``, ``mu_max``,
            ``x_G``, ``overlapping``, ``moving_at_end``, ``stop_speed`` and
            ``slips`` (``start``, ``end``, ``duration``, ``node``, ``du`` of
            shape (S, 2)), the slips also with ``path`` (l0: the length of
            the node's path, ``int |v| dt``). Besides: ``avalanches``, a dict of
            arrays of shape (A,), one per avalanche ended by t = ``steps``
            (from a start with nothing moving to the next moment nothing
            moves): ``start``, ``end`` (tau_th), ``starts`` (int64),
            ``work`` (the thermal load's work, int (theta - theta(0)) g.v
            dt), ``dissipation`` (sum_i mu_d N_i times the path lengths),
            ``dE`` (the change of E = u.K u / 2 - u.f_ext), ``dropped``
            (the kinetic energy set to zero at the stops), all in
            N l0; and ``steps``, the accepted
            steps of the scheme (int).
        """
        scene = self.scene
        steps = scene.steps if steps is None else steps
        if isinstance(steps, bool) or not isinstance(steps, (int, np.integer)) or not 0 <= steps <= scene.steps:
            raise param_error("steps", "Inertia2D.run", f"an integer in [0, {scene.steps}]", steps)
        thetas, mu, batches = horizontal_draws(scene, realization_streams(seed_seq))
        net = scene.operators
        mo, wk = new_motion(scene, mu, thetas[0])
        rec = scene.out_steps[scene.out_steps <= steps]
        out = new_out(np.zeros(rec.size, np.int64), np.zeros(rec.size), np.zeros(rec.size))
        run = Run(mu_d=float(scene.mu_d), tau=self.tau_ratio, rtol=self.rtol, atol=1e-2 * self.rtol,
                       max_step=self.max_step, steps=int(steps))
        floats, ints = new_scalars(self.max_step)
        mu_buf = np.empty(0)
        ints[kern.POS] = 0
        slips: list[np.ndarray] = []
        nodes: list[np.ndarray] = []
        avs: list[np.ndarray] = []
        av_n: list[np.ndarray] = []
        while True:
            code = kern.run_inertia_2d(thetas, rec, net, mo, wk, out, run, floats, ints, mu_buf)
            if code == kern.NEED_MU:
                mu_buf = next(batches)
                ints[kern.POS] = 0
                continue
            # Whatever the code, the buffers' rows so far are kept.
            slips.append(out.slip_f[:ints[kern.N_SLIPS]].copy())
            nodes.append(out.slip_node[:ints[kern.N_SLIPS]].copy())
            avs.append(out.av_f[:ints[kern.N_AV]].copy())
            av_n.append(out.av_n[:ints[kern.N_AV]].copy())
            ints[kern.N_SLIPS] = 0
            ints[kern.N_AV] = 0
            if code == kern.DONE:
                break
            if code == kern.RUNAWAY:
                raise runaway_error(int(ints[kern.RUNAWAY_NODE]), float(floats[kern.T]))
        Ntilde = scene.network.Ntilde
        slip = np.concatenate(slips)
        av = np.concatenate(avs)
        energy = Ntilde
        return {
            "t": rec.astype(np.int64),
            "n": out.n,
            "mu_max": out.mu_max,
            "x_G": out.x_G * Ntilde,
            "overlapping": np.int64(ints[kern.OVERLAPPING]),
            "moving_at_end": np.int64(ints[kern.N_MOVING]),
            "stop_speed": float(floats[kern.STOP_MAX] * Ntilde),
            "slips": {"start": slip[:, 0].copy(), "end": slip[:, 1].copy(), "duration": slip[:, 2].copy(),
                      "node": np.concatenate(nodes), "du": slip[:, 3:5] * Ntilde, "path": slip[:, 5] * Ntilde},
            "avalanches": {"start": av[:, 0].copy(), "end": av[:, 1].copy(), "starts": np.concatenate(av_n),
                           "work": av[:, 2] * energy, "dissipation": av[:, 3] * energy, "dE": av[:, 4] * energy,
                           "dropped": av[:, 5] * energy},
            "steps": int(ints[kern.STEPS]),
        }
