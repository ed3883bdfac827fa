"""Distributions p(mu_s) of the static friction threshold.

A distribution plugin is any object with

* ``sample(rng, size) -> ndarray`` -- ``size`` independent draws, using only
  the ``numpy.random.Generator`` it is given;
* ``cdf(x) -> ndarray`` -- the cumulative distribution function;
* optionally ``sf(x)`` (the survival function, 1 - cdf, accurate in the
  tail) and ``check_mu_d(mu_d)`` (raise :class:`~slidernet.errors.ConfigError`
  when the parameters make no sense for that mu_d).

The model requires p(mu_s) = 0 for mu_s <= mu_d (the paper, section II.A).
slidernet enforces this for every plugin with :class:`TruncatedBelow`: draws
at or below mu_d are rejected and redrawn, and the cdf is renormalised.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import special

from slidernet.errors import ConfigError, param_error


def _check_finite_positive(value: float, param: str, owner: str) -> float:
    value = float(value)
    if not math.isfinite(value) or value <= 0:
        raise param_error(param, owner, "finite and > 0", value)
    return value


class Gaussian:
    """Gaussian p(mu_s) of the paper (section III), before truncation at mu_d.

    Parameters
    ----------
    mean : float
        mu_s bar, the mean static friction coefficient (dimensionless).
    std : float
        sigma_mu, its standard deviation; > 0.

    Examples
    --------
    >>> import numpy as np
    >>> d = Gaussian(mean=0.6, std=0.01)
    >>> d.sample(np.random.default_rng(0), 3).shape
    (3,)
    >>> float(d.cdf(0.6))
    0.5
    """

    def __init__(self, mean: float, std: float) -> None:
        mean = float(mean)
        if not math.isfinite(mean):
            raise param_error("mean", "gaussian", "finite", mean)
        self.mean = mean
        self.std = _check_finite_positive(std, "std", "gaussian")

    def check_mu_d(self, mu_d: float) -> None:
        """Refuse a mean at or below mu_d: the truncated law would be degenerate."""
        if self.mean <= mu_d:
            raise param_error("mean", "gaussian", f"> mu_d = {mu_d!r}", self.mean)

    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        """``size`` draws, shape ``(size,)``."""
        x = rng.standard_normal(size)
        # In place: sampling is a visible share of the two-slider run time.
        x *= self.std
        x += self.mean
        return x

    def cdf(self, x: np.ndarray | float) -> np.ndarray:
        """P(mu_s <= x)."""
        return special.ndtr((np.asarray(x, dtype=float) - self.mean) / self.std)

    def sf(self, x: np.ndarray | float) -> np.ndarray:
        """P(mu_s > x), accurate far in the upper tail."""
        return special.ndtr(-(np.asarray(x, dtype=float) - self.mean) / self.std)

    def __repr__(self) -> str:
        return f"Gaussian(mean={self.mean!r}, std={self.std!r})"


class TruncatedBelow:
    """A distribution conditioned on mu_s > ``lower`` (normally mu_d).

    Sampling is by rejection in batches, so a plugin written in plain numpy
    stays fast. A plugin whose mass above ``lower`` is below ``min_mass`` is
    refused, since rejection would then never end.

    Parameters
    ----------
    dist : object
        The plugin distribution (``sample`` and ``cdf``; ``sf`` optional).
    lower : float
        The truncation point (mu_d); draws must be strictly above it.
    name : str
        The plugin's registered name, used in error messages.
    min_mass : float
        Smallest acceptable P(mu_s > lower).

    Examples
    --------
    >>> import numpy as np
    >>> d = TruncatedBelow(Gaussian(0.6, 0.1), lower=0.5, name="gaussian")
    >>> bool((d.sample(np.random.default_rng(1), 1000) > 0.5).all())
    True
    >>> round(float(d.cdf(0.5)), 12)
    0.0
    """

    def __init__(self, dist: object, lower: float, name: str, min_mass: float = 1e-6) -> None:
        self.dist = dist
        self.lower = float(lower)
        self.name = name
        mass = float(self._raw_sf(self.lower))
        if not (mass >= min_mass):
            raise ConfigError(
                f"The distribution {name!r} puts probability {mass!r} above mu_d = {lower!r}; "
                f"at least {min_mass!r} is needed (p(mu_s) must vanish for mu_s <= mu_d)."
            )
        self.mass = mass
        self.acceptance = mass

    def _raw_sf(self, x: np.ndarray | float) -> np.ndarray:
        sf = getattr(self.dist, "sf", None)
        if sf is not None:
            return np.asarray(sf(x), dtype=float)
        return 1.0 - np.asarray(self.dist.cdf(x), dtype=float)

    def _checked(self, draws: object, size: int) -> np.ndarray:
        from slidernet.registry import checked_output

        return checked_output(draws, (size,), "distribution", self.name, f"sample(rng, {size})")

    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        """``size`` draws strictly above ``lower``, shape ``(size,)``."""
        out = self._checked(self.dist.sample(rng, size), size)
        bad = np.flatnonzero(out <= self.lower)
        while bad.size:
            # Ask for extra draws so that the loop ends in one or two passes.
            want = int(bad.size / self.acceptance * 1.2) + 8
            fresh = self._checked(self.dist.sample(rng, want), want)
            fresh = fresh[fresh > self.lower][: bad.size]
            out[bad[: fresh.size]] = fresh
            bad = bad[fresh.size :]
        return out

    def cdf(self, x: np.ndarray | float) -> np.ndarray:
        """P(mu_s <= x | mu_s > lower)."""
        x = np.asarray(x, dtype=float)
        return np.where(x <= self.lower, 0.0, 1.0 - self.sf(np.maximum(x, self.lower)))

    def sf(self, x: np.ndarray | float) -> np.ndarray:
        """P(mu_s > x | mu_s > lower)."""
        x = np.asarray(x, dtype=float)
        return np.where(x <= self.lower, 1.0, self._raw_sf(np.maximum(x, self.lower)) / self.mass)

    def __repr__(self) -> str:
        return f"TruncatedBelow({self.dist!r}, lower={self.lower!r})"


# The built-in distributions, by the name a config uses (``friction.static.name``).
BUILTINS: dict[str, type] = {"gaussian": Gaussian}
