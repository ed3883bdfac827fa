"""The ``[solver]`` table: the choices of the quasi-static solver.

The kernel (``"auto"``: the one :func:`~slidernet.config.rules.choose_kernel`
picks), the cap on an avalanche, the buffers of random draws, the reset of
the forces against drift, the 2D slip and the size of the event catalogue.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field

from slidernet.config.base import Integer, _Strict, unit


class SolverConfig(_Strict):
    """Choices of the quasi-static solver.

    ``kernel = "auto"`` picks the scalar ``pair`` kernel for the paper's
    two-slider scene, ``csr`` for other 1D networks and ``vec`` in 2D.
    ``recompute_every`` (slips; 0: never) resets the incrementally updated
    forces from the displacements by a sparse mat-vec, against drift.
    ``slip`` chooses, in 2D, between the straight-line slip along the force
    (exact where K_ii is isotropic) and the exactly integrated 2D slip.
    ``max_events`` caps the event catalogue (observable ``events``) of one
    realization: past it the catalogue stops, with a warning, and the result
    says it is incomplete; the run itself goes on.
    """

    kernel: Literal["auto", "pair", "csr", "vec"] = Field(
        "auto", description="The compiled kernel: 'auto' picks the one the scene needs.")
    max_avalanche: Annotated[Integer, Field(ge=1)] = Field(
        100_000_000, description="Slips after which an avalanche that has not ended stops the run with an "
                                 "AvalancheError.", json_schema_extra=unit("slips"))
    batch: Annotated[Integer, Field(ge=1)] = Field(
        1 << 16, description="Random draws that wait in the kernels' buffers; never changes a result. A stop "
                             "request is seen at every refill: with slip = 'exact' in 2D at most 32 wait.",
        json_schema_extra=unit("draws"))
    recompute_every: Annotated[Integer, Field(ge=0)] = Field(
        10_000_000, description="Slips between two resets of the forces from the displacements (0: never).",
        json_schema_extra=unit("slips"))
    slip: Literal["straight", "exact"] = Field(
        "straight", description="2D slips: along the force in a straight line, or integrated exactly.")
    max_events: Annotated[Integer, Field(ge=1)] = Field(
        10_000_000, description="Rows of the event catalogue (observable 'events') kept per realization.",
        json_schema_extra=unit("rows"))
