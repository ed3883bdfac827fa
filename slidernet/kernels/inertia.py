"""The equations of motion of a 1D network with inertia, event-driven and exact between events.

This is the compiled twin of the reference integrator
(:mod:`slidernet.validation.dynamics`): the same equations, the same stick,
start, stop and restart rules, the same order of threshold draws, the same
counting (one rearrangement per start of motion). Units are the kernels':
u in Ntilde l0, theta in Ntilde, forces in N, K in k0, and during motion
the local time s = (t - t_0) / tau_dyn, in which node i (mass N_i) obeys

    N_i d^2u_i/ds^2 = F_i - mu_d N_i sigma_i,    F = -K u + (theta - theta(0)) g + f_ext,

with sigma_i = +-1 the sign of its motion (the sign of F_i when it started).

How a phase (the moving set and the signs fixed, theta linear in s) is
solved, through the modes of the moving segment, with its events found in
closed form or by a safeguarded search, is
:mod:`slidernet.kernels.inertia_phase`'s. This module holds the event loop: the starts, the stops and their draws,
the records, the logs.

**The traps.** A node starts along F_j (sigma_j = sign F_j) with v = 0; at
s = 0 of the next phase its stop function is 0 and rising, so the search
skips it there (the reference's placeholder). A node that stops and finds
|F_i| above its redrawn threshold starts again at once (a new
rearrangement); stuck nodes above their thresholds start, the largest
overload first, one by one (simultaneous starts), each counted. A moving
node found a hair past its stop at s = 0 (rounding after another node's
event) stops at s = 0, so a sign never flips under the friction
(chattering).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from slidernet.kernels.heap import replace_threshold
from slidernet.kernels.inertia_phase import NO_EVENT, START, STOP, force, phase
from slidernet.kernels.jit import kernel_jit
from slidernet.kernels.state import DONE, NEED_EVENTS, NEED_MU

# The helpers are inlined, as those of inertia_phase (see there).

# Return codes besides DONE, NEED_MU and NEED_EVENTS (a log is full): a node slid this long.
RUNAWAY = 8

# A node that slides this long (in tau_dyn) without its velocity ever returning to zero is sliding for ever
# (the reference's MAX_SLIP_DURATION).
MAX_SLIP_DURATION = 1000.0

# Integer scalars (istate) and float scalars (fstate) of a realization.
I_STAGE, I_Q, I_REC, I_N, I_OVERLAP, I_SLIPS, I_POS, I_NODE, I_AVAL, I_AV_START = range(10)
F_T, F_CLOCK, F_STOP_SPEED, F_WORK, F_E0, F_T0 = range(6)
# Stages of the loop, resumable at each: relax the initial overload, record step q, run step q.
STAGE_OVERLOAD, STAGE_RELAX, STAGE_RECORD, STAGE_STEP = range(4)


class Motion(NamedTuple):
    """The nodes' state, shape (N,) each: displacements ``u`` (Ntilde l0), velocities ``v`` (Ntilde l0 per
    tau_dyn), signs of motion ``sig``, thresholds ``mu`` and ``lim`` = mu N_i, ``moving`` (1 or 0), and
    the start of each node's current motion: ``start_t`` (tau_th), ``start_clock`` (tau_dyn), ``start_u``."""

    u: np.ndarray
    v: np.ndarray
    sig: np.ndarray
    mu: np.ndarray
    lim: np.ndarray
    moving: np.ndarray
    start_t: np.ndarray
    start_clock: np.ndarray
    start_u: np.ndarray
    best: np.ndarray  # (3,): the running mu_max, its holder and n_records (kernels.heap.replace_threshold)
    # The dynamic tilt test's (slidernet.solver.inertia_tilt) watch, shape (N, 2) and (2,), or (0, 2) and (0,)
    # where nothing watches (a run: no cost): each node's first start, [t (tau_th), |F_i| (N)]; the first time
    # every node moved at once and the last start from rest (nothing moving before, not a restart), tau_th;
    # NaN until they happen. Not part of a snapshot.
    first: np.ndarray
    times: np.ndarray




