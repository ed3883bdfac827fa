"""The ``[dynamics]`` table: sliders with mass, the equations of motion as the solver.

Absent, the run is quasi-static: every slip is instantaneous and the
quasi-static solver runs, unchanged to the bit. Present, every slider has
mass N_i m and the compiled inertial solver integrates the equations of
motion (docs/model.md, "Inertia"): ``tau_ratio`` = tau_dyn / tau_th, with
tau_dyn = sqrt(m / k) and a lone slip of the paper lasting pi tau_dyn. In
1D the motion is exact between events; in 2D the moving nodes are
integrated by a Dormand-Prince 5(4) scheme whose ``rtol`` and ``max_step``
are set here (they never matter in 1D). ``tilt_rate`` makes the tilt tests at
the recorded times dynamic: the load ramped at that rate under the equations
of motion (:mod:`slidernet.solver.inertia_tilt`); absent, they are the
quasi-static network tilt test of the state at the recorded time.
"""

from __future__ import annotations

from typing import Annotated

from pydantic import Field

from slidernet.config.base import PositiveFloat, _Strict, unit


class DynamicsConfig(_Strict):
    """Sliders with inertia: ``[dynamics]``.

    ``tau_ratio`` is the one parameter of the motion, tau_dyn / tau_th: how
    long a slip lasts against the time between two temperature steps. The
    quasi-static solver is its limit tau_ratio -> 0 (docs/guides/inertia.md
    measures how close 1e-4 comes).
    """

    tau_ratio: PositiveFloat = Field(
        description="tau_dyn / tau_th, > 0: a slip's time scale sqrt(m / k) over the thermal step's.",
        json_schema_extra=unit("1"))
    rtol: Annotated[PositiveFloat, Field(ge=1e-14, le=1e-3)] = Field(
        1e-10, description="2D only: the integration's relative error per step in u and v (absolute: 1e-2 rtol, "
                           "in Ntilde l0).", json_schema_extra=unit("1"))
    max_step: PositiveFloat = Field(
        0.1, description="2D only: the longest integration step, in tau_dyn; a stuck neighbour whose force rises "
                         "above its threshold and falls back within one step is not seen.",
        json_schema_extra=unit("tau_dyn"))
    tilt_rate: PositiveFloat | None = Field(
        None, description="The dynamic tilt test's ramp: the load per unit normal load rises at this rate per "
                          "tau_dyn (units of mu), under the equations of motion. Absent: the quasi-static network "
                          "tilt test of the state at each recorded time.", json_schema_extra=unit("1/tau_dyn"))
