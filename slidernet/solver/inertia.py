"""The inertial solver of 1D networks: the equations of motion (eq. `dynamics`), compiled and exact between events.

:class:`InertialSolver` runs one realization of a 1D scene (the pair, a
chain, any network with ``dim == 1``) with sliders of mass N_i m, on the
same theta(t_q) and the same stream of mu_s draws as
:func:`slidernet.solver.simulate` and as the reference integrator
(:class:`slidernet.validation.dynamics.Dynamics`), and returns the
reference's outputs, so that the two compare slip for slip. The model, its
units and its rules are the reference's module docstring's; how the motion
is solved (modes of the moving segment, closed-form lone slips, a
safeguarded event search) is :mod:`slidernet.kernels.inertia`'s and
:mod:`slidernet.kernels.inertia_phase`'s.
"""

from __future__ import annotations

import math

import numpy as np

from slidernet.errors import AvalancheError, ConfigError, param_error
from slidernet.kernels import inertia as kin
from slidernet.kernels.inertia_phase import new_work
from slidernet.kernels.state import DONE, NEED_EVENTS, NEED_MU
from slidernet.solver.scene import Scene
from slidernet.solver.streams import horizontal_draws, realization_streams

# Rows of the slip and avalanche logs to start with; they double when full.
LOG_ROWS = 1024


class InertialSolver:
    """The equations of motion of a 1D network, event-driven and exact between events.

    Constructing it validates and stores the settings; :meth:`run` runs one
    realization.

    Parameters
    ----------
    scene : Scene
        A scene of a 1D network (``scene.network.dim == 1``): the pair, a
        chain, or any 1D network, with its f_ext, normal loads, thresholds law
        and driver.
    tau_ratio : float
        tau_dyn / tau_th, finite and > 0, with tau_dyn = sqrt(m / k) (masses
        m_i = N_i m; a lone slip of the paper lasts pi tau_dyn).

    Raises
    ------
    ConfigError
        A 2D scene, or a bad ``tau_ratio``.

    Examples
    --------
    A free chain of 4 under the paper's friction, the same realization as
    the reference integrator's: the same slips, node by node, and the same
    displacements to far below the reference's tolerance.

    >>> from slidernet.config import load_config
    >>> from slidernet.validation.dynamics import Dynamics
    >>> scene = Scene.from_config(load_config({
    ...     "steps": 1, "network": {"kind": "chain", "n": 4, "Ntilde": 1e-7},
    ...     "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
    ...     "driver": {"name": "gaussian_steps", "sigma_theta": 3e-7}}))
    >>> out = InertialSolver(scene, tau_ratio=1e-4).run(np.random.SeedSequence(1))
    >>> ref = Dynamics(scene, tau_ratio=1e-4).run(np.random.SeedSequence(1))
    >>> nodes = out["slips"]["node"]
    >>> nodes.size, int(out["overlapping"]), bool((nodes == ref["slips"]["node"]).all())
    (47, 15, True)
    >>> bool(np.abs(out["slips"]["du"] - ref["slips"]["du"]).max() < 1e-12 * np.abs(ref["slips"]["du"]).min())
    True
    """

    def __init__(self, scene: Scene, tau_ratio: float) -> None:
        owner = "InertialSolver"
        if isinstance(tau_ratio, bool) or not isinstance(tau_ratio, (int, float)) or not (
                math.isfinite(tau_ratio) and tau_ratio > 0):
            raise param_error("tau_ratio", owner, "a finite number > 0", tau_ratio)
        if scene.network.dim != 1:
            raise ConfigError(
                f"The inertial solver runs 1D networks only (scene.network.dim == 1); this one is "
                f"{scene.network.dim}D.")
        self.scene = scene
        self.tau_ratio = float(tau_ratio)

    def run(self, seed_seq: np.random.SeedSequence, steps: int | None = None) -> dict:
        """Run one realization through ``steps`` thermal steps (default: the scene's).

        Parameters
        ----------
        seed_seq : numpy.random.SeedSequence
            The realization's seed, as given to :func:`slidernet.solver.simulate`.
        steps : int, optional
            Thermal steps to run, 0 <= steps <= ``scene.steps``.

        Returns
        -------
        dict
            The outputs of :meth:`slidernet.validation.dynamics.Dynamics.run`
            (without ``states``), in the same units: ``t``, ``n``, ``mu_max``,
            ``x_G`` (shape (T,)), ``overlapping``, ``moving_at_end``,
            ``stop_speed`` (here the root search's residual, l0 per tau_dyn)
            and ``slips`` (``start``, ``end``, ``duration``, ``node``,
            ``du``, shape (S,) each); and ``avalanches``, one row per motion
            from rest to rest, each of shape (A,): ``start`` and ``end``
            (tau_th), ``work`` (the work of the loads f_ext + (theta -
            theta(0)) g on the motion), ``e0`` and ``e1`` (the elastic
            energy u.K u / 2 before and after), in N l0; ``slips`` (int64),
            the slips logged by its end (its own: from the previous
            avalanche's ``slips`` on). Each avalanche's energy balance reads
            work = e1 - e0 + sum over its slips of mu_d N_i ``|du_i|`` (the
            kinetic energy is zero at both ends).

        Raises
        ------
        ConfigError
            A bad ``steps``.
        AvalancheError
            A node slid 1000 tau_dyn without stopping (a load f_ext that friction cannot hold).
        """
        scene = self.scene
        steps = scene.steps if steps is None else steps
        if isinstance(steps, bool) or not isinstance(steps, (int, np.integer)) or not 0 <= steps <= scene.steps:
            raise param_error("steps", "InertialSolver.run", f"an integer in [0, {scene.steps}]", steps)
        net = scene.network
        thetas, mu, batches = horizontal_draws(scene, realization_streams(seed_seq))
        N = net.n_nodes
        rec = scene.out_steps[scene.out_steps <= steps].astype(np.int64)
        mo = new_motion(mu.copy(), net.normal_load)
        log = new_log(rec.size, LOG_ROWS)
        istate = np.zeros(10, np.int64)
        fstate = np.zeros(6)
        draws = np.empty(0)
        f_ext = np.ascontiguousarray(net.f_ext, dtype=np.float64).reshape(-1)
        work = new_work(N)
        while True:
            code = kin.run_inertia(scene.operators, f_ext, float(scene.mu_d), self.tau_ratio, thetas, rec,
                                   int(steps), mo, work, log, draws, istate, fstate)
            if code == DONE:
                break
            if code == NEED_MU:
                draws = next(batches)
                istate[kin.I_POS] = 0
            elif code == NEED_EVENTS:
                log = grow_log(log)
            else:  # RUNAWAY
                raise runaway_error(int(istate[kin.I_NODE]), float(fstate[kin.F_T]))
        Ntilde = net.Ntilde
        S = int(istate[kin.I_SLIPS])
        A = int(istate[kin.I_AVAL])
        return {
            "t": rec,
            "n": log.out_n.copy(),
            "mu_max": log.out_mu_max.copy(),
            "x_G": log.out_xg * Ntilde,
            "overlapping": np.int64(istate[kin.I_OVERLAP]),
            "moving_at_end": np.int64(mo.moving.sum()),
            "stop_speed": float(fstate[kin.F_STOP_SPEED] * Ntilde),
            "slips": {
                "start": log.slip_start[:S].copy(),
                "end": log.slip_end[:S].copy(),
                "duration": log.slip_duration[:S].copy(),
                "node": log.slip_node[:S].copy(),
                "du": log.slip_du[:S] * Ntilde,
            },
            "avalanches": {
                "start": log.av_start[:A].copy(),
                "end": log.av_end[:A].copy(),
                # Energies in N Ntilde l0 in the kernel: N l0 here.
                "work": log.av_work[:A] * Ntilde,
                "e0": log.av_e0[:A] * Ntilde,
                "e1": log.av_e1[:A] * Ntilde,
                "slips": log.av_slips[:A].copy(),
            },
        }


