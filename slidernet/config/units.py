"""The ``[units]`` table: a physical setup from which Ntilde and sigma_theta are computed.

:class:`UnitsConfig` validates the setup. Before the whole configuration is
validated, the values the table gives fill ``network.Ntilde`` and
``driver.sigma_theta`` where they are absent (``_fill_from_units``); a value
given both ways is compared with the table's, within ``_UNITS_RTOL``, by the
whole configuration, which sees both.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from pydantic import Field, ValidationError, field_validator, model_validator

from slidernet.config.base import PositiveFloat, _Strict, unit
from slidernet.config.plugins import _takes_sigma_theta
from slidernet.errors import ConfigError
from slidernet.model import units


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
    rho: PositiveFloat | None = Field(None, description="Density of the sliders, in kg/m^3.",
                                      json_schema_extra=unit("kg/m^3"))
    Y: PositiveFloat | None = Field(None, description="Young's modulus, in Pa.", json_schema_extra=unit("Pa"))
    alpha: PositiveFloat | None = Field(None, description="Linear thermal expansion coefficient, in 1/K.",
                                        json_schema_extra=unit("1/K"))
    conductivity: PositiveFloat | None = Field(None, description="Thermal conductivity, in W/(m K).",
                                               json_schema_extra=unit("W/(m K)"))
    heat_capacity: PositiveFloat | None = Field(None, description="Specific heat capacity, in J/(kg K).",
                                                json_schema_extra=unit("J/(kg K)"))
    size: PositiveFloat = Field(description="Size of a slider, l0, in m.", json_schema_extra=unit("m"))
    delta_T: PositiveFloat | None = Field(
        None, description="Standard deviation of the temperature, in K (not an amplitude): gives "
                          "sigma_theta = alpha delta_T.", json_schema_extra=unit("K"))
    g: PositiveFloat = Field(units.G_STANDARD, description="Acceleration of gravity, in m/s^2.",
                             json_schema_extra=unit("m/s^2"))

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
