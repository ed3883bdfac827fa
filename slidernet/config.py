"""Run configuration: pydantic models loaded from TOML or a dict.

Every check happens here, before any work: structure and ranges through
pydantic, plugin names and parameters by building the plugins. Errors are
raised as :class:`~slidernet.errors.ConfigError` with the dotted name of the
field and the reason.

>>> cfg = load_config({"steps": 10, "network": {"Ntilde": 1e-7},
...                    "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6,
...                                 "std": 0.01}},
...                    "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6}})
>>> cfg.network.kind, cfg.realizations
('two_slider', 1)
>>> load_config({"steps": 0})
Traceback (most recent call last):
...
slidernet.errors.ConfigError: Invalid configuration:
  - The 'steps' field must be >= 1. Got 0 instead.
  - The 'network' field is required.
  - The 'friction' field is required.
  - The 'driver' field is required.
"""

from __future__ import annotations

import inspect
import math
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import Annotated, Any, ClassVar, Literal

import numpy as np
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    PrivateAttr,
    SerializerFunctionWrapHandler,
    ValidationError,
    field_validator,
    model_serializer,
    model_validator,
)

from slidernet.errors import ConfigError, SlidernetError
from slidernet.model import units
from slidernet.model.builders import KIND_DIMS, build
from slidernet.model.network import Network, pair_tilt_applies
from slidernet.plugins import registry
from slidernet.plugins.distributions import TruncatedBelow

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

PositiveFloat = Annotated[float, Field(gt=0, allow_inf_nan=False)]
FiniteFloat = Annotated[float, Field(allow_inf_nan=False)]
OBSERVABLES = ("n", "mu_max", "x_G", "mu_eff", "n_records", "events", "creep")


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", validate_assignment=True)
    # Keys left out of a dump when None: a configuration that does not use a key added later dumps as it
    # did before the key existed, so that the config stored with earlier results and the identity of
    # interrupted runs (run.json) still match it.
    _omit_if_none: ClassVar[tuple[str, ...]] = ()

    @model_serializer(mode="wrap")
    def _dump(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        data = handler(self)
        for key in self._omit_if_none:
            if isinstance(data, dict) and key in data and data[key] is None:
                del data[key]
        return data


class PluginSpec(BaseModel):
    """A registered plugin by ``name``; every other key is a parameter of its factory."""

    model_config = ConfigDict(extra="allow")
    name: str = Field(description="The name the plugin is registered under (built-in or from an entry point).")

    @property
    def params(self) -> dict[str, Any]:
        """The factory's keyword arguments."""
        return dict(self.model_extra or {})


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
                    "may come from [units] instead.")
    n: Annotated[int, Field(ge=2)] | None = Field(
        None, description="Number of sliders: kinds 'chain' and 'irregular' (and 2 for 'two_slider').")
    shape: tuple[Annotated[int, Field(ge=1)], Annotated[int, Field(ge=1)]] | None = Field(
        None, description="[rows, cols] of a 'square' or 'triangular' lattice (at least 2 sliders).")
    path: str | None = Field(
        None, description="A GraphML or edge-list file of kind 'graph'; relative to the TOML file that names it.")
    seed: Annotated[int, Field(ge=0)] | None = Field(
        None, description="Seed of an 'irregular' network's random points (None: 0); the geometry is the "
                          "same for every realization, whatever the run's seed.")
    k: PositiveFloat | None = Field(
        None, description="Stiffness of every spring, in units of k0 = N / (Ntilde l0), the paper's spring "
                          "(None: 1); k / Ntilde in N/l0 (docs/model.md section 2).")
    kappa: Annotated[float, Field(allow_inf_nan=False)] | None = Field(
        None, description="Dilation coefficient of every spring: its rest length is its length at theta = 0 "
                          "times (1 + kappa theta) (None: 1).")
    normal_load: PositiveFloat | None = Field(
        None, description="Normal load of every slider, in units of N (None: 1).")
    f_ext: FiniteFloat | tuple[FiniteFloat, FiniteFloat] | None = Field(
        None, description="Constant external tangential force on every slider, in units of N: a number "
                          "along x, or [fx, fy] (2D networks only); None: 0.")
    incline: FiniteFloat | None = Field(
        None, description="Angle of the substrate in degrees, in [0, 90), downhill along +x: every slider "
                          "feels N_i tan(incline) along x as its f_ext (docs/model.md, 'External force'); "
                          "not with f_ext. None: horizontal.")

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
        net = self.pair_network()
        return net is not None and pair_tilt_applies(net)

    def size(self) -> int | None:
        """Number of sliders, when known without reading a file."""
        if self.kind == "two_slider":
            return 2
        if self.shape is not None:
            return self.shape[0] * self.shape[1]
        return self.n


