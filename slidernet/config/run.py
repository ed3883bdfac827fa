"""The whole configuration of a run: :class:`Config`, and the names of the observables.

:class:`Config` holds the tables and the keys outside any table, checks
what no single table can (the values [units] gives against those given
directly, the observables against the kernel the scene will run on, the
recorded times against the duration), and builds its plugins once.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Annotated, Any, ClassVar, Literal

from pydantic import Field, PrivateAttr, model_validator

from slidernet.config.base import Integer, Seed, _Strict, unit
from slidernet.config.creep import CreepConfig
from slidernet.config.dynamics import DynamicsConfig
from slidernet.config.execution import ExecutionConfig
from slidernet.config.network import NetworkConfig
from slidernet.config.plausibility import check as check_plausibility
from slidernet.config.plugins import (
    FrictionConfig,
    PluginSpec,
    _build_plugin,
    _takes_sigma_theta,
    build_distribution,
)
from slidernet.config.rules import choose_kernel, choose_tilt_at
from slidernet.config.shs import ShsConfig
from slidernet.config.solver import SolverConfig
from slidernet.config.tilt import TiltConfig
from slidernet.config.units import _UNITS_RTOL, UnitsConfig, _fill_from_units
from slidernet.plugins import registry

if TYPE_CHECKING:  # the model and the distributions are imported where used (slidernet.config.network says why)
    from slidernet.model.network import Network
    from slidernet.plugins.distributions import TruncatedBelow

OBSERVABLES = ("n", "mu_max", "x_G", "mu_eff", "mu_eff_realization", "tilt_loads", "n_records", "events",
               "creep", "contact_age", "mu_shs")

#: Observables only the network kernels record (always, asked for or not); ``y_G`` in 2D only.
NETWORK_OBSERVABLES = ("y_G", "mu_mean", "mu_min", "avalanche_count", "node_slips", "mu_s")
Observable = Literal["n", "mu_max", "x_G", "mu_eff", "mu_eff_realization", "tilt_loads", "n_records", "events",
                     "creep", "contact_age", "mu_shs",
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

    # "plugins" too: a configuration without it dumps as it did before the key existed, so that
    # stored results and interrupted runs (run.json) still match it.
    _omit_if_none: ClassVar[tuple[str, ...]] = ("creep", "plugins", "tilt", "shs", "dynamics")
    _omit_if_default: ClassVar[tuple[str, ...]] = ("allow_implausible",)

    seed: Seed | None = Field(
        None, description="Seed of the run, in [0, 2^128): realization r is driven by child r of "
                          "SeedSequence(seed) (None: fresh OS entropy, stored in the result).")
    realizations: Annotated[Integer, Field(ge=1)] = Field(1, description="Number of independent realizations R.",
                                                          json_schema_extra=unit("1"))
    steps: Annotated[Integer, Field(ge=1)] = Field(
        description="Duration of a realization, in thermal steps of tau_th (theta is redrawn at each).",
        json_schema_extra=unit("tau_th"))
    record: Literal["log", "all"] | list[Annotated[Integer, Field(ge=0)]] = Field(
        "log", description="Recorded times, in tau_th: 'log'-spaced, 'all', or a list of steps; 0 and 'steps' "
                           "always included.", json_schema_extra=unit("tau_th"))
    log_points_per_decade: Annotated[Integer, Field(ge=1, le=1000)] = Field(
        20, description="Recorded times per decade of t with record = 'log'.", json_schema_extra=unit("1"))
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
    dynamics: DynamicsConfig | None = Field(
        None, description="Sliders with mass: the equations of motion, integrated by the inertial solver "
                          "([dynamics] tau_ratio); None: the quasi-static solver.")
    execution: ExecutionConfig = Field(
        default_factory=ExecutionConfig,
        description="Where the realizations run; never changes a result, and not part of a run's identity.")
    tilt: TiltConfig | None = Field(
        None, description="The sliding rule of the network tilt test (mu_eff at the recorded times); None: "
                          "one avalanche above mu_d in which every node slips, the rule of every earlier result.")
    creep: CreepConfig | None = Field(
        None, description="Parameters of the observable 'creep' (the reptation velocity and the creep events); "
                          "None: the defaults. Refused without that observable.")
    shs: ShsConfig | None = Field(
        None, description="The pull springs of the slide-hold-slide protocol (observable 'mu_shs'); None: the "
                          "defaults. Refused without that observable.")
    plugins: list[Annotated[str, Field(min_length=1)]] | None = Field(
        None, description="Python files (ending in .py; a relative path is relative to the configuration file) "
                          "or dotted module names that register plugins when imported "
                          "(slidernet.register_distribution, register_driver): imported in order, once per "
                          "process, before the names of [friction.static] and [driver] are looked up. Every "
                          "worker imports them again, so a file must be at the same path where the workers "
                          "run. None: none.")

    allow_implausible: bool = Field(
        False, description="Run a scene far outside what real materials give (slidernet.config.plausibility: "
                           "Ntilde, sigma_theta, their ratio, the strengthening's beta and tau_c), which is "
                           "otherwise refused as a likely unit slip.")

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
        if self.dynamics is not None:
            self._check_dynamics()  # first: its reasons are the ones that hold with [dynamics]
        if isinstance(self.record, list):
            if any(t > self.steps for t in self.record):
                raise ValueError(f"the 'record' times must lie in [0, steps = {self.steps}]")
        size = self.network.size()
        if self.friction.strengthening is not None:
            self.friction.strengthening.check_growth(self.steps)
            if self.mu_eff_at == "rearrangements":
                raise ValueError("'mu_eff_at = \"rearrangements\"' (the appendix's tilt test before every "
                                 "rearrangement) is made on thresholds that do not age; with "
                                 "[friction.strengthening] use 'mu_eff_at = \"records\"'")
            if self.solver.kernel == "pair":
                raise ValueError("[friction.strengthening] needs a network kernel (each contact's age); use "
                                 "'solver.kernel = \"auto\"' or '\"csr\"'")
        if self.mu_eff_at == "rearrangements":  # the network is built only for this check, where it may be a pair
            choose_tilt_at(self.mu_eff_at, self.pair_tilt_applies())
        if self.solver.kernel == "pair" and size not in (2, None):
            raise ValueError("the 'solver.kernel' value 'pair' needs a 2-slider network")
        for name, what in (("events", "the event catalogue"), ("creep", "computed from the event catalogue"),
                           ("contact_age", "each node's last slip")):
            if self.solver.kernel == "pair" and name in self.observables:
                raise ValueError(f"the {name!r} observable ({what}) needs a network kernel; "
                                 "use 'solver.kernel = \"auto\"' or '\"csr\"'")
        for name, what in (("mu_eff_realization", "each realization's own mu_eff"),
                           ("tilt_loads", "the tilt test's loads at its first slip, collective motion and "
                                          "contacts' breaks")):
            if name in self.observables and "mu_eff" not in self.observables:
                raise ValueError(f"the {name!r} observable ({what}) needs the tilt tests of 'mu_eff'; add "
                                 "\"mu_eff\" to 'observables'")
        if ("tilt_loads" in self.observables
                and choose_tilt_at(self.mu_eff_at, self.pair_tilt_applies()) != "records"):
            raise ValueError("the 'tilt_loads' observable is read from the network tilt test at the recorded "
                             "times: set 'mu_eff_at = \"records\"'")
        if self.tilt is not None:
            self._check_tilt_table(self.tilt)
        if self.friction.slip_factor() != 2.0 and self.solver.slip == "exact":
            raise ValueError("'friction.overshoot' sets the length of a straight-line slip, and 'solver.slip = "
                             "\"exact\"' integrates the undamped 2D motion, whose overshoot is 1; use one or the "
                             "other")
        if self.shs is not None and "mu_shs" not in self.observables:
            raise ValueError("the [shs] table sets the slide-hold-slide pull of the observable 'mu_shs', which is "
                             "not asked for; add \"mu_shs\" to 'observables' or remove the table")
        if self.creep is not None and "creep" not in self.observables:
            raise ValueError("the [creep] table sets the observable 'creep', which is not asked for; "
                             "add \"creep\" to 'observables' or remove the table")
        if "creep" in self.observables and self.creep_settings().transient >= self.steps:
            raise ValueError(f"the 'creep.transient' value must be < steps = {self.steps} (the run's duration, "
                             f"in tau_th), so that a reptation velocity is measured after it. "
                             f"Got {self.creep_settings().transient!r} instead")
        return self

    @model_validator(mode="after")
    def _check_plausible(self) -> Config:
        check_plausibility(self)  # after every validity check: a scene that cannot run is told why first
        return self

    def _check_tilt_table(self, tilt: TiltConfig) -> None:
        """Refuse a key of [tilt] that acts on tests this run does not make, naming the key and what to set."""
        if not tilt.is_default():
            if "mu_eff" not in self.observables:
                raise ValueError("the [tilt] table sets the sliding rule of the network tilt test of 'mu_eff', "
                                 "which is not asked for; add \"mu_eff\" to 'observables' or remove the table")
            if choose_tilt_at(self.mu_eff_at, self.pair_tilt_applies()) != "records":
                raise ValueError("the [tilt] table sets the sliding rule of the network tilt test, and this run's "
                                 "mu_eff is the appendix's test before every rearrangement: set "
                                 "'mu_eff_at = \"records\"'")
        missing = self._no_network_tilt_test()
        if tilt.repeats > 1 and missing is not None:
            raise ValueError(f"'tilt.repeats' = {tilt.repeats} asks for that many network tilt tests of 'mu_eff' "
                             f"at each recorded time, and this run makes none: {missing}")
        if tilt.inject is not None and not self.injected_tests():
            raise ValueError("'tilt.inject' raises the thresholds of the copy that a test of static friction "
                             "measures at the recorded times (the network tilt test of 'mu_eff', the "
                             "slide-hold-slide pull of 'mu_shs'), and this run makes neither: "
                             f"{missing}, or add \"mu_shs\" to 'observables'")
        if self.injects_by_age() and self.solver.kernel == "pair":
            raise ValueError("'tilt.inject' with select < 1 raises the oldest contacts, whose ages need a network "
                             "kernel; use 'solver.kernel = \"auto\"' or '\"csr\"'")

    def _check_dynamics(self) -> None:
        """What the inertial solver does not model, refused with the reason (docs/guides/inertia.md)."""
        refused = [
            (self.solver.kernel != "auto", "'solver.kernel' names a quasi-static kernel; leave it \"auto\""),
            (self.solver.slip != "straight", "'solver.slip' chooses the quasi-static 2D slip; the equations of "
                                             "motion make their own"),
            (self.friction.overshoot is not None, "'friction.overshoot' sets a quasi-static slip's length; the "
                                                  "equations of motion make their own"),
            (self.friction.strengthening is not None, "[friction.strengthening] is not modelled with inertia"),
            (self.mu_eff_at == "rearrangements", "'mu_eff_at = \"rearrangements\"' (the appendix's test before "
                                                 "every rearrangement) needs the quasi-static pair kernel; use "
                                                 "'records'"),
        ]
        refused += [(name in self.observables, f"the {name!r} observable is not recorded with inertia")
                    for name in ("creep", "mu_shs")]
        for bad, why in refused:
            if bad:
                raise ValueError(f"with [dynamics] (the inertial solver), {why}")

    def _no_network_tilt_test(self) -> str | None:
        """Why this run makes no network tilt test at the recorded times, and what to set; None if it makes one."""
        if "mu_eff" not in self.observables:
            return "\"mu_eff\" is not in 'observables'; add it"
        if choose_tilt_at(self.mu_eff_at, self.pair_tilt_applies()) != "records":
            return ("its mu_eff is the appendix's test of two sliders before every rearrangement; set "
                    "'mu_eff_at = \"records\"'")
        return None

    def injected_tests(self) -> list[str]:
        """The observables whose tests ``[tilt] inject`` raises in this run (the one place of that rule).

        The network tilt test of ``mu_eff`` at the recorded times, and the
        slide-hold-slide pull of ``mu_shs``: each alone, or both; an
        injection with none of them is refused.
        """
        return ([name for name, runs in (("mu_eff", self._no_network_tilt_test() is None),
                                         ("mu_shs", "mu_shs" in self.observables)) if runs])

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
        from slidernet.model.builders import KIND_DIMS

        pair = self.network.pair_network()  # a graph is built here, once
        dim = pair.dim if pair is not None else KIND_DIMS[self.network.kind]
        if dim is None:
            return None, False  # a graph file that cannot be read: building the scene reports it
        # With [dynamics] a pair runs on the inertial kernel, which records what the network kernels do.
        two = pair is not None and pair.is_two_slider() and self.dynamics is None
        return dim, choose_kernel(self.solver.kernel, two, dim, self.needs_node_state()) == "pair"

    def needs_catalogue(self) -> bool:
        """True if the kernel keeps the event catalogue: for the observable 'events', or 'creep' (read from it)."""
        return "events" in self.observables or "creep" in self.observables

    def needs_node_state(self) -> bool:
        """True if the scene needs a network kernel's per-node state: the event catalogue, or each node's last
        slip (observable 'contact_age', [friction.strengthening], or [tilt] inject with select < 1); a
        two-slider scene then runs on the 'csr' kernel."""
        return (self.needs_catalogue() or "contact_age" in self.observables
                or self.friction.strengthening is not None or self.injects_by_age())

    def injects_by_age(self) -> bool:
        """True if ``[tilt] inject`` raises the oldest contacts only (``select < 1``): it reads each node's
        last slip, as the observable 'contact_age' does."""
        inject = self.tilt_settings().inject
        return inject is not None and inject.select < 1.0

    def pair_tilt_applies(self, network: Network | None = None) -> bool:
        """True if the appendix's tilt test before every rearrangement can be this run's mu_eff: a 1D pair
        (:func:`~slidernet.model.network.pair_tilt_applies` of ``network``, or of the configured one,
        :meth:`NetworkConfig.pair_tilt_applies`) whose thresholds do not strengthen (its test reads the
        pair kernel's thresholds, which have no age)."""
        from slidernet.model.network import pair_tilt_applies

        if self.friction.strengthening is not None or self.dynamics is not None:
            return False
        return self.network.pair_tilt_applies() if network is None else pair_tilt_applies(network)

    def tilt_settings(self) -> TiltConfig:
        """The [tilt] table, or its defaults where it is not given."""
        return self.tilt if self.tilt is not None else TiltConfig()

    def shs_settings(self) -> ShsConfig:
        """The [shs] table, or its defaults where it is not given."""
        return self.shs if self.shs is not None else ShsConfig()

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
