"""The creep observables of one realization, read exactly from its event catalogue.

A network under a downhill load (``network.f_ext`` along +x) and a cyclic
temperature creeps: x_G advances slip by slip. The catalogue holds every
slip with the time of its driving event, so x_G is known exactly at any
time, not only at the recorded ones:

- per cycle of a periodic driver (period P, in tau_th): x_G at the ends of
  the whole cycles t_c = c P, c = 1 … C = floor(steps / P), and its advance
  over each cycle (the slips with time in [t_{c-1}, t_c): the kernels stamp
  the events of step q in [q, q + 1), so these are the slips between the
  outputs at t_{c-1} and t_c, and cycle 1 takes the relaxation at t = 0);
- the reptation velocity after the transient t_0: with a period, the mean
  advance per cycle over the whole cycles that start at or after t_0
  (``v_creep_cycle``, l0 per cycle) divided by P (``v_creep``, l0 per
  tau_th), with the standard error of that mean from the spread of those
  cycles' advances (``v_creep_cycles_sem``; NaN with fewer than 2 cycles).
  Without a period, or with no whole cycle after t_0: the end-point
  difference (x_G(steps) - x_G(t_0)) / (steps - t_0), with no standard error
  of its own;
- the creep events: the avalanches (one driving slip and the slips it
  triggers, all at the driving event's time) whose advance of x_G along +x
  exceeds ``event_fraction`` times the reference slip ell, with the waiting
  time since the previous creep event.

Each advance is summed from the slips it holds, never formed as a difference
of two positions, so that whole slips add up to rounding. Everything here is
a function of one realization's catalogue; :mod:`slidernet.analysis.observables`
stacks the realizations.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np


class CreepSpec(NamedTuple):
    """What the creep observables of a scene need, fixed once per scene."""

    period: float | None  # the driver's period, in tau_th; None: not periodic
    transient: float  # tau_th
    slip: float  # the reference slip ell, in l0
    threshold: float  # the smallest advance of x_G of a creep event, in l0 (event_fraction * ell)
    weights: np.ndarray  # (N,) w_i = N_i / sum_j N_j: x_G = sum_i w_i u_i


def reference_slip(mu_s_mean: float, mu_d: float, normal_load: np.ndarray, k: np.ndarray, Ntilde: float,
                   slip_factor: float = 2.0) -> float:
    """The slip of one slider held by one spring: ell = (1 + e) (<mu_s> - mu_d) <N_i> Ntilde l0 / <k>, in l0.

    A slider of threshold mu_s and normal load N held by one spring of
    stiffness k slips by (1 + e) (mu_s - mu_d) N / k (docs/model.md section 1;
    e = ``friction.overshoot``, 1 for the paper's slip); in the model's units
    (forces in N, stiffnesses in k0 = N / (Ntilde l0)) that is
    (1 + e) (mu_s - mu_d) N_i Ntilde l0 / k. Means over the law of mu_s, the
    nodes and the springs.

    Parameters
    ----------
    mu_s_mean : float
        Mean of p(mu_s), conditioned on mu_s > mu_d.
    mu_d : float
        Dynamic friction coefficient.
    normal_load : ndarray, shape (N,)
        Normal loads, in N.
    k : ndarray, shape (E,)
        Spring stiffnesses, in k0.
    Ntilde : float
        N / (k l0).
    slip_factor : float
        1 + e (2.0: the paper's slip).

    Examples
    --------
    >>> round(reference_slip(0.6, 0.5, np.ones(2), np.ones(1), 1e-7) / 1e-8, 12)  # 2 (0.6 - 0.5) 1e-7 / 1e-8
    2.0
    """
    return float(slip_factor * (mu_s_mean - mu_d) * np.mean(normal_load) * Ntilde / np.mean(k))


def whole_cycles(steps: int, period: float) -> int:
    """The number C of whole cycles of ``period`` (tau_th) in ``steps`` (tau_th).

    >>> whole_cycles(100, 10.0), whole_cycles(105, 10.0), whole_cycles(9, 10.0)
    (10, 10, 0)
    """
    # The small excess absorbs the rounding of steps / period for a period such as 0.1.
    return math.floor(steps / period * (1.0 + 1e-12))


def avalanches(events: dict[str, np.ndarray], weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The catalogue's slips grouped by avalanche: its time and its advance of x_G.

    Parameters
    ----------
    events : dict of ndarray
        The event catalogue (:meth:`slidernet.solver.Realization.events`):
        ``time`` (tau_th), ``node``, ``avalanche`` (non-decreasing ids),
        ``dx`` (l0).
    weights : ndarray, shape (N,)
        w_i = N_i / sum_j N_j.

    Returns
    -------
    time : ndarray, shape (A,)
        The time of each avalanche's driving event, in tau_th (0 for the
        relaxation at t = 0), in increasing order.
    dx_G : ndarray, shape (A,)
        The advance of x_G along x over each avalanche, in l0.
    """
    ids = np.asarray(events["avalanche"])
    if ids.size == 0:
        return np.zeros(0), np.zeros(0)
    starts = np.flatnonzero(np.concatenate([[True], ids[1:] != ids[:-1]]))
    dx = weights[np.asarray(events["node"])] * np.asarray(events["dx"])
    return np.asarray(events["time"], dtype=np.float64)[starts], np.add.reduceat(dx, starts)


def creep_record(events: dict[str, np.ndarray], complete: bool, steps: int, spec: CreepSpec) -> dict[str, Any]:
    """The creep observables of one realization (see the module docstring).

    Parameters
    ----------
    events : dict of ndarray
        The realization's event catalogue, as :func:`avalanches` reads it.
    complete : bool
        False if the catalogue stopped at ``solver.max_events``: every value
        is then NaN and no event is listed, since x_G can no longer be read
        from it.
    steps : int
        The run's duration, in tau_th.
    spec : CreepSpec
        The scene's settings.

    Returns
    -------
    dict
        ``cycle_end`` (the times c P, tau_th), ``x_G_cycle``, ``dx_G_cycle``
        (l0), each of shape (C,) and only with a period; ``creep_slip`` and
        ``creep_threshold`` (the scene's ell and event threshold, l0);
        ``v_creep`` (l0 / tau_th), ``v_creep_cycle`` (l0 per cycle; NaN
        without a period), ``v_creep_cycles_sem`` (l0 / tau_th), and
        ``creep_events``: a dict of arrays of shape (E,), ``time`` (tau_th),
        ``dx_G`` (l0) and ``wait`` (tau_th since the previous creep event,
        NaN for the first).

    Examples
    --------
    Two avalanches in the first cycle of 10 tau_th, one in the second:

    >>> spec = CreepSpec(period=10.0, transient=0.0, slip=2.0, threshold=0.5, weights=np.array([0.5, 0.5]))
    >>> ev = {"time": np.array([2.5, 2.5, 7.0, 12.0]), "node": np.array([1, 0, 1, 0]),
    ...       "avalanche": np.array([1, 1, 2, 3]), "dx": np.array([2.0, 2.0, -2.0, 2.0])}
    >>> rec = creep_record(ev, True, 20, spec)
    >>> rec["dx_G_cycle"].tolist(), rec["x_G_cycle"].tolist(), float(rec["v_creep_cycle"])
    ([1.0, 1.0], [1.0, 2.0], 1.0)
    >>> rec["creep_events"]["time"].tolist(), rec["creep_events"]["wait"].tolist()
    ([2.5, 12.0], [nan, 9.5])
    """
    P = spec.period
    C = whole_cycles(steps, P) if P is not None else 0
    ends = P * np.arange(1, C + 1) if P is not None else np.zeros(0)
    out: dict[str, Any] = {"creep_slip": np.float64(spec.slip), "creep_threshold": np.float64(spec.threshold)}
    if not complete:
        nothing = np.zeros(0)
        out.update(v_creep=np.float64(np.nan), v_creep_cycle=np.float64(np.nan),
                   v_creep_cycles_sem=np.float64(np.nan),
                   creep_events={"time": nothing, "dx_G": nothing, "wait": nothing})
        if P is not None:
            out.update(cycle_end=ends, x_G_cycle=np.full(C, np.nan), dx_G_cycle=np.full(C, np.nan))
        return out
    time, dx_G = avalanches(events, spec.weights)
    t0 = spec.transient
    first = math.ceil(t0 / P * (1.0 - 1e-12)) if P is not None else C  # the first whole cycle after t0
    if P is not None:
        # Cycle c (1-based) takes the slips with time in [t_{c-1}, t_c): the kernels stamp the events of
        # step q in [q, q + 1), so these are exactly the slips between the outputs at t_{c-1} and t_c.
        cycle = np.searchsorted(ends, time, side="right")
        dx_cycle = np.bincount(cycle, weights=dx_G, minlength=C + 1)[:C]
        out["cycle_end"] = ends
        out["x_G_cycle"] = np.cumsum(dx_cycle)
        out["dx_G_cycle"] = dx_cycle
    if first < C:
        kept = out["dx_G_cycle"][first:]
        v_cycle = float(kept.mean())
        out["v_creep_cycle"] = np.float64(v_cycle)
        out["v_creep"] = np.float64(v_cycle / P)
        sem = kept.std(ddof=1) / math.sqrt(kept.size) / P if kept.size > 1 else np.nan
        out["v_creep_cycles_sem"] = np.float64(sem)
    else:
        after = time >= t0
        out["v_creep"] = np.float64(dx_G[after].sum() / (steps - t0))
        out["v_creep_cycle"] = np.float64(np.nan)
        out["v_creep_cycles_sem"] = np.float64(np.nan)
    creep = dx_G > spec.threshold
    t_ev = time[creep]
    wait = np.concatenate([[np.nan], np.diff(t_ev)]) if t_ev.size else np.zeros(0)
    out["creep_events"] = {"time": t_ev, "dx_G": dx_G[creep], "wait": wait}
    return out
