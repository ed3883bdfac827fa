"""Thermal creep of two sliders on an incline with constant thresholds, in closed form.

theta drives the spring between two sliders that each carry f = tan(alpha)
downhill; with constant thresholds every slip has the same length, so the
motion between two turning points of theta is a closed-form map:

- :func:`pair_creep_slips`: the slips in each monotone stretch of theta;
- :func:`pair_creep`: the steady creep under a symmetric cycle, from rest;
- :func:`pair_creep_steps`: where that staircase steps up along the angle;
- :func:`pair_critical_amplitude`: the amplitudes below which creep stops.

Shares with :mod:`~slidernet.analysis.theory.creep_chain` (any number of
sliders, followed slip by slip) the checks of the friction pair and the
angle (:mod:`~slidernet.analysis.theory._common`) and the units below;
:func:`~slidernet.analysis.theory.chain_creep` with two sliders gives the
same numbers.

In the kernels' units (forces in N, theta and lengths in Ntilde, k = 1) the
spring's compression is G = theta - (u_2 - u_1). On an incline every slider
carries f = tan(alpha) downhill (+x): slider 2 feels f + G and slider 1
f - G. For 0 < f < mu_d every slip is downhill: slider 2 yields at
G = U = mu_s - f and slider 1 at G = L = f - mu_s (the backward thresholds
lie beyond these), each slip has the length D = 2 (mu_s - mu_d) and moves G
by -D (slider 2) or +D (slider 1), and it moves x_G by D / 2. Between two
turning points theta is monotone, G follows theta, and each arrival at U
(or L) is one slip: the motion is a map of G from one turning point to the
next, exact and closed-form.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from slidernet._validation import check_array, check_scalar
from slidernet.analysis.theory._common import _check_friction, _check_tan


def _pair_creep_args(tan_alpha: float, mu_s: float, mu_d: float, owner: str) -> tuple[float, float, float]:
    ms, md = _check_friction(mu_s, mu_d, owner)
    f = _check_tan(tan_alpha, md, owner)
    return ms - f, f - ms, 2.0 * (ms - md)


def pair_creep_slips(turning_points: ArrayLike, tan_alpha: float, mu_s: float, mu_d: float) -> np.ndarray:
    """Slips of two sliders with constant thresholds on an incline, per monotone stretch of theta (exact).

    The spring is at rest at the first turning point. On a rise of theta by
    R from G_0, slider 2 slips each time G reaches U = mu_s - f:
    floor((R - (U - G_0)) / D) + 1 times if R >= U - G_0, else never, and
    G ends at G_0 + R - (slips) D; a fall is the mirror image at
    L = f - mu_s (slider 1 slips). f = tan(alpha), D = 2 (mu_s - mu_d).

    Parameters
    ----------
    turning_points : array_like, shape (K,)
        theta / Ntilde at t = 0 and at each later extreme, in order (the
        values of theta where it turns, or any points between which it is
        monotone).
    tan_alpha : float
        Downhill load per unit normal load, in (0, mu_d).
    mu_s, mu_d : float
        The constant static threshold and the dynamic coefficient, mu_s > mu_d.

    Returns
    -------
    numpy.ndarray of int, shape (K - 1,)
        Slips in each stretch: by slider 2 on a rise, by slider 1 on a fall.

    Examples
    --------
    Rest at theta = 0, then theta / Ntilde = 0.6, -0.6, 0.6 with f = 0.1:
    U = 0.5, one slip on the way up (G: 0.5 -> 0.3, then 0.4 at the top),
    two on the way down (at G = -0.5 and again after a further fall of D = 0.2),
    two on the next rise: two slips per stretch from then on.

    >>> pair_creep_slips([0.0, 0.6, -0.6, 0.6], 0.1, 0.6, 0.5).tolist()
    [1, 2, 2]
    """
    owner = "pair_creep_slips"
    U, L, D = _pair_creep_args(tan_alpha, mu_s, mu_d, owner)
    theta = check_array(turning_points, "turning_points", owner).ravel()
    G = 0.0
    slips = np.zeros(max(theta.size - 1, 0), dtype=np.int64)
    for k in range(theta.size - 1):
        R = float(theta[k + 1] - theta[k])
        if R >= 0.0:
            gap = U - G
            n = math.floor((R - gap) / D) + 1 if R >= gap else 0
            G += R - n * D
        else:
            gap = G - L
            n = math.floor((-R - gap) / D) + 1 if -R >= gap else 0
            G += R + n * D
        slips[k] = n
    return slips


def pair_creep(amplitude: ArrayLike, Ntilde: float, tan_alpha: ArrayLike, mu_s: float,
               mu_d: float) -> tuple[np.ndarray, np.ndarray]:
    """Steady creep of two sliders under a symmetric cycle of theta, from rest (closed form).

    theta starts at 0 with the spring at rest, rises to +A, falls to -A, and
    so on (the ``sinusoidal`` driver with phase 0 and a period that is a
    multiple of 4 tau_th samples exactly these extremes). With
    x = A / Ntilde - (mu_s - f), f = tan(alpha), D = 2 (mu_s - mu_d):

    * x < 0: theta never brings a slider to its threshold: no slip, v = 0;
    * x >= 0: after the first rise, G sits D - (x mod D) below U, and from the
      first fall on every stretch of theta has m = 2 floor(x / D) + 2 slips.
      Each slider advances m D per cycle, and so does x_G.

    The velocity is a staircase in the angle: m steps up by 2 wherever
    tan(alpha) crosses mu_s - A / Ntilde + j D (:func:`pair_creep_steps`).
    From rest the critical amplitude is A_c = (mu_s - f) Ntilde; for any
    state, reptation cannot last below (mu_d - f) Ntilde
    (:func:`pair_critical_amplitude`).

    Parameters
    ----------
    amplitude : float or array_like
        A, the amplitude of theta (dimensionless dilation), >= 0.
    Ntilde : float
        N / (k l0), > 0.
    tan_alpha : float or array_like
        Downhill load per unit normal load, in (0, mu_d); broadcast with ``amplitude``.
    mu_s, mu_d : float
        The constant threshold and the dynamic coefficient.

    Returns
    -------
    m : numpy.ndarray of int
        Slips per half cycle in the steady state (each slider slips m times per cycle).
    dx : numpy.ndarray
        Advance of x_G per cycle, in l0: m D Ntilde.

    Examples
    --------
    >>> m, dx = pair_creep(0.5e-7, 1e-7, [0.05, 0.15, 0.3, 0.45], 0.6, 0.5)
    >>> m.tolist(), [round(float(v) / 1e-7, 12) for v in dx]
    ([0, 2, 4, 4], [0.0, 0.4, 0.8, 0.8])
    """
    owner = "pair_creep"
    A = check_array(amplitude, "amplitude", owner, ">= 0")
    nt = check_scalar(Ntilde, "Ntilde", owner, "> 0")
    f = check_array(tan_alpha, "tan_alpha", owner)
    for value in np.unique(f):
        _pair_creep_args(value, mu_s, mu_d, owner)
    D = 2.0 * (float(mu_s) - float(mu_d))
    x = A / nt - (float(mu_s) - f)
    m = np.where(x >= 0.0, 2 * np.floor(np.maximum(x, 0.0) / D).astype(np.int64) + 2, 0)
    return m, m * D * nt


def pair_creep_steps(amplitude: float, Ntilde: float, mu_s: float, mu_d: float) -> np.ndarray:
    """The values of tan(alpha) in (0, mu_d) where :func:`pair_creep`'s staircase steps up.

    mu_s - A / Ntilde + j D for j = 0, 1, ... : below the first, no creep;
    above the j-th (j from 0), m = 2 j + 2 slips per half cycle.

    Examples
    --------
    >>> pair_creep_steps(0.6e-7, 1e-7, 0.6, 0.5).round(12).tolist()
    [0.2, 0.4]
    """
    D = 2.0 * (float(mu_s) - float(mu_d))
    first = float(mu_s) - float(amplitude) / float(Ntilde)
    j = np.arange(0, math.ceil((float(mu_d) - first) / D) + 1)
    steps = first + j * D
    return steps[(steps > 0.0) & (steps < float(mu_d))]


def pair_critical_amplitude(Ntilde: float, tan_alpha: float, mu_s: float, mu_d: float) -> tuple[float, float]:
    """The amplitudes of theta below which two sliders on an incline do not creep.

    Returns ``(from_rest, any_state)``:

    * ``from_rest`` = (mu_s - f) Ntilde: starting from rest, no slider
      reaches its threshold below it, and at or above it creep never stops
      (:func:`pair_creep`);
    * ``any_state`` = (mu_d - f) Ntilde: whatever the state, below it the
      peak-to-peak swing 2 A / Ntilde is shorter than the band
      W - D = 2 (mu_d - f) that G must cross between a slip of slider 2
      (which leaves G at least D below U) and one of slider 1, so creep
      stops after at most one stretch of slips. Between the two, whether
      creep lasts depends on the state: every slip is D, so G stays
      congruent to theta modulo D, and a cycle of theta about a mean other
      than the spring's rest value can keep creeping where one from rest
      cannot. Elasticity makes the threshold history-dependent.

    Examples
    --------
    >>> [round(a / 1e-7, 12) for a in pair_critical_amplitude(1e-7, 0.1, 0.6, 0.5)]
    [0.5, 0.4]
    """
    _pair_creep_args(tan_alpha, mu_s, mu_d, "pair_critical_amplitude")
    nt = float(Ntilde)
    return (float(mu_s) - float(tan_alpha)) * nt, (float(mu_d) - float(tan_alpha)) * nt