def runaway_error(node: int, t: float) -> AvalancheError:
    """The error of a node that slid MAX_SLIP_DURATION tau_dyn without stopping, at time t (tau_th)."""
    return AvalancheError(
        f"Node {node} has been sliding for {kin.MAX_SLIP_DURATION:g} tau_dyn without stopping (t = {t!r} tau_th): "
        "a load f_ext that friction cannot hold makes the network slide for ever; lower f_ext.")


def new_motion(mu: np.ndarray, normal_load: np.ndarray) -> kin.Motion:
    """The nodes at rest at u = 0 with thresholds ``mu`` (held, not copied: the kernel writes its draws there)
    and normal loads N_i, shape (N,) each."""
    N = mu.size
    top = int(np.argmax(mu))
    return kin.Motion(u=np.zeros(N), v=np.zeros(N), sig=np.zeros(N), mu=mu, lim=mu * normal_load,
                      moving=np.zeros(N, np.int64), start_t=np.zeros(N), start_clock=np.zeros(N),
                      start_u=np.zeros(N), best=np.array([mu[top], top, 0.0]), first=np.zeros((0, 2)),
                      times=np.zeros(0))


def new_log(records: int, rows: int) -> kin.Log:
    f = np.zeros
    """A log of ``records`` recorded times and ``rows`` rows of slips and of avalanches."""
    return kin.Log(out_n=f(records, np.int64), out_mu_max=f(records), out_xg=f(records),
                   slip_start=f(rows), slip_end=f(rows), slip_duration=f(rows), slip_node=f(rows, np.int64),
                   slip_du=f(rows), av_start=f(rows), av_end=f(rows), av_work=f(rows), av_e0=f(rows),
                   av_e1=f(rows), av_slips=f(rows, np.int64))


def grow_log(log: kin.Log) -> kin.Log:
    """The log with its slip and avalanche rows doubled (the records kept as they are)."""
    grown = {}
    for name, array in log._asdict().items():
        if name.startswith(("slip_", "av_")):
            array = np.concatenate([array, np.zeros_like(array)])
        grown[name] = array
    return kin.Log(**grown)