class FrictionConfig(_Strict):
    """Dynamic coefficient mu_d and the distribution of static thresholds mu_s."""

    mu_d: PositiveFloat = Field(description="Dynamic friction coefficient mu_d (dimensionless).")
    static: PluginSpec = Field(
        description="The distribution p(mu_s) of the static thresholds: a registered name and its "
                    "parameters; conditioned on mu_s > mu_d.")


class UnitsConfig(_Strict):
    """A physical setup from which ``network.Ntilde`` and ``driver.sigma_theta`` are computed.

    A preset ``material`` (``steel``, ``glass``, ``granite``, ``pmma``) and/or
    explicit values (they override the preset's): ``rho`` (kg/m^3), ``Y``
    (Pa), ``alpha`` (1/K), ``conductivity`` (W/(m K)), ``heat_capacity``
    (J/(kg K)); the slider ``size`` l0 (m); the standard deviation of the
    temperature ``delta_T`` (K, optional); gravity ``g`` (m/s^2, default 9.81). See
    :mod:`slidernet.model.units` for the formulas (Ntilde = rho g l0 / Y,
    sigma_theta = alpha delta_T).

    The table fills ``network.Ntilde`` when [network] has none, and, when
    ``delta_T`` is given, ``driver.sigma_theta`` when [driver] has none and
    the driver takes a ``sigma_theta`` parameter. A value given both ways
    must agree to a relative 1e-6 (so a resolved configuration, which keeps
    both, loads again); otherwise the configuration is refused.
    """

    material: str | None = Field(
        None, description="A preset material: 'steel', 'glass', 'granite' or 'pmma' (explicit values "
                          "override it).")
    rho: PositiveFloat | None = Field(None, description="Density of the sliders, in kg/m^3.")
    Y: PositiveFloat | None = Field(None, description="Young's modulus, in Pa.")
    alpha: PositiveFloat | None = Field(None, description="Linear thermal expansion coefficient, in 1/K.")
    conductivity: PositiveFloat | None = Field(None, description="Thermal conductivity, in W/(m K).")
    heat_capacity: PositiveFloat | None = Field(None, description="Specific heat capacity, in J/(kg K).")
    size: PositiveFloat = Field(description="Size of a slider, l0, in m.")
    delta_T: PositiveFloat | None = Field(
        None, description="Standard deviation of the temperature, in K (not an amplitude): gives "
                          "sigma_theta = alpha delta_T.")
    g: PositiveFloat = Field(units.G_STANDARD, description="Acceleration of gravity, in m/s^2.")

    @field_validator("material")
    @classmethod
    def _known_material(cls, value: str | None) -> str | None:
        if value is not None:
            try:
                units.material(value)
            except ConfigError as exc:
                raise ValueError(str(exc).rstrip(".")) from None
        return value

    @model_validator(mode="after")
    def _enough_values(self) -> UnitsConfig:
        if self.material is None:
            missing = [p for p in ("rho", "Y") if getattr(self, p) is None]
            if missing:
                raise ValueError(f"give a 'material' or explicit {' and '.join(repr(p) for p in missing)}")
            if self.delta_T is not None and self.alpha is None:
                raise ValueError("'delta_T' needs 'alpha' (or a 'material') to give sigma_theta")
        return self

    def resolve(self) -> units.Dimensionless:
        """Ntilde, sigma_theta (None without delta_T), tau_th and their ratio."""
        values = {p: getattr(self, p) for p in ("rho", "Y", "alpha", "conductivity", "heat_capacity")}
        return units.setup(self.material, size=self.size, delta_T=self.delta_T, g=self.g, **values)


