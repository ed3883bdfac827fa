"""The tables that name a plugin, and building the plugins they name.

``[friction.static]`` and ``[driver]`` name a registered plugin and give the
parameters of its factory (:class:`PluginSpec`); ``[friction]`` pairs the
first with mu_d (:class:`FrictionConfig`). Building a plugin binds its
parameters to its factory's signature first, so that a wrong key is refused,
by name, before any work; :func:`build_distribution` builds the law of mu_s
and truncates it below mu_d.
"""

from __future__ import annotations

import inspect
import math
from typing import TYPE_CHECKING, Annotated, Any, ClassVar, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, model_validator

from slidernet.config.base import FiniteFloat, PositiveFloat, _Strict, unit
from slidernet.errors import ConfigError
from slidernet.plugins import registry
from slidernet.plugins.guard import build_plugin

# The kernels and the distributions (numba, scipy) are imported where they are used: a configuration is
# checked, and its errors reported, before any of them is imported (slidernet.config.loading).
if TYPE_CHECKING:
    from slidernet.plugins.distributions import TruncatedBelow


class PluginSpec(BaseModel):
    """A registered plugin by ``name``; every other key is a parameter of its factory."""

    model_config = ConfigDict(extra="allow")
    name: str = Field(description="The name the plugin is registered under (built-in or from an entry point).")

    @property
    def params(self) -> dict[str, Any]:
        """The factory's keyword arguments."""
        return dict(self.model_extra or {})


class StrengtheningConfig(_Strict):
    """Contact strengthening: a contact's static threshold grows with the time since its last renewal.

    mu_s,i(a) = mu_s,i^0 + beta L(a / tau_c), with a the age of node i's
    contact (the time since it last slipped, in tau_th; since t = 0 for a
    node that has not slipped) and mu_s,i^0 the threshold drawn at that
    renewal. ``law = "log"``: L(x) = ln(1 + x) (Dieterich; Baumberger and
    Caroli); ``law = "power"``: L(x) = (1 + x)^p - 1 with ``exponent`` p in
    (0, 1]. Both laws are built into the kernels rather than registered as
    plugins: the kernels evaluate the law inside the event search, and a
    user's compiled function passed to a kernel becomes an address in its
    machine code, which numba cannot cache.
    """

    law: Literal["log", "power"] = Field(
        "log", description="'log': beta ln(1 + a/tau_c); 'power': beta ((1 + a/tau_c)^exponent - 1).")
    beta: Annotated[FiniteFloat, Field(ge=0)] = Field(
        description="beta >= 0: the strengthening's amplitude, in units of mu_s (0: the option has no effect).",
        json_schema_extra=unit("1"))
    tau_c: PositiveFloat = Field(
        description="tau_c > 0: the age at which strengthening sets in, in tau_th.",
        json_schema_extra=unit("tau_th"))
    exponent: Annotated[FiniteFloat, Field(gt=0, le=1)] | None = Field(
        None, description="The power law's exponent p in (0, 1] (law = 'power' only).",
        json_schema_extra=unit("1"))

    @model_validator(mode="after")
    def _exponent_with_power_law(self) -> StrengtheningConfig:
        if self.law == "power" and self.exponent is None:
            raise ValueError("law = 'power' needs an 'exponent' in (0, 1]")
        if self.law == "log" and self.exponent is not None:
            raise ValueError("'exponent' belongs to law = 'power'; the 'log' law has none")
        return self

    def constants(self) -> tuple[float, float, float]:
        """(beta, tau_c, exponent) as the kernels take them; exponent 0.0 stands for the logarithmic law."""
        return float(self.beta), float(self.tau_c), 0.0 if self.law == "log" else float(self.exponent)

    def growth(self, age: float) -> float:
        """beta L(age / tau_c), what a contact of ``age`` tau_th adds to its threshold: the kernels' law
        (:func:`slidernet.kernels.strength.strengthening`), inf where float64 overflows.

        >>> StrengtheningConfig(beta=0.01, tau_c=1.0).growth(math.e - 1.0)
        0.01
        >>> StrengtheningConfig(beta=0.01, tau_c=5e-324).growth(10.0)
        inf
        """
        try:
            from slidernet.kernels.strength import strengthening

            return float(strengthening.py_func(self.constants(), float(age)))
        except OverflowError:  # math.expm1 of the power law past float64
            return math.inf

    def check_growth(self, steps: int) -> None:
        """Refuse a law whose growth over ``steps`` leaves float64 or passes :data:`MU_S_MAX`, the bound on
        every threshold (a contact that never slips ages by the whole run)."""
        grows = self.growth(float(steps))
        if not grows <= MU_S_MAX:
            raise ValueError(
                f"the 'friction.strengthening' table: over the run's {steps} steps a contact's threshold grows by "
                f"beta L(steps / tau_c) = {grows:.3g} (beta = {self.beta!r}, tau_c = {self.tau_c!r}), beyond "
                f"{MU_S_MAX:g}, the bound on every threshold that keeps the forces and their squares finite in "
                f"float64; use a larger tau_c or a smaller beta"
            )