class Log(NamedTuple):
    """What a run writes: the records at the recorded steps (``out_n``, ``out_mu_max``, ``out_xg``); one
    row per slip that came to rest (``slip_start``, ``slip_end`` in tau_th, ``slip_duration`` in tau_th,
    ``slip_node``, ``slip_du`` in Ntilde l0); one row per avalanche from rest to rest (``av_start``,
    ``av_end`` in tau_th, ``av_work`` the work of the loads f_ext + (theta - theta(0)) g on the motion,
    ``av_e0`` and ``av_e1`` the elastic energy u.K u / 2 before and after, in N Ntilde l0, ``av_slips`` the
    slips logged by its end: its own are those from the previous avalanche's)."""

    out_n: np.ndarray
    out_mu_max: np.ndarray
    out_xg: np.ndarray
    slip_start: np.ndarray
    slip_end: np.ndarray
    slip_duration: np.ndarray
    slip_node: np.ndarray
    slip_du: np.ndarray
    av_start: np.ndarray
    av_end: np.ndarray
    av_work: np.ndarray
    av_e0: np.ndarray
    av_e1: np.ndarray
    av_slips: np.ndarray




@kernel_jit(forceinline=True)
def elastic_energy(net, u):
    """u . K u / 2, in N Ntilde l0."""
    e = 0.0
    for i in range(u.size):
        Ku = 0.0
        for p in range(net.indptr[i], net.indptr[i + 1]):
            Ku += net.K_data[p] * u[net.indices[p]]
        e += u[i] * Ku
    return 0.5 * e



@kernel_jit(forceinline=True)
def start_node(mo, istate, fstate, i, F):
    """Node i starts along F (its force, N): one rearrangement, v = 0."""
    moving_any = False
    for j in range(mo.u.size):
        if mo.moving[j]:
            moving_any = True
            break
    if moving_any:
        istate[I_OVERLAP] += 1
    istate[I_N] += 1
    mo.moving[i] = 1
    mo.sig[i] = 1.0 if F > 0.0 else -1.0
    mo.v[i] = 0.0
    mo.start_t[i] = fstate[F_T]
    mo.start_clock[i] = fstate[F_CLOCK]
    mo.start_u[i] = mo.u[i]
    if mo.first.shape[0] > 0:
        if math.isnan(mo.first[i, 0]):
            mo.first[i, 0] = fstate[F_T]
            mo.first[i, 1] = abs(F)
        if math.isnan(mo.times[0]):
            every = True
            for j in range(mo.u.size):
                if not mo.moving[j]:
                    every = False
                    break
            if every:
                mo.times[0] = fstate[F_T]


@kernel_jit(forceinline=True)
def any_moving(mo):
    for i in range(mo.u.size):
        if mo.moving[i]:
            return True
    return False


@kernel_jit(forceinline=True)
def begin_avalanche(net, mo, fstate):
    """The network leaves rest: the avalanche's start time and elastic energy, its work zeroed."""
    fstate[F_T0] = fstate[F_T]
    fstate[F_E0] = elastic_energy(net, mo.u)
    fstate[F_WORK] = 0.0


@kernel_jit(forceinline=True)
def most_loaded(net, f_ext, mo, dtheta, ratio):
    """The stuck node with the largest |F_j| / (mu_s,j N_j) (``ratio``) or |F_j| - mu_s,j N_j, the lowest
    index of a tie (numpy's argmax, as the reference): (node, F_node, that value); (-1, 0, -inf) if none."""
    best = -math.inf
    node = -1
    F_node = 0.0
    for j in range(mo.u.size):
        if mo.moving[j]:
            continue
        F = force(net, f_ext, mo.u, j, dtheta)
        value = abs(F) / mo.lim[j] if ratio else abs(F) - mo.lim[j]
        if value > best:
            best = value
            node = j
            F_node = F
    return node, F_node, best


