"""Plausibility: a scene far outside what real materials give is refused unless the configuration allows it.

Validity (every key of the run configuration) says a scene can run; plausibility says a real slider could
be it. A value that passes validation but lies far outside what real materials give is most often a unit
slip: ``sigma_theta = 1.0`` meant as 1 K instead of alpha x 1 K = 1e-5 drives the network 1e5 times too
hard, and the run goes on for hours. :func:`check` refuses such a scene when the configuration is loaded,
naming the quantity, its value, the range real materials give and the likely slip, unless the run
configuration says ``allow_implausible = true`` (a stress test, a study of the model beyond real
materials).

The ranges (:func:`ranges`) come from the material table of :mod:`slidernet.model.units` (what ``slidernet
units`` computes): each material of :data:`~slidernet.model.units.MATERIALS`, for slider sizes l0 in
:data:`SIZES` (1 mm grains to 1 m blocks) and standard deviations of the temperature in :data:`DELTA_T`
(1 mK in a thermostated laboratory to 10 K outdoors), widened by :data:`MARGIN` = 100 on each side. The
margin admits materials the table does not hold (a rubber's Y is 1e3 times below PMMA's, a metal foam's rho
1e1 times below steel's) and setups beyond the corners, while a value in the wrong unit stays outside:
a temperature in kelvin in place of alpha delta_T is 1 / alpha, 1.4e4 to 1.25e5 times too large for the
table's materials, so ``sigma_theta`` from 0.07 up is refused. sigma_theta / Ntilde of real setups spans
more than seven decades (a 1 m block in a thermostated room to millimetre grains outdoors), so the slip of
the issue's case shows first in ``sigma_theta`` itself: each quantity is checked on its own.

The strengthening's ``beta`` and ``tau_c`` are not in the material table: the log-aging slope of static
friction is 0.005 to 0.03 for rocks, glass and PMMA, and its cutoff time (``tau_c``) about 1 ms to 10 s
(Dieterich 1972, J. Geophys. Res. 77, 3690; Marone 1998, Annu. Rev. Earth Planet. Sci. 26, 643; Baumberger
& Caroli 2006, Adv. Phys. 55, 279). ``tau_c`` is in units of tau_th, so its range is those times over the
table's tau_th = l0^2 rho c / lambda, with the same margin. A ``beta`` of 0 switches the strengthening off
and is never refused; only a beta above the range is (a small one is weak aging, not a slip).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Any

from slidernet.model.units import MATERIALS, dimensionless

#: Slider sizes l0, m: millimetre grains to metre blocks.
SIZES = (1e-3, 1.0)
#: Standard deviations of the temperature, K: a thermostated laboratory (the paper's 0.01 K) to outdoors.
DELTA_T = (1e-3, 10.0)
#: The cutoff time of logarithmic aging, s (the papers in this module's docstring).
AGING_CUTOFF = (1e-3, 10.0)
#: The log-aging slope of static friction, dimensionless (the same papers).
AGING_SLOPE = (0.005, 0.03)
#: How far beyond the table's corners a value may lie: two decades each way.
MARGIN = 100.0

#: The keys of the drivers whose value is a scale of theta (a dilation alpha delta_T).
THETA_KEYS = ("sigma_theta", "amplitude", "noise_std")


@dataclass(frozen=True)
class Range:
    """What real materials give for one quantity, and the likely slips beyond it.

    Attributes
    ----------
    low, high : float
        The range, :data:`MARGIN` included.
    too_low, too_high : str
        The likely unit slip of a value below ``low`` / above ``high``, in words.
    """

    low: float
    high: float
    too_low: str
    too_high: str


_THETA = ("{key} is the dimensionless dilation alpha*DeltaT (1e-5 /K x 0.01 K = 1e-7 for the paper), "
          "not a temperature in kelvin")
_NTILDE = "Ntilde is the dimensionless N / (k l0) = rho g l0 / Y (1e-8 for the paper), not a load in newtons"


@functools.cache
def ranges() -> dict[str, Range]:
    """The plausible range of each checked quantity (see the module's docstring), by name.

    >>> r = ranges()
    >>> f"{r['Ntilde'].low:.2g} {r['Ntilde'].high:.2g} {r['sigma_theta'].high:.2g}"
    '3.5e-12 0.00039 0.07'
    >>> f"{r['sigma_theta / Ntilde'].low:.2g} {r['sigma_theta / Ntilde'].high:.2g}"
    '0.00015 3.1e+07'
    """
    found: dict[str, list[float]] = {"Ntilde": [], "sigma_theta": [], "sigma_theta / Ntilde": [], "tau_th": []}
    for name in MATERIALS:
        for size in SIZES:
            for delta_T in DELTA_T:
                d = dimensionless(name, size, delta_T)
                found["Ntilde"].append(d.Ntilde)
                found["sigma_theta"].append(d.sigma_theta)
                found["sigma_theta / Ntilde"].append(d.ratio)
                found["tau_th"].append(d.tau_th)

    def widened(values: list[float] | tuple[float, float], too_low: str, too_high: str) -> Range:
        return Range(min(values) / MARGIN, max(values) * MARGIN, too_low, too_high)

    tau = found.pop("tau_th")
    return {
        "Ntilde": widened(found["Ntilde"], _NTILDE, _NTILDE),
        "sigma_theta": widened(found["sigma_theta"], _THETA + " (or a dilation in percent or ppm)", _THETA),
        "sigma_theta / Ntilde": widened(
            found["sigma_theta / Ntilde"],
            "sigma_theta is alpha*DeltaT and Ntilde is rho g l0 / Y: one of them is in another unit",
            "sigma_theta is alpha*DeltaT, not a temperature in kelvin, and Ntilde is rho g l0 / Y"),
        "strengthening.tau_c": widened(
            (AGING_CUTOFF[0] / max(tau), AGING_CUTOFF[1] / min(tau)),
            "tau_c is in units of tau_th (the time for heat to cross a slider, seconds to weeks), not seconds",
            "tau_c is in units of tau_th (the time for heat to cross a slider, seconds to weeks), not seconds"),
        "strengthening.beta": Range(0.0, AGING_SLOPE[1] * MARGIN, "",
                                    "beta is the slope of mu_s against ln(age), about 0.01, not a percentage"),
    }


def _values(cfg: Any) -> dict[str, tuple[str, float]]:
    """The checked quantities of ``cfg``: name in :func:`ranges` -> (how the message names it, value)."""
    Ntilde = float(cfg.network.Ntilde)
    values = {"Ntilde": ("Ntilde", Ntilde)}
    params = cfg.driver.params
    for key in THETA_KEYS:
        try:
            theta = float(params[key])
        except (KeyError, TypeError, ValueError):  # absent, or the driver refuses it with its own message
            continue
        if theta > 0 and math.isfinite(theta):
            values["sigma_theta"] = (key, theta)
            values["sigma_theta / Ntilde"] = (f"{key} / Ntilde", theta / Ntilde)
            break
    strengthening = cfg.friction.strengthening
    if strengthening is not None and strengthening.beta > 0:
        values["strengthening.tau_c"] = ("strengthening.tau_c", float(strengthening.tau_c))
        values["strengthening.beta"] = ("strengthening.beta", float(strengthening.beta))
    return values


def check(cfg: Any) -> None:
    """Refuse a scene far outside what real materials give, unless ``cfg.allow_implausible``.

    ``cfg`` is a :class:`~slidernet.config.Config` (not imported here: its validation calls this check).

    Raises
    ------
    ValueError
        Naming each quantity outside its range (:func:`ranges`), its value, the range and the likely unit
        slip, and ``allow_implausible = true``. Raised inside the configuration's validation, it reaches
        the user as a :class:`~slidernet.errors.ConfigError`.
    """
    if cfg.allow_implausible:
        return
    found = ranges()
    values = _values(cfg)
    reasons = []
    for name, (label, value) in values.items():
        r = found[name]
        if r.low <= value <= r.high:
            continue
        slip = (r.too_low if value < r.low else r.too_high).format(key=label.split(" ")[0])
        # the drive that the scale of theta gives, where the ratio is not named on its own
        drive = values.get("sigma_theta / Ntilde") if name == "sigma_theta" else None
        also = f" ({drive[0]} = {drive[1]:.3g})" if drive and found["sigma_theta / Ntilde"].low <= drive[1] \
            <= found["sigma_theta / Ntilde"].high else ""
        reasons.append(f"{label} = {value:.3g}{also} is far outside what real materials give (about {r.low:.2g} "
                       f"to {r.high:.2g}; see `slidernet units`): {slip}")
    if reasons:
        raise ValueError("; ".join(reasons) + ". Set allow_implausible = true to run it anyway")
