"""The ``[tilt]`` table: when the network tilt test declares that the network slides.

The network tilt test (``mu_eff_at = "records"``) raises a uniform tilt on a
copy of the network until one avalanche sets every node in motion with the
load above mu_d (docs/model.md, "The network tilt test"). These keys make
that rule stricter, so that a result can be checked against the rule it
rests on: every node must have slipped ``min_slips`` times in that
avalanche, and its centre of mass must have moved along the tilt by
``min_displacement`` reference slips (one slider held by one spring of the
mean stiffness). The defaults are the rule itself.
"""

from __future__ import annotations

from typing import Annotated

from pydantic import Field

from slidernet.config.base import FiniteFloat, Integer, _Strict


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
    """

    min_slips: Annotated[Integer, Field(ge=1)] = Field(
        1, description="Slips of every node within the sliding avalanche (1: the rule of every earlier result).")
    min_displacement: Annotated[FiniteFloat, Field(ge=0)] = Field(
        0.0, description="Displacement of the centre of mass along +x within the sliding avalanche, in "
                         "reference slips (1 + e)(<mu_s> - mu_d) <N_i> Ntilde l0 / <k> of one slider held by "
                         "one spring of the mean stiffness <k> (0: none asked).")

    def is_default(self) -> bool:
        """True if the table asks for nothing beyond the rule of every earlier result."""
        return self.min_slips == 1 and self.min_displacement == 0.0