class FrictionConfig(_Strict):
    """Dynamic coefficient mu_d, the distribution of static thresholds mu_s, and the slip rule.

    ``overshoot = e``, in [0, 1]: a slip moves a node by
    ``(1 + e) (|F_i| - mu_d N_i) / K_ii`` along its force. e = 1 (the default,
    also when the key is left out) is the paper's eq. `displacement`, the
    undamped half-oscillation under Coulomb friction, which leaves the node
    at a force ``2 mu_d N_i - |F_i|``; e = 0 stops the slip where the force
    reaches mu_d N_i. It applies to every kernel and to both tilt tests.
    """

    _omit_if_none: ClassVar[tuple[str, ...]] = ("overshoot", "strengthening")

    mu_d: PositiveFloat = Field(description="Dynamic friction coefficient mu_d (dimensionless).",
                                json_schema_extra=unit("1"))
    static: PluginSpec = Field(
        description="The distribution p(mu_s) of the static thresholds: a registered name and its "
                    "parameters; conditioned on mu_s > mu_d.")
    overshoot: Annotated[FiniteFloat, Field(ge=0, le=1)] | None = Field(
        None, description="e in [0, 1]: a slip moves a node by (1 + e)(F - mu_d N)/K_ii, F the force's "
                          "magnitude (None: 1, the paper's undamped slip; 0: the slip stops at mu_d N).",
        json_schema_extra=unit("1"))
    strengthening: StrengtheningConfig | None = Field(
        None, description="Contact strengthening, the [friction.strengthening] table (None: thresholds do not "
                          "age).")

    def slip_factor(self) -> float:
        """1 + e, the slip's length over ``(|F_i| - mu_d N_i) / K_ii`` (2.0: the paper's)."""
        return 1.0 + (1.0 if self.overshoot is None else float(self.overshoot))


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
        # The plugin's own errors, here and in every later call of its object, are named as its (plugins.guard).
        return build_plugin(reg, spec.name, factory, params)
    except ConfigError as exc:
        raise ConfigError(f"The '{field}' field: {exc}") from None


#: The largest static threshold slidernet accepts, in units of the normal load: forces, the tilt tests' loads
#: and their squares (in the tilt tests' sums and the standard errors) stay finite in float64 below it.
MU_S_MAX = 1e150
#: The probability above :data:`MU_S_MAX` that counts as none: below float64's resolution of a probability.
MU_S_MAX_TAIL = 2.0**-53


def build_distribution(friction: FrictionConfig) -> TruncatedBelow:
    """Build the mu_s plugin and truncate it below mu_d (docs/model.md section 1).

    A law that would draw thresholds above :data:`MU_S_MAX` (a power law of
    tiny ``alpha``, mu_d = 1e308) is refused, by the law's name. Floating
    point warnings of the law's functions at such extremes (an overflow of
    sf(1e308)) are not shown: the values they give are judged here, and a
    raw numpy line before the refusal said nothing more.
    """
    from slidernet.plugins.distributions import TruncatedBelow

    name = friction.static.name
    with np.errstate(all="ignore"):
        dist = _build_plugin(registry.distributions, friction.static, "friction.static")
        check = getattr(dist, "check_mu_d", None)
        try:
            if check is not None:
                check(friction.mu_d)
            law = TruncatedBelow(dist, friction.mu_d, name)
        except ConfigError as exc:
            raise ConfigError(f"The 'friction.static' field: {exc}") from None
        tail = float(law.sf(MU_S_MAX))
    if tail > MU_S_MAX_TAIL:  # NaN (a plugin's sf undefined there) is left to the draws' own checks
        raise ConfigError(
            f"The 'friction.static' field: the distribution {name!r} (above mu_d = {friction.mu_d!r}) draws "
            f"mu_s > {MU_S_MAX:g} with probability {tail:.3g}; every threshold must stay below {MU_S_MAX:g} "
            f"(a probability under 2^-53), so that the forces and their squares stay finite in float64."
        )
    return law


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


def is_finite(x: float) -> bool:
    """True for a finite float (helper for plugin validation)."""
    return math.isfinite(x)
