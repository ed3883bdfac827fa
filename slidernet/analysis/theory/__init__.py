"""Predictions of the model to compare simulations against: the paper's section IV and thermal creep.

Everything here is a reference for the solver, and shares no code with it.
Units follow docs/model.md: lengths in l0, time in tau_th, friction
coefficients dimensionless. ``n`` is always the number of rearrangements
since t = 0, so the initial state holds two drawn thresholds and after ``n``
rearrangements ``n + 2`` thresholds have been drawn in all (docs/model.md,
section 4). The paper counts from an initial step n = 1 and therefore writes
``n + 1`` for the same number.

Three kinds of results live side by side and the docstrings say which is which:

* exact statements about the threshold sequence, which hold for every
  distribution p(mu_s) -- :func:`mu_max_cdf`, :func:`mu_max_moments`,
  :func:`harmonic`, :func:`mean_records`;
* the paper's approximate laws -- :func:`mean_rearrangements` (eq. ``slope``),
  :func:`mu_max_leading` (eq. ``mumaxth``) and :func:`msd` (order of
  magnitude only);
* thermal creep on an incline with constant thresholds: closed forms for
  two sliders (:func:`pair_creep` and its companions) and for three sliders'
  first plateau (:func:`three_slider_onset`), and the exact periodic orbit
  of any chain, followed slip by slip in rational arithmetic
  (:func:`chain_creep`, :func:`chain_creep_segments`,
  :func:`chain_critical_amplitude`).

None of them holds with contact strengthening (``[friction.strengthening]``,
docs/model.md, "Contact strengthening"): the thresholds are then draws
raised by the age of their contact, no longer a sequence of i.i.d. draws,
so the exact statistics of mu_max and of its records, the paper's laws
built on them (eq. ``mumaxth``; eq. ``slope`` assumes thresholds that do
not change between slips) and the creep of constant thresholds describe
runs without it only.

Each kind has its module, and every public name is re-exported here, so
``from slidernet.analysis.theory import mu_max_moments`` is the way to use
them:

- :mod:`~slidernet.analysis.theory.extremes`: the exact statistics of mu_max
  and of its records;
- :mod:`~slidernet.analysis.theory.paper_laws`: the paper's approximate laws;
- :mod:`~slidernet.analysis.theory.creep_pair`: two sliders' creep in closed
  form;
- :mod:`~slidernet.analysis.theory.creep_chain`: a chain's exact orbit, on
  the rational arithmetic of ``_exact_orbit``.

The two creep modules share their checks of the friction pair and the angle
(``_common``); every module checks plain numbers with
:mod:`slidernet._validation`. Imports point one way: this package imports
the modules, ``creep_chain`` imports ``_exact_orbit`` and ``_common``,
``creep_pair`` imports ``_common``, and nothing imports back.
"""

from __future__ import annotations

from slidernet.analysis.theory.creep_chain import (
    ChainOrbit,
    CreepSegment,
    chain_creep,
    chain_creep_segments,
    chain_critical_amplitude,
    chain_orbit,
    three_slider_onset,
)
from slidernet.analysis.theory.creep_pair import (
    pair_creep,
    pair_creep_slips,
    pair_creep_steps,
    pair_critical_amplitude,
)
from slidernet.analysis.theory.extremes import harmonic, mean_records, mu_max_cdf, mu_max_moments
from slidernet.analysis.theory.paper_laws import mean_rearrangements, msd, mu_max_leading

__all__ = [
    "ChainOrbit",
    "CreepSegment",
    "chain_creep",
    "chain_creep_segments",
    "chain_critical_amplitude",
    "chain_orbit",
    "harmonic",
    "mean_rearrangements",
    "mean_records",
    "msd",
    "mu_max_cdf",
    "mu_max_leading",
    "mu_max_moments",
    "pair_creep",
    "pair_creep_slips",
    "pair_creep_steps",
    "pair_critical_amplitude",
    "three_slider_onset",
]
