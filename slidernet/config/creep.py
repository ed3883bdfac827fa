"""The ``[creep]`` table: the parameters of the observable ``"creep"``.

The time after which the reptation velocity is measured, and the advance of
x_G that makes an avalanche a creep event. The whole configuration refuses
the table without the observable.
"""

from __future__ import annotations

from pydantic import Field

from slidernet.config.base import NonNegativeFloat, PositiveFloat, _Strict, unit


class CreepConfig(_Strict):
    """The creep observables (observable ``"creep"``): the reptation velocity and the creep events.

    A network driven cyclically under a downhill load (``network.f_ext``
    along +x) creeps: x_G advances by whole slips. With the observable
    ``"creep"`` the result holds x_G at the end of every cycle of a periodic
    driver and its advance over each cycle, the reptation velocity ``v_creep``
    measured after ``transient`` (whole cycles only, with a periodic driver),
    and the creep events: the avalanches that advance x_G along +x by more
    than ``event_fraction`` times the reference slip
    ell = 2 (<mu_s> - mu_d) <N_i> Ntilde l0 / <k>, the slip of a slider of
    mean threshold, mean normal load and one spring of mean stiffness
    (docs/model.md section 3). They are computed exactly from the event
    catalogue, which the kernel keeps for them (its rows enter the result
    only with the observable ``"events"``).
    """

    transient: NonNegativeFloat = Field(
        0.0, description="Time, in tau_th, before which x_G is left out of the reptation velocity: v_creep "
                         "is measured from the first cycle that starts at or after it (periodic driver) or "
                         "from it (otherwise) to the end; >= 0 and < steps.",
        json_schema_extra=unit("tau_th", "< steps"))
    event_fraction: PositiveFloat = Field(
        0.25, description="A creep event is an avalanche whose advance of x_G along +x exceeds event_fraction "
                          "times the reference slip ell = 2 (<mu_s> - mu_d) <N_i> Ntilde l0 / <k>; > 0.",
        json_schema_extra=unit("ell"))