@kernel_jit(forceinline=True)
def start_overloaded(net, f_ext, mo, istate, fstate, dtheta):
    """Start every stuck node above its threshold, the largest overload |F|/(mu_s N) first, one at a time."""
    while True:
        node, Fbest, best = most_loaded(net, f_ext, mo, dtheta, True)
        if best <= 1.0:
            return
        if not any_moving(mo):
            begin_avalanche(net, mo, fstate)
        start_node(mo, istate, fstate, node, Fbest)


@kernel_jit(forceinline=True)
def after_phase(net, f_ext, mo, istate, fstate, log, draws, what, node, dtheta, tau_ratio):
    """Apply the event that ended a phase (t and u already at its time): a stop (the slip logged, a new
    threshold drawn) or a start; then start whatever is above its threshold; log an avalanche that ended."""
    if what == STOP:
        i = node
        fstate[F_STOP_SPEED] = max(fstate[F_STOP_SPEED], abs(mo.v[i]))
        mo.moving[i] = 0
        mo.v[i] = 0.0
        k = istate[I_SLIPS]
        log.slip_start[k] = mo.start_t[i]
        log.slip_end[k] = fstate[F_T]
        log.slip_duration[k] = (fstate[F_CLOCK] - mo.start_clock[i]) * tau_ratio
        log.slip_node[k] = i
        log.slip_du[k] = mo.u[i] - mo.start_u[i]
        istate[I_SLIPS] = k + 1
        # A new place on the substrate: a new threshold.
        replace_threshold(mo.mu, i, draws[istate[I_POS]], mo.best)
        istate[I_POS] += 1
        mo.lim[i] = mo.mu[i] * net.normal_load[i]
    elif what == START:
        j_best, F_best, _ = most_loaded(net, f_ext, mo, dtheta, False)
        start_node(mo, istate, fstate, j_best, F_best)
    # At rest (if only for an instant, before a restart): the avalanche ends here, kinetic energy zero.
    if not any_moving(mo):
        k = istate[I_AVAL]
        log.av_start[k] = fstate[F_T0]
        log.av_end[k] = fstate[F_T]
        log.av_work[k] = fstate[F_WORK]
        log.av_e0[k] = fstate[F_E0]
        log.av_e1[k] = elastic_energy(net, mo.u)
        log.av_slips[k] = istate[I_SLIPS]
        istate[I_AVAL] = k + 1
    start_overloaded(net, f_ext, mo, istate, fstate, dtheta)


@kernel_jit(forceinline=True)
def runaway(mo, fstate, istate):
    """A node has moved MAX_SLIP_DURATION tau_dyn without stopping: True, and its index in istate[I_NODE]."""
    longest = -1.0
    node = -1
    for i in range(mo.u.size):
        if mo.moving[i] and fstate[F_CLOCK] - mo.start_clock[i] > longest:
            longest = fstate[F_CLOCK] - mo.start_clock[i]
            node = i
    if node >= 0 and longest >= MAX_SLIP_DURATION:
        istate[I_NODE] = node
        return True
    return False


