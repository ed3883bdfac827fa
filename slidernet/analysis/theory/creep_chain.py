"""Thermal creep of a chain of sliders on an incline with constant thresholds: the exact periodic orbit.

A symmetric cycle of theta drives a chain of ``n`` sliders, each carrying
f = tan(alpha) downhill, from rest. The orbit is followed slip by slip in
rational arithmetic (:mod:`~slidernet.analysis.theory._exact_orbit`) until
the state at the start of a cycle repeats:

- :func:`chain_orbit`: the orbit at one point (period, transient, velocity);
- :func:`chain_creep`: the steady slips and advance per cycle, vectorised;
- :func:`chain_creep_segments`: the plateaus along the angle or the
  amplitude, with their exact ends (:class:`CreepSegment`);
- :func:`chain_critical_amplitude`: where creep from rest starts;
- :func:`three_slider_onset`: three sliders' first plateau in closed form.

Shares with :mod:`~slidernet.analysis.theory.creep_pair` the checks of the
friction pair and the angle (:mod:`~slidernet.analysis.theory._common`) and
the units; for two sliders every result here is that module's closed form.
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from fractions import Fraction

import numpy as np
from numpy.typing import ArrayLike

from slidernet._validation import check_array, check_scalar
from slidernet.analysis.theory._common import _check_friction, _check_tan
from slidernet.analysis.theory._exact_orbit import _Affine, _chain_orbit, _Window
from slidernet.errors import ConfigError, OrbitError, param_error


def _chain_args(n_sliders: int, mu_s: float, mu_d: float, owner: str) -> tuple[int, Fraction, Fraction]:
    if isinstance(n_sliders, bool) or not isinstance(n_sliders, (int, np.integer)) or n_sliders < 2:
        raise param_error("n_sliders", owner, "an integer >= 2", n_sliders)
    ms, md = _check_friction(mu_s, mu_d, owner)
    return int(n_sliders), Fraction(ms), Fraction(md)


@dataclasses.dataclass(frozen=True)
class ChainOrbit:
    """The steady creep orbit of a chain from rest (:func:`chain_orbit`).

    Attributes
    ----------
    period : int
        Cycles of theta after which the state at the start of a cycle repeats.
    transient : int
        Cycles before the first cycle of the periodic orbit.
    slips : float
        Slips per cycle in the orbit (all sliders; a mean over the period).
    dx : float
        Advance of x_G per cycle in the orbit, in l0.
    """

    period: int
    transient: int
    slips: float
    dx: float


def _orbit_at(n: int, x: float, f: float, mu_s: Fraction, mu_d: Fraction, max_cycles: int) -> ChainOrbit:
    """The orbit at one point, x = A / Ntilde; dx in Ntilde l0."""
    window = _Window(Fraction(0), Fraction(0), Fraction(0))
    period, count, advance, transient = _chain_orbit(n, _Affine(Fraction(f)), _Affine(Fraction(x)), mu_s, mu_d,
                                                     window, max_cycles)
    return ChainOrbit(period, transient, count / period, float(advance.a / period))


def chain_orbit(n_sliders: int, amplitude: float, Ntilde: float, tan_alpha: float, mu_s: float, mu_d: float, *,
                max_cycles: int = 200) -> ChainOrbit:
    """The steady creep orbit of a chain with constant thresholds at one point: period, transient, velocity.

    As :func:`chain_creep` at one (amplitude, tan_alpha), with the orbit's
    period and transient. For three sliders at generic parameters the
    orbit repeats after at most one cycle, with a period of one cycle (300
    random parameter sets, ``benchmarks/creep_orbit_periods.py``); at an
    exact tie of two events the period can be longer (22 cycles at
    A = 0.75 Ntilde, f = 0.171875, mu_s = 0.59375, mu_d = 0.34375, all exact
    in binary).
    From four sliders on the orbits are richer: of 300 random sets of four
    sliders, 54 did not repeat within 200 cycles, and the others had
    periods of up to 39 cycles after transients of up to 170.

    Parameters
    ----------
    n_sliders : int
        Sliders in the chain, >= 2.
    amplitude : float
        A, the amplitude of theta (dimensionless dilation), >= 0.
    Ntilde : float
        N / (k l0), > 0.
    tan_alpha : float
        Downhill load per unit normal load, in (0, mu_d).
    mu_s, mu_d : float
        The constant threshold and the dynamic coefficient, mu_s > mu_d > 0.
    max_cycles : int
        Cycles to follow before giving up on a repeat.

    Returns
    -------
    ChainOrbit

    Raises
    ------
    OrbitError
        The state did not repeat within ``max_cycles`` cycles.

    Examples
    --------
    >>> orbit = chain_orbit(3, 0.55e-7, 1e-7, 0.22, 0.6, 0.5)
    >>> orbit.period, orbit.transient, orbit.slips, round(orbit.dx / 1e-7, 12)
    (1, 1, 6.0, 0.56)
    """
    owner = "chain_orbit"
    n, ms, md = _chain_args(n_sliders, mu_s, mu_d, owner)
    A = check_scalar(amplitude, "amplitude", owner, ">= 0")
    nt = check_scalar(Ntilde, "Ntilde", owner, "> 0")
    f = _check_tan(tan_alpha, float(md), owner)
    orbit = _orbit_at(n, A / nt, f, ms, md, max_cycles)
    return dataclasses.replace(orbit, dx=orbit.dx * nt)


def chain_creep(n_sliders: int, amplitude: ArrayLike, Ntilde: float, tan_alpha: ArrayLike, mu_s: float,
                mu_d: float, *, max_cycles: int = 200) -> tuple[np.ndarray, np.ndarray]:
    """Steady creep of a chain of sliders with constant thresholds under a symmetric cycle of theta (exact).

    The chain starts at rest at theta = 0; theta rises to +A, falls to -A
    and so on (the ``sinusoidal`` driver with phase 0 and a period that is
    a multiple of 4 tau_th). Every slider carries f = tan(alpha) downhill
    and slips by the solver's rule (docs/model.md). The orbit is followed
    slip by slip in rational arithmetic until the state at the start of a
    cycle repeats (:func:`chain_orbit`, which gives the period and the
    transient too). For two sliders this is :func:`pair_creep`. Where the
    orbit does not repeat within ``max_cycles`` (some orbits of four sliders
    and more never do), the result is NaN, with a ``RuntimeWarning``.

    Parameters
    ----------
    n_sliders : int
        Sliders in the chain, >= 2.
    amplitude : float or array_like
        A, the amplitude of theta (dimensionless dilation), >= 0.
    Ntilde : float
        N / (k l0), > 0.
    tan_alpha : float or array_like
        Downhill load per unit normal load, in (0, mu_d); broadcast with ``amplitude``.
    mu_s, mu_d : float
        The constant threshold and the dynamic coefficient, mu_s > mu_d > 0.
    max_cycles : int
        Cycles to follow before giving up on a repeat.

    Returns
    -------
    slips : numpy.ndarray of float, broadcast shape
        Slips per cycle in the steady state (all sliders together; a mean
        over the period when it is longer than one cycle).
    dx : numpy.ndarray of float, broadcast shape
        Advance of x_G per cycle in the steady state, in l0.

    Notes
    -----
    The inputs are taken as the exact binary numbers they are. Where two
    events tie (the ends of :func:`chain_creep_segments`), the orbit follows
    the solver's rules in exact arithmetic (``|F| = mu_s`` sticks; equal
    overloads go to the lowest index), but the solver's floating-point
    forces can break such a tie either way: compare inside a segment.

    Examples
    --------
    Three sliders at A = 0.55 Ntilde: at tan(alpha) = 0.12 the two ends slip
    back and forth and the chain stays put; at 0.22 and 0.26, six slips per
    cycle advance it by 2 (mu_d - f) Ntilde (docs/guides/incline-creep.md
    derives it):

    >>> slips, dx = chain_creep(3, 0.55e-7, 1e-7, [0.12, 0.22, 0.26], 0.6, 0.5)
    >>> slips.tolist(), [round(float(v) / 1e-7, 12) for v in dx]
    ([4.0, 6.0, 6.0], [0.0, 0.56, 0.48])
    """
    owner = "chain_creep"
    n, ms, md = _chain_args(n_sliders, mu_s, mu_d, owner)
    A = check_array(amplitude, "amplitude", owner, ">= 0")
    nt = check_scalar(Ntilde, "Ntilde", owner, "> 0")
    f = check_array(tan_alpha, "tan_alpha", owner)
    A, f = np.broadcast_arrays(A, f)
    for value in np.unique(f):
        _check_tan(value, float(md), owner)
    slips = np.zeros(A.shape)
    dx = np.zeros(A.shape)
    aperiodic = 0
    for idx in np.ndindex(A.shape):
        try:
            orbit = _orbit_at(n, float(A[idx]) / nt, float(f[idx]), ms, md, max_cycles)
        except OrbitError:
            aperiodic += 1
            slips[idx] = dx[idx] = np.nan
            continue
        slips[idx] = orbit.slips
        dx[idx] = orbit.dx * nt
    if aperiodic:
        warnings.warn(f"chain_creep: the orbit of {n} sliders did not repeat within max_cycles = {max_cycles} "
                      f"at {aperiodic} of {A.size} points (NaN there); it may be aperiodic, as some orbits of "
                      "four sliders and more are.", RuntimeWarning, stacklevel=2)
    return slips, dx


@dataclasses.dataclass(frozen=True)
class CreepSegment:
    """An interval of one parameter on which a chain's steady cycle is one sequence of slips.

    On it the advance of x_G per cycle is affine in the parameter:
    ``dx = dx_lo + (p - lo) * (dx_hi - dx_lo) / (hi - lo)``.

    Attributes
    ----------
    over : str
        The parameter: ``"tan_alpha"`` or ``"amplitude"``.
    lo, hi : float
        The ends of the interval (amplitude in the units of theta); the
        orbit at the ends themselves may belong to the neighbouring segment.
    period : int
        Cycles of theta per period of the steady orbit.
    slips : float
        Slips per cycle (all sliders), a mean over the period.
    dx_lo, dx_hi : float
        Advance of x_G per cycle at ``lo`` and at ``hi``, in l0 (the limits from inside).
    """

    over: str
    lo: float
    hi: float
    period: int
    slips: float
    dx_lo: float
    dx_hi: float


def chain_creep_segments(n_sliders: int, Ntilde: float, mu_s: float, mu_d: float, *,
                         tan_alpha: float | tuple[float, float], amplitude: float | tuple[float, float],
                         resolution: float = 1e-9, max_cycles: int = 200) -> list[CreepSegment]:
    """The plateaus of a chain's creep along tan(alpha) or along the amplitude, with their exact ends.

    Exactly one of ``tan_alpha`` and ``amplitude`` is a ``(lo, hi)`` range.
    The range is cut into the intervals on which the steady cycle (from
    rest, as in :func:`chain_creep`) is one fixed sequence of slips; on each
    the velocity is affine in the parameter, and the ends are the exact
    values where two events tie. Along the amplitude the velocity is
    constant on each interval (a staircase); along the angle, for three
    sliders and more, it is not: an interior slider's overshoot grows with f.
    Consecutive intervals with the same slips and the same affine velocity
    are merged.

    Parameters
    ----------
    n_sliders : int
        Sliders in the chain, >= 2.
    Ntilde : float
        N / (k l0), > 0.
    mu_s, mu_d : float
        The constant threshold and the dynamic coefficient, mu_s > mu_d > 0.
    tan_alpha, amplitude : float or (float, float)
        The fixed value of one and the range of the other (tan(alpha) within
        (0, mu_d); the amplitude of theta, dimensionless, >= 0).
    resolution : float
        Each interval is entered this far (relative to the range) past the
        end of the previous one: a segment narrower than that can be missed.
    max_cycles : int
        Cycles to follow before giving up on a repeat.

    Returns
    -------
    list of CreepSegment
        In increasing order, covering the range.

    Examples
    --------
    Two sliders: the staircase of :func:`pair_creep`, steps at mu_s - A / Ntilde + j D.

    >>> for seg in chain_creep_segments(2, 1e-7, 0.6, 0.5, tan_alpha=(0.01, 0.49), amplitude=0.55e-7):
    ...     print(f"{seg.lo:.3f} {seg.hi:.3f} {seg.slips:g} {seg.dx_lo / 1e-7:.3f} {seg.dx_hi / 1e-7:.3f}")
    0.010 0.050 0 0.000 0.000
    0.050 0.250 4 0.400 0.400
    0.250 0.450 8 0.800 0.800
    0.450 0.490 12 1.200 1.200

    Three sliders at tan(alpha) = 0.22: no creep below a critical
    amplitude, then a staircase in the amplitude:

    >>> for seg in chain_creep_segments(3, 1e-7, 0.6, 0.5, tan_alpha=0.22, amplitude=(0.0, 0.95e-7)):
    ...     print(f"{seg.lo / 1e-7:.2f} {seg.hi / 1e-7:.2f} {seg.slips:g} {seg.dx_lo / 1e-7:.3f}")
    0.00 0.46 0 0.000
    0.46 0.66 6 0.560
    0.66 0.82 12 1.120
    0.82 0.86 18 1.680
    0.86 0.95 24 2.240
    """
    owner = "chain_creep_segments"
    n, ms, md = _chain_args(n_sliders, mu_s, mu_d, owner)
    nt = check_scalar(Ntilde, "Ntilde", owner, "> 0")
    ranged = [name for name, value in (("tan_alpha", tan_alpha), ("amplitude", amplitude))
              if isinstance(value, (tuple, list))]
    if len(ranged) != 1:
        raise ConfigError(f"Exactly one of 'tan_alpha' and 'amplitude' of {owner} must be a (lo, hi) range. "
                          f"Got tan_alpha={tan_alpha!r} and amplitude={amplitude!r} instead.")
    over = ranged[0]
    lo_f, hi_f = (float(v) for v in (tan_alpha if over == "tan_alpha" else amplitude))  # type: ignore[union-attr]
    if not (math.isfinite(lo_f) and math.isfinite(hi_f) and lo_f < hi_f):
        raise param_error(over, owner, "a range (lo, hi) with lo < hi", (lo_f, hi_f))
    if not 0.0 < float(resolution) < 1.0:
        raise param_error("resolution", owner, "in (0, 1)", resolution)
    unit = Fraction(1)
    if over == "tan_alpha":
        _check_tan(lo_f, float(md), owner)
        _check_tan(hi_f, float(md), owner)
        A = check_scalar(amplitude, "amplitude", owner, ">= 0")
        x = _Affine(Fraction(A / nt))
        f = _Affine(Fraction(0), Fraction(1))
        lo, hi = Fraction(lo_f), Fraction(hi_f)
    else:
        check_scalar(lo_f, "amplitude", owner, ">= 0")
        f = _Affine(Fraction(_check_tan(tan_alpha, float(md), owner)))  # type: ignore[arg-type]
        x = _Affine(Fraction(0), Fraction(1))
        unit = Fraction(nt)
        lo, hi = Fraction(lo_f / nt), Fraction(hi_f / nt)
    step = (hi - lo) * Fraction(float(resolution))
    # (lo, hi, period, slips, a, b): x_G advances (a + b p) Ntilde l0 per cycle on [lo, hi], exactly.
    exact: list[tuple[Fraction, Fraction, int, Fraction, Fraction, Fraction]] = []
    start = lo
    while start < hi:
        if exact and hi - start < step:
            # A sliver narrower than the resolution at the range's end: the last segment takes it.
            exact[-1] = (*exact[-1][:1], hi, *exact[-1][2:])
            break
        window = _Window(start + step, lo, hi)
        period, count, advance, _ = _chain_orbit(n, f, x, ms, md, window, max_cycles)
        end = window.hi if window.hi > start else start + step
        seg = (start, end, period, Fraction(count, period), advance.a / period, advance.b / period)
        if exact and exact[-1][2:] == seg[2:]:
            seg = (exact.pop()[0], *seg[1:])
        exact.append(seg)
        start = end
    return [CreepSegment(over, float(s * unit), float(e * unit), period, float(slips), float((a + b * s) * nt),
                         float((a + b * e) * nt)) for s, e, period, slips, a, b in exact]


def chain_critical_amplitude(n_sliders: int, Ntilde: float, tan_alpha: float, mu_s: float, mu_d: float, *,
                             amplitude_max: float, resolution: float = 1e-9) -> float:
    """The amplitude of theta from which a chain at rest starts to creep for good, with constant thresholds.

    The lower end of the first segment of :func:`chain_creep_segments`
    (along the amplitude, up to ``amplitude_max``) with a positive velocity;
    below it the steady velocity is zero. For two sliders it is
    (mu_s - f) Ntilde (:func:`pair_critical_amplitude`). NaN if the chain does
    not creep below ``amplitude_max``.

    Examples
    --------
    >>> round(chain_critical_amplitude(2, 1e-7, 0.2, 0.6, 0.5, amplitude_max=2e-7) / 1e-7, 12)
    0.4
    >>> round(chain_critical_amplitude(3, 1e-7, 0.2, 0.6, 0.5, amplitude_max=2e-7) / 1e-7, 12)
    0.6
    """
    segments = chain_creep_segments(n_sliders, Ntilde, mu_s, mu_d, tan_alpha=tan_alpha,
                                    amplitude=(0.0, float(amplitude_max)), resolution=resolution)
    for seg in segments:
        if seg.dx_lo > 0 or seg.dx_hi > 0:
            return seg.lo
    return math.nan


def three_slider_onset(Ntilde: float, tan_alpha: float, mu_s: float, mu_d: float) -> tuple[float, float, float]:
    """Closed form of three sliders' first creeping plateau from rest, with constant thresholds.

    With f = tan(alpha) and D = 2 (mu_s - mu_d), for
    max(mu_s - 2 D, mu_d / 2 - D / 4) < f < 3 mu_d - 2 mu_s
    (docs/guides/incline-creep.md derives it):

    * the critical amplitude from rest is A_c = (3 mu_d - mu_s - 2 f) Ntilde:
      the first fall of theta must bring the uphill end to its threshold
      twice, once to push the middle slider over and once more after it;
    * from A_c up to A_c + D Ntilde each half cycle is three slips (an end
      by D, the middle with an overshoot, the same end again) and x_G
      advances by 2 (mu_d - f) Ntilde per cycle, whatever the amplitude.

    :func:`chain_creep_segments` finds the same numbers from the exact
    orbit, and the rest of the plateaus with them.

    Parameters
    ----------
    Ntilde : float
        N / (k l0), > 0.
    tan_alpha : float
        Downhill load per unit normal load, inside the window above.
    mu_s, mu_d : float
        The constant threshold and the dynamic coefficient.

    Returns
    -------
    A_c, A_next : float
        The amplitudes of theta where the plateau begins and ends.
    dx : float
        Advance of x_G per cycle on the plateau, in l0.

    Examples
    --------
    >>> [round(v / 1e-7, 12) for v in three_slider_onset(1e-7, 0.22, 0.6, 0.5)]
    [0.46, 0.66, 0.56]
    """
    owner = "three_slider_onset"
    ms, md = _check_friction(mu_s, mu_d, owner)
    nt = check_scalar(Ntilde, "Ntilde", owner, "> 0")
    f = check_scalar(tan_alpha, "tan_alpha", owner)
    D = 2.0 * (ms - md)
    lo, hi = max(ms - 2.0 * D, md / 2.0 - D / 4.0), 3.0 * md - 2.0 * ms
    if not lo < f < hi:
        raise param_error("tan_alpha", owner, f"in ({lo!r}, {hi!r}), where the closed form holds", tan_alpha)
    A_c = (3.0 * md - ms - 2.0 * f) * nt
    return A_c, A_c + D * nt, 2.0 * (md - f) * nt