_UNITS_RTOL = 1e-6


def _takes_sigma_theta(name: object) -> bool | None:
    """Whether the driver called ``name`` takes a ``sigma_theta`` parameter; None if unknown."""
    if not isinstance(name, str):
        return None
    try:
        factory = registry.drivers.get(name)
    except ConfigError:
        return None
    try:
        params = inspect.signature(factory).parameters
    except (TypeError, ValueError):  # pragma: no cover - no introspectable signature
        return True
    return "sigma_theta" in params or any(p.kind is p.VAR_KEYWORD for p in params.values())


def _fill_from_units(data: Any) -> Any:
    """A copy of the raw config with the values its [units] table gives filled in where absent."""
    if not isinstance(data, Mapping) or not isinstance(data.get("units"), (Mapping, UnitsConfig)):
        return data
    data = dict(data)
    network = data.get("network", {})
    try:
        found = UnitsConfig.model_validate(data["units"]).resolve()
    except (ValidationError, ConfigError):
        # The 'units' field reports the error; a placeholder keeps a missing Ntilde
        # from adding a second, misleading message (this config is refused anyway).
        if isinstance(network, Mapping) and "Ntilde" not in network:
            data["network"] = {**network, "Ntilde": 1.0}
        return data
    if isinstance(network, Mapping) and "Ntilde" not in network:
        data["network"] = {**network, "Ntilde": found.Ntilde}
    driver = data.get("driver")
    if found.sigma_theta is not None and isinstance(driver, Mapping) and "sigma_theta" not in driver \
            and _takes_sigma_theta(driver.get("name")):
        data["driver"] = {**driver, "sigma_theta": found.sigma_theta}
    return data


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
    max_avalanche: Annotated[int, Field(ge=1)] = Field(
        100_000_000, description="Slips after which an avalanche that has not ended stops the run with an "
                                 "AvalancheError.")
    batch: Annotated[int, Field(ge=1)] = Field(
        1 << 16, description="Random draws that wait in the kernels' buffers; never changes a result.")
    recompute_every: Annotated[int, Field(ge=0)] = Field(
        10_000_000, description="Slips between two resets of the forces from the displacements (0: never).")
    slip: Literal["straight", "exact"] = Field(
        "straight", description="2D slips: along the force in a straight line, or integrated exactly.")
    max_events: Annotated[int, Field(ge=1)] = Field(
        10_000_000, description="Rows of the event catalogue (observable 'events') kept per realization.")


_SCHEDULER_SCHEMES = ("tcp", "tls", "inproc", "ucx", "ws", "wss")


class ExecutionConfig(_Strict):
    """Where and how the realizations run; never changes a result.

    ``workers`` local processes run the realizations (None: every core this
    process may use); ``scheduler`` (``"tcp://host:port"``) sends them to a
    Dask distributed cluster instead. ``checkpoint_every`` (seconds) is how
    often a run with an output directory saves its work, and
    ``scheduler_timeout`` (seconds) how long to wait for the scheduler to
    answer before giving up with a message. Realization r is
    always driven by child r of the seed and the ensemble is reduced in
    realization order, so the same config gives the same bits on 1 worker,
    N workers or a cluster; this table is kept out of the identity of a run
    (a run may resume with other workers).
    """

    workers: Annotated[int, Field(ge=1)] | None = Field(
        None, description="Local processes that run the realizations (None: every core this process may use).")
    scheduler: str | None = Field(
        None, description="Address of a Dask scheduler, 'tcp://host:port'; when given, the realizations run "
                          "on that cluster and 'workers' is ignored.")
    checkpoint_every: Annotated[float, Field(gt=0)] = Field(
        60.0, description="Seconds between two saves of the work of a run that has an output directory.")
    scheduler_timeout: Annotated[float, Field(gt=0)] = Field(
        10.0, description="Seconds to wait for the Dask scheduler to answer before giving up.")

    @field_validator("scheduler")
    @classmethod
    def _scheduler_address(cls, value: str | None) -> str | None:
        if value is not None and not is_scheduler_address(value):
            raise ValueError(f"must be {SCHEDULER_REQUIREMENT}; got {value!r}")
        return value


