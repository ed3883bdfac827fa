"""The dynamic tilt test, ``[dynamics] tilt_rate``: the load ramped at a finite rate under the equations of motion.

With ``[dynamics] tilt_rate`` = r, the tilt tests of a run with inertia
(``mu_eff_at = "records"``) are made under the equations of motion instead
of the quasi-static network tilt test: the rule of the reference
integrator's :meth:`~slidernet.validation.dynamics.Dynamics.tilt_test`,
compiled. On a copy of the state at the recorded time (displacements u,
the tested thresholds, every velocity set to zero: a node that was moving
is held where it is, as the quasi-static test on the dynamic state holds
it, and starts at once if its force is above its threshold), the tangential
force f N_i along +x is added to every node and f rises from 0 at r per
tau_dyn, theta frozen at its value. A node starts, along F_i, when |F_i|
reaches mu_s,i N_i; a node whose velocity returns to zero gets a new
threshold from the realization's tilt stream (``buffers.tilt_mu``, read as
the quasi-static test reads it) and sticks or starts again.

How the kernels run it: the load is the kernels' thermal drive in
disguise. theta is frozen and its load folded into the constant forces
(F = F_now + f g' with g'_i = N_i along x), and ``thetas`` = df (0, 1, 2,
...) with tau_dyn / tau_th = rate / df, so that f = df t rises at r per
tau_dyn and each "thermal step" lasts ``CHUNK`` = 10 tau_dyn. The inertial
kernels (:func:`~slidernet.kernels.inertia.run_inertia`,
:func:`~slidernet.kernels.inertia_2d.run_inertia_2d`) integrate it unchanged,
returning at the ends of steps (while nothing moves, many steps at a time);
their watch (``Motion.first``, ``Motion.times``) marks each node's first
start, the first time every node moved at once and the last start from rest.

**Sliding for good.** At the end of each step in which every node moves (in
1D, forward), the reference's proof that the network never sticks again is
checked (:func:`_slides_for_good`: the internal energy bounds each node's
velocity about the centre of mass's, which the load above mu_d only
raises); in 1D it is the reference's 2D bound, looser than its modal one,
so it may hold a step later, which leaves the sample unchanged. Where the
proof does not apply (springs to the ground, loads with a net torque) the
test ends when a node has slid for ``MAX_SLIP_DURATION`` = 1000 tau_dyn
without stopping (the kernels' runaway). A load that reaches ``TILT_CAP``
(per unit normal load) first is an error.

**The sample.** mu_eff is the load at the last start from rest before the
network slid for good: the largest load the state held (every node stuck,
none above its threshold), the reference's ``mu_eff``. An instant of rest at
a stop followed by a restart on a redrawn threshold below the force is not
rest (the reference's rule). The loads of ``tilt_loads``: ``tilt_first_slip``
at the first start; ``tilt_all_moving`` when every node first moved at once;
``tilt_contact_mean`` and ``tilt_half_broken`` from each node's first start
(a contact breaks there); ``tilt_break_ratio``, the mean weighted by N_i of
|F_i| / N_i at each node's first start. Under the equations of motion a
stuck node's force is continuous in time, so a node starts exactly at its
threshold (to the event location's tolerance): ``tilt_break_ratio`` is the
mean of the tested thresholds weighted by N_i, unless a node is above its
threshold when the test begins (a moving node held, an injected threshold).

The ramp raises f during each motion, so every avalanche before the last
rest comes at a slightly higher load than under a static load: mu_eff
depends on r, and :func:`slidernet.analysis.tilt_rate.zero_rate` extrapolates
it to r -> 0.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy.sparse.linalg import splu

from slidernet import kernels
from slidernet.errors import TiltTestError
from slidernet.kernels import inertia as kin
from slidernet.kernels import inertia_2d as k2d
from slidernet.kernels.inertia_phase import new_work
from slidernet.solver.inertia import LOG_ROWS, new_log, new_motion
from slidernet.solver.inertia_2d import Run, new_out, new_scalars
from slidernet.solver.inertia_2d import new_motion as new_motion_2d

#: The load per unit normal load (f, without f_ext) at which a dynamic tilt test that has not slid gives up.
TILT_CAP = 10.0
#: The ramp is run in chunks of CHUNK tau_dyn (at most MAX_CHUNKS of them to the cap), the proof of sliding
#: checked at the end of each chunk in motion; at rest the chunks double up to MAX_REST_CHUNKS.
CHUNK = 10.0
MAX_CHUNKS = 100_000
MAX_REST_CHUNKS = 16
#: Starts of motion after which a dynamic tilt test gives up (the reference's TILT_MAX_STARTS), checked at the
#: kernel's returns.
MAX_STARTS = 100_000


def _watch(mo: Any, N: int) -> Any:
    """The motion with the tilt test's watch: each node's first start and the two times, NaN."""
    return mo._replace(first=np.full((N, 2), math.nan), times=np.full(2, math.nan))


def dynamic_tilt(backend: Any, real: Any, mu: np.ndarray, rate: float) -> tuple[float, dict[str, float], int]:
    """One dynamic tilt test on a copy of the state of ``real`` (a realization run by an inertial backend).

    Parameters
    ----------
    backend : InertiaBackend or Inertia2DBackend
        The realization's backend (its displacements and forces are read, not changed).
    real : Realization
        The realization: its tilt stream's buffer and read position ``tilt_mu_pos``.
    mu : ndarray, shape (N,)
        The thresholds to test; the test writes its redraws there.
    rate : float
        df/ds, the load's rate per tau_dyn, in units of mu.

    Returns
    -------
    mu_eff : float
        The load per unit normal load along x, f + f_bar (f_bar = sum_i f_ext,i,x / sum_i N_i), at the last
        start from rest before the network slid for good.
    loads : dict
        The loads of :data:`slidernet.kernels.tilt_net.TILT_LOADS` (see the module docstring).
    pos : int
        The read position in ``real.buffers.tilt_mu`` after the test (the buffer may have been lengthened).

    Raises
    ------
    TiltTestError
        The load reached ``TILT_CAP``, or ``MAX_STARTS`` starts of motion, without sliding for good.
    """
    scene = real.scene
    net = scene.operators
    N = scene.network.n_nodes
    mu_d = float(scene.mu_d)
    f_bar = float(scene.tilt_operators().f_bar)
    # The ramp in "thermal steps" of df = rate * CHUNK (CHUNK tau_dyn each, at most MAX_CHUNKS of them up to the
    # cap), f = df t: the kernel returns at the ends of steps, where the proof of sliding is checked.
    f_cap = TILT_CAP + 2.0 * kin.MAX_SLIP_DURATION * rate
    df = rate * max(CHUNK, f_cap / (rate * MAX_CHUNKS))
    Q = math.ceil(f_cap / df)
    thetas = df * np.arange(Q + 1, dtype=np.float64)
    tau = rate / df
    no_records = np.zeros(0, np.int64)
    F = np.array(backend.forces(real), dtype=np.float64)
    st = real.state
    pos = int(st["tilt_mu_pos"][0])
    if scene.network.dim == 1:
        tnet = net._replace(g=np.ascontiguousarray(net.normal_load, dtype=np.float64))
        mo = _watch(new_motion(mu, net.normal_load), N)
        mo.u[:] = backend.u
        # F = f_ext' - K u + f g': the forces of the state at f = 0.
        f_ext = F + scene.K @ mo.u
        work, log = new_work(N), new_log(0, LOG_ROWS)
        istate, fstate = np.zeros(10, np.int64), np.zeros(6)
        kin.start_overloaded(tnet, f_ext, mo, istate, fstate, 0.0)
        istate[kin.I_STAGE] = kin.STAGE_STEP

        def call(draws: np.ndarray, p: int, upto: int) -> tuple[int, int]:
            istate[kin.I_POS] = p
            code = kin.run_inertia(tnet, f_ext, mu_d, tau, thetas, no_records, upto, mo, work, log, draws, istate,
                                   fstate)
            if code == kernels.NEED_EVENTS:
                istate[kin.I_SLIPS] = istate[kin.I_AVAL] = 0
            return {kernels.NEED_EVENTS: -1, kin.RUNAWAY: kin.RUNAWAY}.get(code, code), int(istate[kin.I_POS])

        def forces() -> np.ndarray:
            return (f_ext - scene.K @ mo.u + net.normal_load * (df * fstate[kin.F_T]))[:, None]

        starts = lambda: int(istate[kin.I_N])  # noqa: E731
        forward = lambda: bool((mo.sig > 0).all())  # noqa: E731
    else:
        g = np.zeros((N, 2))
        g[:, 0] = net.normal_load
        tnet = net._replace(g=g)
        mo, wk = new_motion_2d(scene, mu, 0.0)
        mo = _watch(mo, N)
        mo.u[:] = backend.u
        mo.a[:] = F
        for j in range(N):
            k2d.node_crit(tnet, mo, j)
        out = new_out(np.zeros(0, np.int64), np.zeros(0), np.zeros(0))
        dyn = scene.dynamics
        run = Run(mu_d=mu_d, tau=tau, rtol=dyn.rtol, atol=1e-2 * dyn.rtol, max_step=dyn.max_step, steps=0)
        floats, ints = new_scalars(dyn.max_step)
        k2d.start_overloaded_all(tnet, mo, wk, floats, ints, 0.0)
        ints[k2d.STAGE] = 2

        def call(draws: np.ndarray, p: int, upto: int) -> tuple[int, int]:
            ints[k2d.POS] = p
            code = k2d.run_inertia_2d(thetas, no_records, tnet, mo, wk, out, run._replace(steps=upto), floats,
                                      ints, draws)
            if code == k2d.NEED_OUT:
                ints[k2d.N_SLIPS] = ints[k2d.N_AV] = 0
            codes = {k2d.NEED_OUT: -1, k2d.NEED_MU: kernels.NEED_MU, k2d.DONE: kernels.DONE}
            return codes.get(code, kin.RUNAWAY), int(ints[k2d.POS])

        def forces() -> np.ndarray:
            return mo.a + g * (df * floats[k2d.T])

        starts = lambda: int(ints[k2d.N])  # noqa: E731
        forward = lambda: True  # noqa: E731
    if mo.moving.any():
        mo.times[1] = 0.0  # a state above its thresholds at f = 0: it was never at rest
    q, chunk = 0, 1
    while True:
        upto = min(q + chunk, Q)
        code, pos = call(real.buffers.tilt_mu, pos, upto)
        if code == kin.RUNAWAY:
            break
        if starts() > MAX_STARTS:
            raise TiltTestError(f"The dynamic tilt test made {MAX_STARTS} starts of motion without sliding for "
                                "good.")
        if code == kernels.NEED_MU:
            pos, _ = real.streams.extend_tilt(st, (pos, int(st["tilt_u_pos"][0])))
        if code != kernels.DONE:
            continue
        q = upto
        if mo.moving.all() and forward() and _slides_for_good(backend, forces(), mo.v.reshape(N, -1),
                                                              net.normal_load, mu_d):
            break
        if q == Q:
            raise TiltTestError(f"The dynamic tilt test reached the load f = {df * Q + f_bar!r} (TILT_CAP) "
                                "without sliding for good.")
        # In motion, a check every CHUNK tau_dyn; at rest, the wait for the next start runs in closed form.
        chunk = 1 if mo.moving.any() else min(2 * chunk, MAX_REST_CHUNKS)
    return df * float(mo.times[1]) + f_bar, _loads(mo.first, mo.times, net.normal_load, df, f_bar), pos


def _slides_for_good(backend: Any, F: np.ndarray, v: np.ndarray, normal_load: np.ndarray, mu_d: float) -> bool:
    """The reference's proof that a network whose every node moves (in 1D, forward) never sticks again.

    With V the centre-of-mass velocity, w_i = v_i - V and r_i = F_i - N_i sum_j F_j / sum_j N_j (the springs'
    force about their equilibrium under loads uniform per N_i), E = r . K^+ r / 2 + sum_i N_i |w_i|^2 / 2 never
    grows while every node slides (friction removes energy from the w_i, the uniform loads do no work on
    them), so |w_i| <= B_i = sqrt(2 E (1 / N_i - 1 / sum_j N_j)); the load along x, above mu_d, only raises
    V_x, so V_x > B_i for every i keeps every node moving for ever. False where the proof does not apply
    (springs to the ground, loads with a net torque: K^+ r is then not their equilibrium).

    Parameters
    ----------
    F, v : ndarray, shape (N, d)
        Forces (N) and velocities (Ntilde l0 per tau_dyn).
    """
    n = np.asarray(normal_load, dtype=np.float64)
    total = n.sum()
    if F[:, 0].sum() / total <= mu_d:
        return False
    solve = _compliance(backend)
    if solve is None:
        return False
    r = F - np.outer(n, F.sum(axis=0) / total)
    x = solve(r.reshape(-1))
    if x is None:
        return False
    V = n @ v / total
    energy = 0.5 * float(r.reshape(-1) @ x) + 0.5 * float(n @ ((v - V) ** 2).sum(axis=1))
    bound = np.sqrt(2.0 * max(energy, 0.0) * (1.0 / n - 1.0 / total))
    return bool((V[0] > bound).all())


def _compliance(backend: Any) -> Any:
    """x = K^+ r for r in the range of K (a solver of K with the first node held), built once per backend and
    kept on it; None for a network with springs to the ground (or with a floppy part)."""
    if not hasattr(backend, "_tilt_compliance"):
        K = backend.scene.K.tocsc()
        d = backend.scene.network.dim
        shift = np.zeros((K.shape[0], d))
        for c in range(d):
            shift[c::d, c] = 1.0
        scale = abs(K).max() if K.nnz else 1.0
        solver = None
        if abs(K @ shift).max() <= 1e-12 * scale and K.shape[0] > d:
            try:
                lu = splu(K[d:, d:])
            except RuntimeError:  # singular: a part of the network free of the rest
                lu = None
            if lu is not None:
                def solver(r: np.ndarray) -> np.ndarray | None:
                    x = np.concatenate([np.zeros(d), lu.solve(r[d:])])
                    # r not in the range of K (a net torque of the loads): no equilibrium, no proof.
                    ok = np.abs(K @ x - r).max() <= 1e-9 * max(np.abs(r).max(), 1.0)
                    return x if ok else None
        backend._tilt_compliance = solver
    return backend._tilt_compliance


def _loads(first: np.ndarray, times: np.ndarray, normal_load: np.ndarray, df: float,
           f_bar: float) -> dict[str, float]:
    """The loads of ``tilt_loads`` from the watch: each node's first start [t, |F_i|], shape (N, 2), and
    the time every node first moved at once (``times[0]``)."""
    load = df * first[:, 0] + f_bar  # NaN for a node that never started (it slid with the others)
    n = np.asarray(normal_load, dtype=np.float64)
    broke = ~np.isnan(load)
    order = np.argsort(load[broke], kind="stable")
    held = np.cumsum(n[broke][order])
    half = np.flatnonzero(2.0 * held >= n.sum())
    return {"tilt_first_slip": float(np.nanmin(load)) if broke.any() else math.nan,
            "tilt_all_moving": df * float(times[0]) + f_bar,
            "tilt_contact_mean": float(n[broke] @ load[broke] / n[broke].sum()) if broke.all() else math.nan,
            "tilt_half_broken": float(load[broke][order][half[0]]) if half.size else math.nan,
            "tilt_break_ratio": float(first[broke, 1].sum() / n.sum()) if broke.all() else math.nan}
