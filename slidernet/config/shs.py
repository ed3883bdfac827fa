"""The ``[shs]`` table: the pull springs of the slide-hold-slide protocol (observable ``"mu_shs"``).

After the hold (the thermal cycling up to a recorded time), a copy of the
network is pulled through springs from a stage moving quasi-statically along
+x, until every contact has been renewed; the peak of the stage force per
unit normal load is the static friction ``mu_shs`` (docs/model.md,
"Slide-hold-slide"). The whole configuration refuses the table without the
observable.
"""

from __future__ import annotations

from pydantic import Field

from slidernet.config.base import PositiveFloat, _Strict, unit


class ShsConfig(_Strict):
    """The slide-hold-slide pull (observable ``"mu_shs"``): how stiff the springs are that pull the network.

    The stage is joined to every node i by a spring of stiffness
    ``stiffness`` N_i <k>, <k> the network's mean spring stiffness: gamma =
    ``stiffness`` is a node's pull spring relative to one spring of the
    network, per unit normal load. Until the first slip the pull is the tilt
    test's uniform load, whatever gamma. After it, a stiff pull (large gamma)
    holds each node near the stage: a slip relaxes mostly its own pull
    spring, and the nodes slip nearly on their own; a soft one keeps the
    load nearly constant through an avalanche, as the tilt test's load does.
    """

    stiffness: PositiveFloat = Field(
        1.0, description="gamma: each node's pull spring, gamma N_i <k>, relative to the network's mean spring "
                         "stiffness <k> per unit normal load N_i; > 0.", json_schema_extra=unit("1"))
