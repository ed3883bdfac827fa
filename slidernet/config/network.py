"""The ``[network]`` table: the network's kind, its size, and uniform overrides of the defaults.

:class:`NetworkConfig` checks that the size keys match the kind and builds
the network. The checks of a configuration that depend on the network ask
the network itself, built where it may be a 1D pair of sliders
(:meth:`NetworkConfig.pair_network`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Annotated, ClassVar, Literal

import numpy as np
from pydantic import Field, field_validator, model_validator

from slidernet.config.base import FiniteFloat, Integer, PositiveFloat, Seed, _Strict, unit
from slidernet.errors import SlidernetError

# The model (numba's kernels, scipy's sparse matrices) is imported where a network is built: a configuration
# is checked, and its errors reported, before any of it is imported (slidernet.config.loading).
if TYPE_CHECKING:
    from slidernet.model.network import Network

_KIND_PARAMS = {
    "two_slider": set(),
    "chain": {"n"},
    "square": {"shape"},
    "triangular": {"shape"},
    "irregular": {"n", "seed"},
    "graph": {"path"},
}


class NetworkConfig(_Strict):
    """The network: its ``kind``, its size, and uniform overrides of the defaults.

    ``two_slider`` (the paper), ``chain`` (``n``), ``square`` and
    ``triangular`` (``shape = [rows, cols]``), ``irregular`` (``n`` random
    points joined by their Delaunay triangulation, drawn from ``seed``: the
    geometry is quenched, the same for every realization) and ``graph``
    (``path`` of a GraphML or edge-list file). ``k`` (in units of
    N / (Ntilde l0)), ``kappa`` and ``normal_load`` (in units of N) replace
    the default 1 on every spring or node. ``f_ext`` (in units of N) is a
    constant external tangential force on every slider: a number is a force
    along x, ``[fx, fy]`` a 2D force (2D networks only); default 0.
    ``incline`` (degrees, in [0, 90)) tilts the substrate along +x (downhill
    is +x): each slider keeps its normal load N_i and feels the downhill
    force N_i tan(incline) along x, as its ``f_ext``; give one or the other.
    """

    _omit_if_none: ClassVar[tuple[str, ...]] = ("incline",)

    kind: Literal["two_slider", "chain", "square", "triangular", "irregular", "graph"] = Field(
        "two_slider", description="The network's geometry; each kind takes its own size keys (above).")
    Ntilde: PositiveFloat = Field(
        description="Ntilde = N / (k l0), the one dimensionless number of the model (docs/model.md section 1); "
                    "may come from [units] instead.", json_schema_extra=unit("1"))
    n: Annotated[Integer, Field(ge=2)] | None = Field(
        None, description="Number of sliders: kinds 'chain' and 'irregular' (and 2 for 'two_slider').",
        json_schema_extra=unit("1"))
    shape: tuple[Annotated[Integer, Field(ge=1)], Annotated[Integer, Field(ge=1)]] | None = Field(
        None, description="[rows, cols] of a 'square' or 'triangular' lattice (at least 2 sliders).",
        json_schema_extra=unit("1"))
    path: str | None = Field(
        None, description="A GraphML or edge-list file of kind 'graph'; relative to the TOML file that names it.")
    seed: Seed | None = Field(
        None, description="Seed of an 'irregular' network's random points (None: 0); the geometry is the "
                          "same for every realization, whatever the run's seed.")
    k: PositiveFloat | None = Field(
        None, description="Stiffness of every spring, in units of k0 = N / (Ntilde l0), the paper's spring "
                          "(None: 1); k / Ntilde in N/l0 (docs/model.md section 2).", json_schema_extra=unit("k0"))
    kappa: FiniteFloat | None = Field(
        None, description="Dilation coefficient of every spring: its rest length is its length at theta = 0 "
                          "times (1 + kappa theta) (None: 1).", json_schema_extra=unit("1"))
    normal_load: PositiveFloat | None = Field(
        None, description="Normal load of every slider, in units of N (None: 1).", json_schema_extra=unit("N"))
    f_ext: FiniteFloat | tuple[FiniteFloat, FiniteFloat] | None = Field(
        None, description="Constant external tangential force on every slider, in units of N: a number "
                          "along x, or [fx, fy] (2D networks only); None: 0.", json_schema_extra=unit("N"))
    incline: FiniteFloat | None = Field(
        None, description="Angle of the substrate in degrees, in [0, 90), downhill along +x: every slider "
                          "feels N_i tan(incline) along x as its f_ext (docs/model.md, 'External force'); "
                          "not with f_ext. None: horizontal.", json_schema_extra=unit("degree", "in [0, 90)"))

    @field_validator("incline")
    @classmethod
    def _incline_range(cls, value: float | None) -> float | None:
        if value is not None and not 0.0 <= value < 90.0:
            raise ValueError(f"must be in [0, 90) degrees. Got {value!r} instead")
        return value

    @model_validator(mode="after")
    def _params_match_kind(self) -> NetworkConfig:
        wanted = _KIND_PARAMS[self.kind]
        given = {p for p in ("n", "shape", "path", "seed") if getattr(self, p) is not None}
        if self.kind == "two_slider" and self.n == 2:
            given.discard("n")
        extra = given - wanted
        if extra:
            raise ValueError(f"a {self.kind} network does not take {sorted(extra)}")
        missing = (wanted - {"seed"}) - given
        if missing:
            raise ValueError(f"a {self.kind} network needs {sorted(missing)}")
        if self.shape is not None and self.shape[0] * self.shape[1] < 2:
            raise ValueError(f"shape {list(self.shape)} has fewer than 2 sliders")
        if isinstance(self.f_ext, tuple) and self.kind in ("two_slider", "chain"):
            raise ValueError(f"a {self.kind} network is 1D: 'f_ext' must be a number (the force along x), "
                             f"not {list(self.f_ext)}")
        if self.incline is not None and self.f_ext is not None:
            raise ValueError("'network.incline' and 'network.f_ext' both set the tangential load on the sliders; "
                             "give one or the other (an incline is f_ext = N_i tan(incline) along x)")
        return self

    def tangential_load(self) -> bool:
        """True if a nonzero f_ext or incline loads the sliders (known without a file)."""
        return bool(self.f_ext) or bool(self.incline)

    def build(self) -> Network:
        """The network (its own ``seed``: the geometry is quenched), with the incline's f_ext."""
        from slidernet.model.builders import build

        params = self.model_dump(exclude={"kind", "Ntilde", "seed", "incline"}, exclude_none=True)
        # seed None means 0, not fresh entropy: a network is part of the scene.
        rng = np.random.Generator(np.random.PCG64(self.seed or 0))
        net = build(self.kind, params, self.Ntilde, rng)
        if self.incline:
            # The downhill pull of gravity on a slider of normal load N_i: N_i tan(incline) along +x.
            f_ext = np.zeros((net.n_nodes, net.dim))
            f_ext[:, 0] = math.tan(math.radians(self.incline)) * net.normal_load
            net.f_ext = f_ext
        return net

    def pair_network(self) -> Network | None:
        """The network, built, where it may be a 1D pair of sliders; None where it cannot be one.

        The checks of a configuration ask the network itself
        (:meth:`Network.is_two_slider`, :func:`pair_tilt_applies`) rather
        than its keys, so that they follow the rules the scene follows. The
        kind and size rule most networks out without building them; a pair
        costs nothing to build, and a graph's file is read. A file that
        cannot be read gives None: building the scene reports it.
        """
        from slidernet.model.builders import KIND_DIMS

        if KIND_DIMS[self.kind] == 2 or self.size() not in (2, None):
            return None
        try:
            return self.build()
        except (SlidernetError, OSError):
            return None

    def is_two_slider(self) -> bool:
        """True for the paper's two sliders, which the pair kernel runs (:meth:`Network.is_two_slider`)."""
        net = self.pair_network()
        return net is not None and net.is_two_slider()

    def pair_tilt_applies(self) -> bool:
        """True if the appendix's tilt test before every rearrangement applies (:func:`pair_tilt_applies`)."""
        from slidernet.model.network import pair_tilt_applies

        net = self.pair_network()
        return net is not None and pair_tilt_applies(net)

    def size(self) -> int | None:
        """Number of sliders, when known without reading a file."""
        if self.kind == "two_slider":
            return 2
        if self.shape is not None:
            return self.shape[0] * self.shape[1]
        return self.n