SCHEDULER_REQUIREMENT = (f"a Dask scheduler address such as 'tcp://host:8786' (schemes: "
                         f"{', '.join(_SCHEDULER_SCHEMES)})")


def is_scheduler_address(value: object) -> bool:
    """Whether ``value`` reads as a Dask scheduler address ``scheme://host[:port]``."""
    if not isinstance(value, str):
        return False
    scheme, sep, rest = value.partition("://")
    return bool(sep) and scheme in _SCHEDULER_SCHEMES and bool(rest)


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

    transient: Annotated[float, Field(ge=0, allow_inf_nan=False)] = Field(
        0.0, description="Time, in tau_th, before which x_G is left out of the reptation velocity: v_creep "
                         "is measured from the first cycle that starts at or after it (periodic driver) or "
                         "from it (otherwise) to the end; >= 0 and < steps.")
    event_fraction: PositiveFloat = Field(
        0.25, description="A creep event is an avalanche whose advance of x_G along +x exceeds event_fraction "
                          "times the reference slip ell = 2 (<mu_s> - mu_d) <N_i> Ntilde l0 / <k>; > 0.")


#: Observables only the network kernels record (always, asked for or not); ``y_G`` in 2D only.
NETWORK_OBSERVABLES = ("y_G", "mu_mean", "mu_min", "avalanche_count", "node_slips", "mu_s")
Observable = Literal["n", "mu_max", "x_G", "mu_eff", "n_records", "events", "creep",
                     "y_G", "mu_mean", "mu_min", "avalanche_count", "node_slips", "mu_s"]


