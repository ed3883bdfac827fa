"""From a material and a setup to the model's dimensionless parameters.

The model works in units of l0 (lengths), N (forces) and tau_th (time), so a
real setup enters through three numbers only. They follow the discussion of
orders of magnitude in Géminard & Bertin (2010), section V ("Discussion",
``\\label{discussion}``):

* ``Ntilde = N / (k l0) = rho g l0 / Y``. The paper takes the spring stiffness
  k ~ Y A / l0 and the normal load N ~ rho A l0 g for a slider of cross
  section A and length l0; A cancels, so the shape does not matter. With
  g = 10 m/s^2, rho ~ 1e3 kg/m^3, Y ~ 100 GPa and l0 = 10 cm the paper finds
  Ntilde ~ 1e-8.
* ``sigma_theta = alpha * delta_T``: theta = kappa (T - T0) (eq. of l(T) in
  section II), so the standard deviation of theta is the thermal expansion
  coefficient (the paper's kappa, here ``alpha``) times the standard deviation
  delta_T of the temperature. The paper: kappa ~ 1e-5 /K and 0.01 K give
  sigma_theta ~ 1e-7.
* ``tau_th = l0^2 C / lambda`` with C = rho c the heat capacity per unit
  volume and lambda the thermal conductivity: the time for heat to diffuse
  over the slider size (diffusion coefficient lambda / C).

A note on tau_th: the paper quotes lambda ~ 1 W/(m K) and C ~ 1e6 J/(m^3 K)
and then a range of 1e-2 to 1 s for l0 = 1 to 10 cm. Its own formula gives
1e2 to 1e4 s for those values (lambda / C = 1e-6 m^2/s, and 1 cm^2 / 1e-6
m^2/s = 100 s); the quoted range matches l0 = 0.1 to 1 mm instead. This
module follows the formula, not the quoted range. tau_th only converts the
model's time (in tau_th) to seconds; it changes no result of a run.

Examples
--------
>>> r = dimensionless("steel", size=0.1, delta_T=0.01)
>>> f"{r.Ntilde:.3g} {r.sigma_theta:.3g} {r.tau_th:.3g} {r.ratio:.3g}"
'3.85e-08 1.2e-07 769 3.12'
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass
from typing import Any

from slidernet._validation import check_scalar
from slidernet.errors import ConfigError

#: Standard gravity, m/s^2.
G_STANDARD = 9.81

_OWNER = "units"


def _positive(value: object, param: str) -> float:
    """``value`` as a float, refused with a message naming ``param`` unless a finite real number > 0.

    >>> _positive(-1, "Y")
    Traceback (most recent call last):
    ...
    slidernet.errors.ConfigError: The 'Y' parameter of units must be > 0. Got -1.0 instead.
    """
    return check_scalar(value, param, _OWNER, "> 0")


def ntilde(rho: float, Y: float, size: float, g: float = G_STANDARD) -> float:
    """Ntilde = N / (k l0) = rho g l0 / Y (the paper, section V).

    Parameters
    ----------
    rho : float
        Density of the slider material, kg/m^3.
    Y : float
        Young's modulus, Pa.
    size : float
        Slider size l0, m.
    g : float
        Gravity, m/s^2 (default 9.81).

    Returns
    -------
    float
        Ntilde, dimensionless.

    Examples
    --------
    The paper's estimate (g = 10 m/s^2, rho = 1e3 kg/m^3, Y = 100 GPa, l0 = 10 cm):

    >>> ntilde(rho=1e3, Y=100e9, size=0.1, g=10.0)
    1e-08
    """
    return _positive(rho, "rho") * _positive(g, "g") * _positive(size, "size") / _positive(Y, "Y")


def sigma_theta(alpha: float, delta_T: float) -> float:
    """sigma_theta = alpha * delta_T, the standard deviation of theta = alpha (T - T0).

    Parameters
    ----------
    alpha : float
        Linear thermal expansion coefficient (the paper's kappa), 1/K.
    delta_T : float
        Standard deviation of the temperature, K (not an amplitude).

    Returns
    -------
    float
        sigma_theta, dimensionless.

    Examples
    --------
    The paper: kappa ~ 1e-5 /K and temperature changes of 0.01 K give 1e-7.

    >>> f"{sigma_theta(alpha=1e-5, delta_T=0.01):.3g}"
    '1e-07'
    """
    return _positive(alpha, "alpha") * _positive(delta_T, "delta_T")


def tau_th(rho: float, heat_capacity: float, conductivity: float, size: float) -> float:
    """tau_th = l0^2 rho c / lambda, the time for heat to diffuse over the slider.

    Parameters
    ----------
    rho : float
        Density, kg/m^3.
    heat_capacity : float
        Specific heat capacity c, J/(kg K); rho c is the paper's C, J/(m^3 K).
    conductivity : float
        Thermal conductivity lambda, W/(m K).
    size : float
        Slider size l0, m.

    Returns
    -------
    float
        tau_th, s.

    Examples
    --------
    The paper's values (C = 1e6 J/(m^3 K), lambda = 1 W/(m K)) for l0 = 1 cm:

    >>> round(tau_th(rho=1e3, heat_capacity=1e3, conductivity=1.0, size=0.01), 9)
    100.0
    """
    size = _positive(size, "size")
    return size * size * _positive(rho, "rho") * _positive(heat_capacity, "heat_capacity") \
        / _positive(conductivity, "conductivity")


@dataclass(frozen=True)
class Material:
    """Bulk properties of a slider material (SI units).

    Parameters
    ----------
    name : str
        Label used in messages and output.
    rho : float
        Density, kg/m^3.
    Y : float
        Young's modulus, Pa.
    alpha : float, optional
        Linear thermal expansion coefficient, 1/K (needed for sigma_theta).
    conductivity : float, optional
        Thermal conductivity lambda, W/(m K) (needed for tau_th).
    heat_capacity : float, optional
        Specific heat capacity c, J/(kg K) (needed for tau_th).
    source : str
        Where the values come from.

    Examples
    --------
    >>> Material("brass", rho=8500, Y=100e9, alpha=1.9e-5).Y
    100000000000.0
    >>> Material("bad", rho=1e3, Y=-1)
    Traceback (most recent call last):
    ...
    slidernet.errors.ConfigError: The 'Y' parameter of units must be > 0. Got -1.0 instead.
    """

    name: str
    rho: float
    Y: float
    alpha: float | None = None
    conductivity: float | None = None
    heat_capacity: float | None = None
    source: str = ""

    def __post_init__(self) -> None:
        for field in ("rho", "Y", "alpha", "conductivity", "heat_capacity"):
            value = getattr(self, field)
            if value is None and field not in ("rho", "Y"):
                continue
            object.__setattr__(self, field, _positive(value, field))

    def replace(self, **changes: float | str | None) -> Material:
        """A copy with some values changed (``None`` values are ignored), validated again.

        >>> MATERIALS["steel"].replace(Y=210e9, rho=None).Y
        210000000000.0
        """
        changes = {k: v for k, v in changes.items() if v is not None}
        return dataclasses.replace(self, **changes)  # type: ignore[arg-type]


_HANDBOOKS = ("rounded typical room-temperature values, as tabulated in M. F. Ashby, Materials Selection "
              "in Mechanical Design (4th ed., 2011) and the CRC Handbook of Chemistry and Physics; "
              "real grades differ by 10-30 %")

#: Presets with typical values. Real grades vary: give explicit values for a real setup.
MATERIALS: dict[str, Material] = {
    # Carbon steel (e.g. AISI 1020).
    "steel": Material("steel", rho=7850.0, Y=200e9, alpha=1.2e-5, conductivity=50.0, heat_capacity=490.0,
                      source="carbon steel: " + _HANDBOOKS),
    # Soda-lime glass.
    "glass": Material("glass", rho=2500.0, Y=70e9, alpha=9e-6, conductivity=1.0, heat_capacity=840.0,
                      source="soda-lime glass: " + _HANDBOOKS),
    # Granite: the widest spread (Y from 10 to 70 GPa with porosity and cracks).
    "granite": Material("granite", rho=2700.0, Y=50e9, alpha=8e-6, conductivity=2.8, heat_capacity=790.0,
                        source="granite: " + _HANDBOOKS),
    # Poly(methyl methacrylate), below its glass transition.
    "pmma": Material("pmma", rho=1190.0, Y=3e9, alpha=7e-5, conductivity=0.19, heat_capacity=1470.0,
                     source="PMMA: " + _HANDBOOKS),
}


def material(name: str | Material) -> Material:
    """A preset by name (case-insensitive), or ``name`` itself if it is a :class:`Material`.

    >>> material("Glass").Y
    70000000000.0
    >>> material("wood")
    Traceback (most recent call last):
    ...
    slidernet.errors.ConfigError: Unknown material 'wood'. Available: 'glass', 'granite', 'pmma', 'steel'.
    """
    if isinstance(name, Material):
        return name
    found = MATERIALS.get(str(name).lower())
    if found is None:
        available = ", ".join(repr(n) for n in sorted(MATERIALS))
        raise ConfigError(f"Unknown material {name!r}. Available: {available}.")
    return found


_lookup = material  # for functions whose parameter is called ``material``


@dataclass(frozen=True)
class Dimensionless:
    """The model's parameters for one setup (the output of :func:`dimensionless`).

    Attributes
    ----------
    Ntilde : float
        N / (k l0), dimensionless (``[network] Ntilde``).
    sigma_theta : float or None
        Standard deviation of theta (``[driver] sigma_theta``); None without delta_T.
    tau_th : float or None
        Thermal time, s; None without conductivity and heat capacity.
    ratio : float or None
        sigma_theta / Ntilde. Rearrangements need it above about mu_d (eq. `slope`), and
        their number per tau_th grows with it.
    material : Material
        The values used.
    size : float
        l0, m.
    delta_T : float or None
        Standard deviation of the temperature, K.
    g : float
        Gravity, m/s^2.
    """

    Ntilde: float
    sigma_theta: float | None
    tau_th: float | None
    ratio: float | None
    material: Material
    size: float
    delta_T: float | None
    g: float

    def toml(self) -> str:
        """The TOML lines of a config that use these values (exact: they round-trip).

        >>> print(dimensionless("glass", size=0.05, delta_T=0.01, g=10.0).toml())
        [network]
        Ntilde = 1.7857142857142856e-08
        <BLANKLINE>
        [driver]
        name = "gaussian_steps"
        sigma_theta = 9e-08
        """
        lines = ["[network]", f"Ntilde = {self.Ntilde!r}"]
        if self.sigma_theta is not None:
            lines += ["", "[driver]", 'name = "gaussian_steps"', f"sigma_theta = {self.sigma_theta!r}"]
        return "\n".join(lines)

    def units_toml(self) -> str:
        """The ``[units]`` table of a config that gives the same values (see :class:`~slidernet.config.Config`).

        >>> print(dimensionless("steel", size=0.1, delta_T=0.01).units_toml())
        [units]
        material = "steel"
        size = 0.1
        delta_T = 0.01
        """
        m = self.material
        lines = ["[units]"]
        if MATERIALS.get(m.name) == m:
            lines.append(f'material = "{m.name}"')
        else:
            for field in ("rho", "Y", "alpha", "conductivity", "heat_capacity"):
                if getattr(m, field) is not None:
                    lines.append(f"{field} = {getattr(m, field)!r}")
        lines.append(f"size = {self.size!r}")
        if self.delta_T is not None:
            lines.append(f"delta_T = {self.delta_T!r}")
        if self.g != G_STANDARD:
            lines.append(f"g = {self.g!r}")
        return "\n".join(lines)

    def summary(self) -> str:
        """A human-readable table of the inputs and the results (what ``slidernet units`` prints).

        >>> print(dimensionless("steel", size=0.1, delta_T=0.01).summary())  # doctest: +NORMALIZE_WHITESPACE
        material            steel: rho = 7850 kg/m^3, Y = 2e+11 Pa, alpha = 1.2e-05 1/K,
                            lambda = 50 W/(m K), c = 490 J/(kg K)
        setup               l0 = 0.1 m, delta_T = 0.01 K, g = 9.81 m/s^2
        Ntilde              3.85e-08   N / (k l0) = rho g l0 / Y
        sigma_theta         1.2e-07    alpha delta_T
        sigma_theta/Ntilde  3.12       rearrangements need more than about mu_d
        tau_th              769 s      l0^2 rho c / lambda
        """
        m = self.material
        props = [f"rho = {m.rho:g} kg/m^3", f"Y = {m.Y:g} Pa"]
        if m.alpha is not None:
            props.append(f"alpha = {m.alpha:g} 1/K")
        thermal = []
        if m.conductivity is not None:
            thermal.append(f"lambda = {m.conductivity:g} W/(m K)")
        if m.heat_capacity is not None:
            thermal.append(f"c = {m.heat_capacity:g} J/(kg K)")
        pad = " " * 20
        lines = [f"{'material':<20}{m.name}: {', '.join(props)}" + ("," if thermal else "")]
        if thermal:
            lines.append(pad + ", ".join(thermal))
        dT = "not given" if self.delta_T is None else f"{self.delta_T:g} K"
        lines.append(f"{'setup':<20}l0 = {self.size:g} m, delta_T = {dT}, g = {self.g:g} m/s^2")
        lines.append(f"{'Ntilde':<20}{self.Ntilde:<10.3g} N / (k l0) = rho g l0 / Y")
        if self.sigma_theta is None:
            lines.append(f"{'sigma_theta':<20}{'n/a':<10} (give delta_T)")
        else:
            lines.append(f"{'sigma_theta':<20}{self.sigma_theta:<10.3g} alpha delta_T")
            lines.append(f"{'sigma_theta/Ntilde':<20}{self.ratio:<10.3g} rearrangements need more than about mu_d")
        if self.tau_th is None:
            lines.append(f"{'tau_th':<20}{'n/a':<10} (give conductivity and heat capacity)")
        else:
            lines.append(f"{'tau_th':<20}{f'{self.tau_th:.3g} s':<10} l0^2 rho c / lambda")
        return "\n".join(lines)


@dataclass(frozen=True)
class Quantity:
    """A value of the setup as the command line takes it: a number with its unit, read into SI.

    Attributes
    ----------
    unit : str
        The SI unit the value is converted to, as pint reads it (``"m"``, ``"K"``).
    what : str
        What the value is, for a message (``"a length"``).
    examples : tuple of str
        Ways to write it, for a message (``("10cm", "0.1m")``).
    """

    unit: str
    what: str
    examples: tuple[str, ...]


#: The quantities of a setup, by their parameter's name: a bare number is refused for each, since none has a
#: unit a physicist would take for granted (a slider of "10" is 10 m or 10 cm; a delta_T of "300" is a
#: temperature, not a standard deviation of one).
QUANTITIES = {
    "size": Quantity("m", "a length", ("10cm", "0.1m")),
    "delta_T": Quantity("K", "a temperature difference", ("0.01K", "10mK")),
    "rho": Quantity("kg/m^3", "a density", ("7800kg/m^3", "7.8g/cm^3")),
    "Y": Quantity("Pa", "a Young's modulus", ("200GPa", "2e11Pa")),
    "alpha": Quantity("1/K", "a thermal expansion coefficient", ("12e-6/K", "12ppm/K")),
    "conductivity": Quantity("W/(m K)", "a thermal conductivity", ("50W/m/K",)),
    "heat_capacity": Quantity("J/(kg K)", "a specific heat capacity", ("450J/kg/K",)),
    "g": Quantity("m/s^2", "an acceleration", ("9.81m/s^2",)),
}


def read_quantity(text: str, param: str, option: str | None = None) -> float:
    """The value of ``param`` written as ``text``, a number with its unit, in the SI unit of :data:`QUANTITIES`.

    pint reads the unit (any unit of the right dimension: ``10cm``,
    ``0.1 m``, ``4in``); a bare number, a unit of another dimension, and an
    absolute temperature scale for ``delta_T`` (``3degC`` is 276.15 K;
    its difference is ``3delta_degC``) are refused with a message that
    names ``option`` (default: the parameter) and a way to write it.

    Examples
    --------
    >>> read_quantity("10cm", "size"), read_quantity("10 mK", "delta_T"), read_quantity("200GPa", "Y")
    (0.1, 0.01, 200000000000.0)
    >>> read_quantity("0.1", "size", "--size")
    Traceback (most recent call last):
    ...
    slidernet.errors.ConfigError: The '--size' option must be a length with its unit, such as --size 10cm or \
--size 0.1m: a bare number is ambiguous. Got '0.1' instead.
    """
    import pint  # here only: 0.5 s to import and 0.3 s to build its registry, which only `slidernet units` needs

    spec = QUANTITIES[param]
    name = option or param
    write = " or ".join(f"{name} {example}" if option else f"{example!r}" for example in spec.examples)
    where = f"The {name!r} option" if option else f"The {param!r} parameter of {_OWNER}"

    def refuse(why: str) -> ConfigError:
        return ConfigError(f"{where} must be {spec.what} with its unit, such as {write}{why}. "
                           f"Got {text!r} instead.")

    registry = _unit_registry()
    try:
        value = registry.Quantity(text)
    except pint.errors.OffsetUnitCalculusError:
        raise refuse(" (a temperature difference in degrees Celsius is written delta_degC)") from None
    except Exception:  # pint's parser raises many kinds (an undefined unit, a syntax error, a bad token)
        raise refuse(": pint cannot read it as a number and a unit") from None
    if not isinstance(value, registry.Quantity) or value.dimensionless:
        raise refuse(": a bare number is ambiguous")
    try:
        return float(value.to(spec.unit).magnitude)
    except pint.errors.DimensionalityError:
        raise refuse(f": its unit, {value.units:~}, is not that of {spec.what}") from None


@functools.cache
def _unit_registry() -> Any:
    """pint's registry of units, built once (pint is imported only here and in :func:`read_quantity`)."""
    import pint

    return pint.UnitRegistry()


def setup(
    material: str | Material | None = None,
    *,
    size: float,
    delta_T: float | None = None,
    g: float = G_STANDARD,
    **values: float | None,
) -> Dimensionless:
    """:func:`dimensionless` for a preset and/or explicit values (what the CLI and ``[units]`` take).

    Parameters
    ----------
    material : str or Material, optional
        A preset name or a :class:`Material`; explicit ``values`` override its values.
    size, delta_T, g : float
        As in :func:`dimensionless`.
    **values : float or None
        Any of ``rho``, ``Y``, ``alpha``, ``conductivity``, ``heat_capacity``
        (SI units, see :class:`Material`); None values are ignored.

    Examples
    --------
    >>> f"{setup(rho=1e3, Y=100e9, size=0.1, g=10.0).Ntilde:.3g}"
    '1e-08'
    >>> f"{setup('steel', Y=100e9, size=0.1).Ntilde:.3g}"
    '7.7e-08'
    >>> setup(rho=1e3, size=0.1)
    Traceback (most recent call last):
    ...
    slidernet.errors.ConfigError: Give a material or explicit values of 'Y' (units).
    """
    known = ("rho", "Y", "alpha", "conductivity", "heat_capacity")
    unknown = sorted(set(values) - set(known))
    if unknown:
        raise TypeError(f"Unknown material values {unknown}; known: {list(known)}.")
    given = {k: v for k, v in values.items() if v is not None}
    if material is not None:
        mat = _lookup(material).replace(**given)
    else:
        missing = [p for p in ("rho", "Y") if p not in given]
        if missing:
            raise ConfigError(f"Give a material or explicit values of {' and '.join(repr(p) for p in missing)} "
                              f"(units).")
        mat = Material("custom", **given)  # type: ignore[arg-type]
    return dimensionless(mat, size, delta_T, g)


def dimensionless(
    mat: str | Material, size: float, delta_T: float | None = None, g: float = G_STANDARD
) -> Dimensionless:
    """Ntilde, sigma_theta, tau_th and sigma_theta / Ntilde for a material and a setup.

    Parameters
    ----------
    mat : str or Material
        A preset name (``"steel"``, ``"glass"``, ``"granite"``, ``"pmma"``) or a :class:`Material`.
    size : float
        Slider size l0, m.
    delta_T : float, optional
        Standard deviation of the temperature, K. Without it sigma_theta is None.
    g : float
        Gravity, m/s^2 (default 9.81).

    Returns
    -------
    Dimensionless

    Raises
    ------
    ConfigError
        On an unknown preset, a value that is not finite and > 0, or delta_T given
        for a material without ``alpha``; the message names the parameter.

    Examples
    --------
    >>> r = dimensionless("pmma", size=0.01, delta_T=1e-3)
    >>> f"{r.Ntilde:.3g} {r.sigma_theta:.3g} {r.ratio:.3g} {r.tau_th:.3g} s"
    '3.89e-08 7e-08 1.8 921 s'
    >>> dimensionless("steel", size=0.0)
    Traceback (most recent call last):
    ...
    slidernet.errors.ConfigError: The 'size' parameter of units must be > 0. Got 0.0 instead.
    """
    m = material(mat)
    size = _positive(size, "size")
    g = _positive(g, "g")
    nt = ntilde(m.rho, m.Y, size, g)
    sig = None
    if delta_T is not None:
        delta_T = _positive(delta_T, "delta_T")
        if m.alpha is None:
            raise ConfigError(f"The 'alpha' parameter of units is needed to turn delta_T into sigma_theta "
                              f"(material {m.name!r} has none).")
        sig = sigma_theta(m.alpha, delta_T)
    tau = None
    if m.conductivity is not None and m.heat_capacity is not None:
        tau = tau_th(m.rho, m.heat_capacity, m.conductivity, size)
    return Dimensionless(
        Ntilde=nt, sigma_theta=sig, tau_th=tau, ratio=None if sig is None else sig / nt,
        material=m, size=size, delta_T=delta_T, g=g,
    )
