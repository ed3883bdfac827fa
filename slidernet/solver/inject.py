"""Injected aging (``[tilt] inject``): the thresholds that a test's injected twin reads.

A test of static friction made at a recorded time (the network tilt test of
``mu_eff``) is made twice on the same state with the same draws: on the
thresholds as they are, and on a copy raised by a known law of time,
:func:`injected_thresholds`. The difference between the two readings is the
estimator's response to a known aging, with common random numbers
(docs/model.md, "Injected aging"). This module computes the raised copy and
nothing else: which tests have a twin, and how their draws are shared, is
the realization's (:meth:`slidernet.solver.Realization.tested_thresholds`).
"""

from __future__ import annotations

import numpy as np

from slidernet.config import InjectConfig


def injected_thresholds(mu: np.ndarray, last_slip: np.ndarray, t: float, inject: InjectConfig) -> np.ndarray:
    """A copy of the thresholds ``mu`` raised by ``inject`` at the recorded time ``t``.

    Every threshold is raised by c ln(1 + t / t0) when ``select = 1``; with
    ``select < 1`` only those of the ceil(select N) oldest contacts, the
    nodes that have gone longest without slipping (the smallest
    ``last_slip``; ties: the lower node index first). ``mu`` is left as it
    is.

    Parameters
    ----------
    mu : ndarray of float64, shape (N,)
        The thresholds mu_s of the state at ``t``.
    last_slip : ndarray of float64, shape (N,) or (0,)
        Each node's last slip time in the horizontal evolution, in tau_th
        (0 for a node that has not slipped: its contact age is t); read only
        with ``select < 1``, where it must hold N values.
    t : float
        The recorded time, in tau_th.
    inject : InjectConfig
        The injection: ``c``, ``t0``, ``select``.

    Returns
    -------
    ndarray of float64, shape (N,)
        The raised copy. With c = 0 it equals ``mu`` to the bit.

    Raises
    ------
    ValueError
        If ``select < 1`` and ``last_slip`` does not hold one time per node
        (the scene did not keep the ages: ``Scene.keeps_ages``).

    Examples
    --------
    Four contacts, the two oldest raised (nodes 1 and 3 never slipped: ties
    go to the lower index, so node 1 and node 3 before node 0):

    >>> inject = InjectConfig(c=0.01, t0=1.0, select=0.5)
    >>> raised = injected_thresholds(np.full(4, 0.6), np.array([2.0, 0.0, 5.0, 0.0]), 9.0, inject)
    >>> (raised - 0.6).round(6).tolist()
    [0.0, 0.023026, 0.0, 0.023026]
    """
    raised = np.array(mu, dtype=np.float64, copy=True)
    shift = inject.shift(float(t))
    if inject.select >= 1.0:
        raised += shift
        return raised
    if last_slip.shape != mu.shape:
        raise ValueError(f"an injection into the oldest contacts (select = {inject.select!r}) needs each node's "
                         f"last slip: got {last_slip.shape[0]} times for {mu.size} nodes")
    # The smallest last slip is the oldest contact; a stable sort keeps the lower index first among ties.
    oldest = np.argsort(last_slip, kind="stable")[: inject.raised(mu.size)]
    raised[oldest] += shift
    return raised