class Config(_Strict):
    """A full run: what to simulate, for how long, and what to record.

    ``mu_eff_at`` says when the virtual tilt test of ``mu_eff`` is made:
    ``"rearrangements"`` before every rearrangement (the appendix; a 1D pair
    of sliders), ``"records"`` once per realization at every recorded time
    (the network tilt test, any network), ``"auto"`` the first where it
    applies and the second otherwise.

    ``units`` (optional, :class:`UnitsConfig`) computes ``network.Ntilde``
    and ``driver.sigma_theta`` from a material, a slider size and the
    standard deviation of the temperature, where they are not given.
    """

    _omit_if_none: ClassVar[tuple[str, ...]] = ("creep",)

    seed: Annotated[int, Field(ge=0)] | None = Field(
        None, description="Seed of the run: realization r is driven by child r of SeedSequence(seed) "
                          "(None: fresh OS entropy, stored in the result).")
    realizations: Annotated[int, Field(ge=1)] = Field(1, description="Number of independent realizations R.")
    steps: Annotated[int, Field(ge=1)] = Field(
        description="Duration of a realization, in thermal steps of tau_th (theta is redrawn at each).")
    record: Literal["log", "all"] | list[Annotated[int, Field(ge=0)]] = Field(
        "log", description="Recorded times, in tau_th: 'log'-spaced, 'all', or a list of steps; 0 and 'steps' "
                           "always included.")
    log_points_per_decade: Annotated[int, Field(ge=1, le=1000)] = Field(
        20, description="Recorded times per decade of t with record = 'log'.")
    observables: list[Observable] = Field(
        default_factory=lambda: ["n", "mu_max", "x_G"],
        description="Variables to record (default ['n', 'mu_max', 'x_G']; docs/model.md section 3); the "
                    "network kernels always add their own.",
    )
    mu_eff_at: Literal["auto", "rearrangements", "records"] = Field(
        "auto", description="When the virtual tilt test of 'mu_eff' is made (above).")
    units: UnitsConfig | None = Field(
        None, description="A physical setup that gives network.Ntilde and driver.sigma_theta where they are "
                          "not given.")
    network: NetworkConfig = Field(description="The network of sliders and springs.")
    friction: FrictionConfig = Field(description="mu_d and the distribution of the static thresholds mu_s.")
    driver: PluginSpec = Field(
        description="The temperature driver theta(t): a registered name and its parameters.")
    solver: SolverConfig = Field(default_factory=SolverConfig, description="Choices of the solver.")
    execution: ExecutionConfig = Field(
        default_factory=ExecutionConfig,
        description="Where the realizations run; never changes a result, and not part of a run's identity.")
    creep: CreepConfig | None = Field(
        None, description="Parameters of the observable 'creep' (the reptation velocity and the creep events); "
                          "None: the defaults. Refused without that observable.")

    _distribution: Any = PrivateAttr(default=None)
    _driver: Any = PrivateAttr(default=None)

    @model_validator(mode="before")
    @classmethod
    def _units_fill(cls, data: Any) -> Any:
        return _fill_from_units(data)

    @model_validator(mode="after")
    def _units_agree(self) -> Config:
        if self.units is None:
            return self
        found = self.units.resolve()
        if not math.isclose(self.network.Ntilde, found.Ntilde, rel_tol=_UNITS_RTOL):
            raise ValueError(
                f"'network.Ntilde' = {self.network.Ntilde!r} disagrees with [units], which gives "
                f"Ntilde = rho g l0 / Y = {found.Ntilde!r}; give one of them, or the same value"
            )
        if found.sigma_theta is None:
            return self
        given = self.driver.params.get("sigma_theta")
        if given is None:
            if _takes_sigma_theta(self.driver.name) is False:
                raise ValueError(
                    f"'units.delta_T' gives sigma_theta = {found.sigma_theta!r}, but the driver "
                    f"{self.driver.name!r} takes no 'sigma_theta' parameter; remove 'delta_T'"
                )
            return self  # an unknown driver: load_config names it
        try:
            given = float(given)
        except (TypeError, ValueError):
            return self  # the driver itself refuses it, naming the parameter
        if not math.isclose(given, found.sigma_theta, rel_tol=_UNITS_RTOL):
            raise ValueError(
                f"'driver.sigma_theta' = {given!r} disagrees with [units], which gives "
                f"sigma_theta = alpha delta_T = {found.sigma_theta!r}; give one of them, or the same value"
            )
        return self

    @model_validator(mode="after")
    def _check_cross_fields(self) -> Config:
        if isinstance(self.record, list):
            if any(t > self.steps for t in self.record):
                raise ValueError(f"the 'record' times must lie in [0, steps = {self.steps}]")
        size = self.network.size()
        if self.mu_eff_at == "rearrangements":  # the network is built only for this check, where it may be a pair
            choose_tilt_at(self.mu_eff_at, self.network.pair_tilt_applies())
        if self.solver.kernel == "pair" and size not in (2, None):
            raise ValueError("the 'solver.kernel' value 'pair' needs a 2-slider network")
        for name, what in (("events", "the event catalogue"), ("creep", "computed from the event catalogue")):
            if self.solver.kernel == "pair" and name in self.observables:
                raise ValueError(f"the {name!r} observable ({what}) needs a network kernel; "
                                 "use 'solver.kernel = \"auto\"' or '\"csr\"'")
        if self.creep is not None and "creep" not in self.observables:
            raise ValueError("the [creep] table sets the observable 'creep', which is not asked for; "
                             "add \"creep\" to 'observables' or remove the table")
        if "creep" in self.observables and self.creep_settings().transient >= self.steps:
            raise ValueError(f"the 'creep.transient' value must be < steps = {self.steps} (the run's duration, "
                             f"in tau_th), so that a reptation velocity is measured after it. "
                             f"Got {self.creep_settings().transient!r} instead")
        return self

    @model_validator(mode="after")
    def _network_observables_can_be_recorded(self) -> Config:
        asked = [name for name in NETWORK_OBSERVABLES if name in self.observables]
        if not asked:
            return self
        dim, pair = self._network_dim_and_pair()
        if pair:
            raise ValueError(
                f"the observables {asked} are recorded by the network kernels, and this two-slider scene runs on "
                f"the 'pair' kernel; set 'solver.kernel = \"csr\"' to record them"
            )
        if "y_G" in asked and dim == 1:
            raise ValueError(
                f"the 'y_G' observable (the centre of mass along y) needs a 2D network; this {self.network.kind} "
                f"network is 1D (its displacement is x_G)"
            )
        return self

    def _network_dim_and_pair(self) -> tuple[int | None, bool]:
        """(dimension, runs on the pair kernel) of the network, reading a graph file only if there is one."""
        pair = self.network.pair_network()  # a graph is built here, once
        dim = pair.dim if pair is not None else KIND_DIMS[self.network.kind]
        if dim is None:
            return None, False  # a graph file that cannot be read: building the scene reports it
        two = pair is not None and pair.is_two_slider()
        return dim, choose_kernel(self.solver.kernel, two, dim, self.needs_catalogue()) == "pair"

    def needs_catalogue(self) -> bool:
        """True if the kernel keeps the event catalogue: for the observable 'events', or 'creep' (read from it)."""
        return "events" in self.observables or "creep" in self.observables

    def creep_settings(self) -> CreepConfig:
        """The [creep] table, or its defaults where it is not given."""
        return self.creep if self.creep is not None else CreepConfig()

    def distribution(self) -> TruncatedBelow:
        """The mu_s distribution, truncated below mu_d (built once, cached)."""
        if self._distribution is None:
            self._distribution = build_distribution(self.friction)
        return self._distribution

    def driver_plugin(self) -> Any:
        """The temperature driver (built once, cached)."""
        if self._driver is None:
            self._driver = _build_plugin(registry.drivers, self.driver, "driver")
        return self._driver