@kernel_jit()
def run_inertia(net, f_ext, mu_d, tau_ratio, thetas, rec, steps, mo, wk, log, draws, istate, fstate):
    """Run one realization of a 1D network with inertia through ``steps`` thermal steps, resumably.

    Mirrors the reference's ``_Realization.run`` and ``_segment``: the initial overload relaxed with theta
    frozen at theta(0), then per step q the records (if q is recorded) and the motion with theta linear
    from thetas[q] to thetas[q + 1] (Ntilde). Returns DONE, NEED_MU (the threshold buffer ``draws`` is read
    to its end: refill it and set istate[I_POS] = 0), NEED_EVENTS (a log is full: grow it) or RUNAWAY
    (istate[I_NODE] slid MAX_SLIP_DURATION tau_dyn); it checks before each phase, so every return is at a
    clean point, and calling it again resumes.
    """
    theta0 = thetas[0]
    while True:
        if istate[I_STAGE] == STAGE_OVERLOAD:
            # An f_ext above some thresholds is relaxed with theta frozen at theta(0), before the t = 0 record.
            start_overloaded(net, f_ext, mo, istate, fstate, 0.0)
            istate[I_STAGE] = STAGE_RELAX
        elif istate[I_STAGE] == STAGE_RELAX:
            if not any_moving(mo):
                istate[I_STAGE] = STAGE_RECORD
                continue
            if istate[I_POS] >= draws.size:
                return NEED_MU
            if istate[I_SLIPS] >= log.slip_node.size or istate[I_AVAL] >= log.av_end.size:
                return NEED_EVENTS
            s1, what, node, work = phase(net, f_ext, mo, wk, mu_d, 0.0, 0.0, MAX_SLIP_DURATION)
            fstate[F_CLOCK] += s1
            fstate[F_WORK] += work
            after_phase(net, f_ext, mo, istate, fstate, log, draws, what, node, 0.0, tau_ratio)
            if runaway(mo, fstate, istate):
                return RUNAWAY
        elif istate[I_STAGE] == STAGE_RECORD:
            q = istate[I_Q]
            k = istate[I_REC]
            if k < rec.size and rec[k] == q:
                log.out_n[k] = istate[I_N]
                mx = -math.inf
                xg = 0.0
                for i in range(mo.u.size):
                    mx = max(mx, mo.mu[i])
                    xg += net.w[i] * mo.u[i]
                log.out_mu_max[k] = mx
                log.out_xg[k] = xg
                istate[I_REC] = k + 1
            if q == steps:
                return DONE
            istate[I_STAGE] = STAGE_STEP
        else:
            q = istate[I_Q]
            theta_a = thetas[q]
            rate = thetas[q + 1] - theta_a  # per tau_th
            t = fstate[F_T]
            theta = theta_a + rate * (t - q)
            if any_moving(mo):
                if istate[I_POS] >= draws.size:
                    return NEED_MU
                if istate[I_SLIPS] >= log.slip_node.size or istate[I_AVAL] >= log.av_end.size:
                    return NEED_EVENTS
                left = (q + 1 - t) / tau_ratio
                s1, what, node, work = phase(net, f_ext, mo, wk, mu_d, theta - theta0, rate * tau_ratio,
                                             min(left, MAX_SLIP_DURATION))
                fstate[F_CLOCK] += s1
                fstate[F_WORK] += work
                if what == NO_EVENT and s1 >= left:
                    fstate[F_T] = float(q + 1)
                    istate[I_Q] = q + 1
                    istate[I_STAGE] = STAGE_RECORD
                    continue
                fstate[F_T] = t + tau_ratio * s1
                theta = theta_a + rate * (fstate[F_T] - q)
                after_phase(net, f_ext, mo, istate, fstate, log, draws, what, node, theta - theta0, tau_ratio)
                if runaway(mo, fstate, istate):
                    return RUNAWAY
            else:
                # Nothing moves: F_j = F_j(t) + g_j rate x, the first start in closed form (eq. `critique`).
                wait = math.inf
                j_best = -1
                for j in range(mo.u.size):
                    d = net.g[j] * rate
                    if d == 0.0:
                        continue
                    F = force(net, f_ext, mo.u, j, theta - theta0)
                    x = (mo.lim[j] - F) / d if d > 0.0 else (mo.lim[j] + F) / -d
                    x = max(x, 0.0)
                    if x < wait:
                        wait = x
                        j_best = j
                # Inclusive at the end of the step, as the solver's eq. `critique`.
                if j_best < 0 or t + wait > q + 1:
                    fstate[F_T] = float(q + 1)
                    istate[I_Q] = q + 1
                    istate[I_STAGE] = STAGE_RECORD
                    continue
                fstate[F_T] = t + wait
                theta = theta_a + rate * (fstate[F_T] - q)
                if mo.times.size:
                    mo.times[1] = fstate[F_T]
                begin_avalanche(net, mo, fstate)
                start_node(mo, istate, fstate, j_best, force(net, f_ext, mo.u, j_best, theta - theta0))
                start_overloaded(net, f_ext, mo, istate, fstate, theta - theta0)
