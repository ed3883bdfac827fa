"""The ``[tilt]`` table: when the network tilt test declares that the network slides, how many tests a record
makes, and a known aging injected into the tested copy.

The network tilt test (``mu_eff_at = "records"``) raises a uniform tilt on a
copy of the network until one avalanche sets every node in motion with the
load above mu_d (docs/model.md, "The network tilt test"). ``min_slips`` and
``min_displacement`` make that rule stricter, so that a result can be checked
against the rule it rests on: every node must have slipped ``min_slips``
times in that avalanche, and its centre of mass must have moved along the
tilt by ``min_displacement`` reference slips (one slider held by one spring
of the mean stiffness). The defaults are the rule
itself. ``repeats`` makes several independent tests per recorded time;
``inject`` (:class:`InjectConfig`) tests, beside each test, a copy whose
thresholds are raised by a known law of time: a positive control of the
estimator (docs/model.md, "Injected aging").
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Annotated, ClassVar

from pydantic import Field

from slidernet.config.base import FiniteFloat, Integer, NonNegativeFloat, PositiveFloat, _Strict, unit


class InjectConfig(_Strict):
    """A known aging, injected into the copy of the state that a test measures: ``[tilt] inject``.

    At a recorded time t the test is made twice on the same state with the
    same draws: as it is, and on a copy whose thresholds mu_s are raised by
    ``c ln(1 + t / t0)``: every contact's with ``select = 1``; with
    ``0 < select < 1`` only those of the ceil(select N) oldest contacts (the
    longest since their last slip; ties: the lower node index first), which
    mimics aging by selection. A contact that slips during the test draws a
    fresh threshold and keeps no shift. The run itself (its state, its
    streams, every other record) is never touched: the paired difference is
    the estimator's response to a known rise of the thresholds, with common
    random numbers. The tests are the network tilt test of ``mu_eff`` and the
    slide-hold-slide pull of ``mu_shs``, each where the run makes it (the
    pull alone is enough). The result gains ``mu_eff_injected``,
    ``mu_shs_injected`` and the other ``*_injected`` variables
    (docs/model.md, "Injected aging").
    """

    c: NonNegativeFloat = Field(
        description="Amplitude of the injected rise of mu_s, per unit of ln(1 + t / t0) (dimensionless; "
                    "c ln 10 per decade of t late in the run). 0 injects nothing: the injected outputs equal the "
                    "plain ones.", json_schema_extra=unit("1"))
    t0: PositiveFloat = Field(
        1.0, description="The time t0 of the law c ln(1 + t / t0), in tau_th (1: tau_th).",
        json_schema_extra=unit("tau_th"))
    select: Annotated[FiniteFloat, Field(gt=0, le=1)] = Field(
        1.0, description="Share of the contacts raised, in (0, 1]: 1 raises every contact; below 1 only the "
                         "ceil(select N) oldest by contact age (ties: the lower node index first).",
        json_schema_extra=unit("1"))

    def shift(self, t: float) -> float:
        """The rise of a raised threshold at time ``t`` (tau_th): c ln(1 + t / t0).

        >>> InjectConfig(c=0.01, t0=1.0).shift(0.0), round(InjectConfig(c=0.01).shift(9.0), 12)
        (0.0, 0.02302585093)
        """
        return self.c * math.log1p(t / self.t0)

    def raised(self, n_nodes: int) -> int:
        """How many of ``n_nodes`` contacts are raised: ceil(select N), with ``select`` read as the decimal
        number written (0.3 of 10 contacts is 3, although 0.3 * 10 is 3.0000000000000004 in float64).

        >>> InjectConfig(c=0.01, select=0.3).raised(10), InjectConfig(c=0.01, select=0.1).raised(16)
        (3, 2)
        """
        return min(n_nodes, math.ceil(Fraction(repr(float(self.select))) * n_nodes))


class TiltConfig(_Strict):
    """The sliding rule of the network tilt test: how much motion one avalanche above mu_d needs to count as
    sliding.

    ``min_slips = m``: every node has slipped at least m times in that
    avalanche (or m - 1 times and is unstable, about to slip again); 1 is
    the rule of every earlier result. ``min_displacement = X``: the
    avalanche has also moved the centre of mass along +x by X reference
    slips ell = (1 + e) (<mu_s> - mu_d) <N_i> Ntilde l0 / <k> (e =
    ``friction.overshoot``, <k> the mean spring stiffness): the slip of one
    slider held by one spring, the creep observables' reference slip
    (docs/model.md). A node of a network slips less, held by all its
    springs (K_ii,xx, near 3 <k> in a large irregular network, whose nodes
    have six springs on average), so X reference slips are up to about 3 X
    slips per node along the tilt; 0, the default, asks for no
    displacement. Both
    apply to the network tilt test only, not to the appendix's test of two
    sliders (``mu_eff_at = "rearrangements"``). A rule that the test's caps
    (max(100 N, 1e5) slips in one avalanche, ``solver.max_avalanche`` in a
    test) cannot let it meet is refused before the run; a test that meets
    the avalanche cap first is counted in ``tilt_capped``, not sampled.

    ``repeats = K`` makes K independent tests at each recorded time, one
    after the other from the tilt stream, the first of them the test of a
    run without the key; ``inject`` adds an injected twin to each test
    (:class:`InjectConfig`), and to the slide-hold-slide pull of
    ``mu_shs``. ``repeats`` needs the network tilt test of ``mu_eff`` at
    the recorded times; ``inject`` that test or the pull.
    """

    # Left out of a dump when not given, so that a table without them keeps its identity (config/base.py).
    _omit_if_none: ClassVar[tuple[str, ...]] = ("inject",)
    _omit_if_default: ClassVar[tuple[str, ...]] = ("repeats",)

    min_slips: Annotated[Integer, Field(ge=1)] = Field(
        1, description="Slips of every node within the sliding avalanche (1: the rule of every earlier result).",
        json_schema_extra=unit("slips"))
    min_displacement: Annotated[FiniteFloat, Field(ge=0)] = Field(
        0.0, description="Displacement of the centre of mass along +x within the sliding avalanche, in "
                         "reference slips (1 + e)(<mu_s> - mu_d) <N_i> Ntilde l0 / <k> of one slider held by "
                         "one spring of the mean stiffness <k> (0: none asked).", json_schema_extra=unit("ell"))
    repeats: Annotated[Integer, Field(ge=1)] = Field(
        1, description="Independent network tilt tests per recorded time, read one after the other from the "
                       "tilt stream (1: one, the result of every earlier run to the bit). mu_eff pools them; "
                       "mu_eff_realization is their mean, mu_eff_spread their standard deviation.",
        json_schema_extra=unit("1"))
    inject: InjectConfig | None = Field(
        None, description="A known aging injected into the tested copy of the state, tested beside every test "
                          "at the recorded times: the network tilt test of mu_eff and the slide-hold-slide "
                          "pull of mu_shs (None: none).")

    def is_default(self) -> bool:
        """True if the sliding rule is that of every earlier result (``repeats`` and ``inject`` aside)."""
        return self.min_slips == 1 and self.min_displacement == 0.0