def _build_plugin(reg: registry.Registry, spec: PluginSpec, field: str) -> Any:
    factory = reg.get(spec.name)
    params = spec.params
    try:
        signature = inspect.signature(factory)
    except (TypeError, ValueError):  # pragma: no cover - builtins without signature
        signature = None
    try:
        if signature is not None:
            signature.bind(**params)
    except TypeError as exc:
        accepted = signature.parameters
        names = ", ".join(repr(p) for p in accepted)
        # Name only the keys at fault: listing every given key put the right ones among the refused.
        takes_any = any(p.kind is p.VAR_KEYWORD for p in accepted.values())
        unknown = [] if takes_any else sorted(set(params) - set(accepted))
        missing = [name for name, p in accepted.items() if p.default is p.empty
                   and p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY) and name not in params]
        if unknown:
            fault = f"does not accept {unknown}" + (f" and needs {missing}" if missing else "")
        elif missing:
            fault = f"does not accept the parameters given: it needs {missing}"
        else:  # pragma: no cover - positional-only parameters and the like
            fault = f"does not accept these parameters: {exc}"
        raise ConfigError(
            f"The '{field}' field: the {reg.kind} {spec.name!r} {fault}. Its parameters are {names}."
        ) from None
    try:
        return factory(**params)
    except ConfigError as exc:
        raise ConfigError(f"The '{field}' field: {exc}") from None


def build_distribution(friction: FrictionConfig) -> TruncatedBelow:
    """Build the mu_s plugin and truncate it below mu_d (docs/model.md section 1)."""
    dist = _build_plugin(registry.distributions, friction.static, "friction.static")
    check = getattr(dist, "check_mu_d", None)
    if check is not None:
        try:
            check(friction.mu_d)
        except ConfigError as exc:
            raise ConfigError(f"The 'friction.static' field: {exc}") from None
    try:
        return TruncatedBelow(dist, friction.mu_d, friction.static.name)
    except ConfigError as exc:
        raise ConfigError(f"The 'friction.static' field: {exc}") from None


def _describe(err: Mapping[str, Any]) -> str:
    # Drop pydantic's internal names of union members and validators from the path.
    loc = ".".join(
        str(p) for p in err["loc"] if not (str(p).startswith("function-") or "[" in str(p))
    )
    kind = err["type"]
    ctx = err.get("ctx") or {}
    got = err.get("input")
    if kind == "missing":
        return f"The {loc!r} field is required."
    if kind == "extra_forbidden":
        parent, _, key = loc.rpartition(".")
        where = f" in [{parent}]" if parent else ""
        return f"Unknown key {key!r}{where}."
    bounds = {"greater_than": ">", "greater_than_equal": ">=", "less_than": "<",
              "less_than_equal": "<="}
    if kind in bounds:
        limit = next(iter(ctx.values()))
        return f"The {loc!r} field must be {bounds[kind]} {limit}. Got {got!r} instead."
    if kind == "finite_number":
        return f"The {loc!r} field must be a finite number. Got {got!r} instead."
    if kind == "value_error":
        msg = str(ctx.get("error", err["msg"]))
        return f"The {loc!r} field: {msg}." if loc else f"Invalid combination: {msg}."
    return f"The {loc!r} field: {err['msg']}. Got {got!r} instead."


def read_toml(path: str | Path) -> dict[str, Any]:
    """A configuration file as a dict, not validated; relative file paths made relative to the file.

    Files named in a config file (a graph, a temperature series, measured
    thresholds) are found next to that file.
    """
    path = Path(path)
    try:
        with path.open("rb") as fh:
            source = tomllib.load(fh)
    except FileNotFoundError:
        raise ConfigError(f"The configuration file {str(path)!r} does not exist.") from None
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"The configuration file {str(path)!r} is not valid TOML: {exc}") from None
    friction = source.get("friction")
    static = friction.get("static") if isinstance(friction, dict) else None
    for table in (source.get("network"), source.get("driver"), static):
        if isinstance(table, dict) and isinstance(table.get("path"), str):
            named = Path(table["path"])
            if not named.is_absolute():
                table["path"] = str(path.parent / named)
    return source


def load_config(source: Config | Mapping[str, Any] | str | Path) -> Config:
    """Validate a configuration and build its plugins.

    Parameters
    ----------
    source : Config, mapping, or path
        A :class:`Config`, a dict with the keys of docs/model.md section 5, or the
        path of a TOML file with those keys.

    Returns
    -------
    Config
        The validated configuration, with its plugins already built.

    Raises
    ------
    ConfigError
        On any invalid field; the message names the field and the reason.
    """
    if isinstance(source, (str, Path)):
        source = read_toml(source)
    if isinstance(source, Config):
        cfg = source
    else:
        if not isinstance(source, Mapping):
            raise ConfigError(f"A configuration must be a dict, a Config or a path; got {type(source).__name__}.")
        try:
            cfg = Config.model_validate(dict(source))
        except ValidationError as exc:
            # dict.fromkeys: a union reports one error per member, often alike.
            lines = "\n".join(f"  - {m}" for m in dict.fromkeys(_describe(e) for e in exc.errors()))
            raise ConfigError(f"Invalid configuration:\n{lines}") from None
    cfg.distribution()
    _check_incline_holds(cfg)
    driver = cfg.driver_plugin()
    # An optional hook: a driver that cannot cover the run (a recorded series
    # too short) says so now, before any work.
    check = getattr(driver, "check_steps", None)
    if check is not None:
        try:
            check(cfg.steps)
        except ConfigError as exc:
            raise ConfigError(f"The 'driver' field: {exc}") from None
    return cfg


def _check_incline_holds(cfg: Config) -> None:
    """Refuse an incline steeper than every threshold: tan(incline) >= mu_s for every slider.

    Such a network can never rest: every slider is unstable on its own from
    t = 0 on. The law's upper end is taken after its truncation at mu_d.
    """
    incline = cfg.network.incline
    if not incline:
        return
    hi = cfg.distribution().support()[1]
    slope = math.tan(math.radians(incline))
    if hi <= slope:
        raise ConfigError(
            f"The 'network.incline' field: tan({incline!r} degrees) = {slope!r} is at or above every static "
            f"threshold (the law {cfg.friction.static.name!r} of 'friction.static' ends at mu_s = {hi!r}), so no "
            f"slider can rest on it. Use a smaller angle."
        )


def is_finite(x: float) -> bool:
    """True for a finite float (helper for plugin validation)."""
    return math.isfinite(x)


def build_network(cfg: Config) -> Network:
    """The network of the configured scene (its own seed: the geometry is quenched)."""
    return cfg.network.build()


def choose_kernel(requested: str, two_slider: bool, dim: int, catalogue: bool) -> str:
    """The kernel a scene runs on: the one rule, used by the scene and by the checks of a configuration.

    ``auto`` gives ``pair`` (scalars only) for the paper's two sliders unless
    the event catalogue is kept (observables "events" and "creep"; it needs per-node state), and else the
    network kernel of the dimension: ``csr`` in 1D, ``vec`` in 2D. A kernel
    named in ``solver.kernel`` is returned as it is (the scene refuses one
    that cannot run its network).

    >>> [choose_kernel("auto", True, 1, False), choose_kernel("auto", True, 1, True)]
    ['pair', 'csr']
    >>> choose_kernel("auto", False, 2, False)
    'vec'
    """
    if requested != "auto":
        return requested
    if two_slider and not catalogue:
        return "pair"
    return "csr" if dim == 1 else "vec"


#: Why ``mu_eff_at = "rearrangements"`` is refused: the one message, from :func:`choose_tilt_at`.
PAIR_TILT_ONLY = ("'mu_eff_at = \"rearrangements\"' (the appendix's tilt test before every rearrangement) "
                  "needs a 1D pair of sliders with unit normal loads and no f_ext; use 'records' "
                  "(the network tilt test at the recorded times)")


def choose_tilt_at(requested: str, pair_tilt: bool) -> str:
    """When the tilt test of mu_eff is made: the one rule, used by the scene and by the checks of a configuration.

    ``auto`` gives ``"rearrangements"`` (the appendix's test before every
    rearrangement) where it applies, ``"records"`` (the network tilt test at
    the recorded times) elsewhere; a value named in ``mu_eff_at`` is returned
    as it is, and ``"rearrangements"`` where the appendix's test does not
    apply is refused.

    Parameters
    ----------
    requested : {"auto", "rearrangements", "records"}
        The configuration's ``mu_eff_at``.
    pair_tilt : bool
        The appendix's test applies to the network
        (:func:`~slidernet.model.network.pair_tilt_applies`).

    Returns
    -------
    {"rearrangements", "records"}

    Raises
    ------
    ValueError
        ``"rearrangements"`` without ``pair_tilt``; the message is
        :data:`PAIR_TILT_ONLY` (a validator's ValueError, which pydantic
        reports with the field names).

    Examples
    --------
    >>> choose_tilt_at("auto", True), choose_tilt_at("auto", False)
    ('rearrangements', 'records')
    """
    if requested == "auto":
        return "rearrangements" if pair_tilt else "records"
    if requested == "rearrangements" and not pair_tilt:
        raise ValueError(PAIR_TILT_ONLY)
    return requested
