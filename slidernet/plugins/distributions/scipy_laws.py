"""``scipy``: any continuous law of :mod:`scipy.stats` as a law of mu_s, by name and parameters."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike
from scipy import stats

from slidernet._validation import check_array, check_scalar
from slidernet.errors import param_error
from slidernet.plugins.distributions.law import Distribution


class ScipyStats(Distribution):
    """Any continuous law of :mod:`scipy.stats`, by name and parameters.

    The name is looked up as an attribute of ``scipy.stats`` and must be an
    ``rv_continuous`` instance (``"gamma"``, ``"lognorm"``, ``"genpareto"``,
    ...); nothing else is imported. If the law's support reaches mu_d or
    below, slidernet conditions it on mu_s > mu_d with :class:`TruncatedBelow`
    (rejection); if it starts above mu_d no truncation is needed. The
    extreme-value class is the law's own.

    Parameters
    ----------
    dist : str
        Name of the law in ``scipy.stats``.
    params : mapping of str to float, optional
        Its shape parameters and ``loc``, ``scale`` as scipy names them,
        e.g. ``{"a": 2, "loc": 0.5, "scale": 0.05}`` for ``gamma``.

    Examples
    --------
    >>> import numpy as np
    >>> d = ScipyStats("gamma", {"a": 2, "loc": 0.5, "scale": 0.05})
    >>> d.sample(np.random.default_rng(0), 3).shape
    (3,)
    >>> d.support()
    (0.5, inf)
    >>> ScipyStats("poisson", {"mu": 1})
    Traceback (most recent call last):
    ...
    slidernet.errors.ConfigError: The 'dist' parameter of scipy must be the name of a continuous \
distribution of scipy.stats (e.g. 'gamma'). Got 'poisson' instead.
    """

    name = "scipy"
    example_params: ClassVar[dict[str, Any]] = {"dist": "gamma", "params": {"a": 2.0, "loc": 0.45, "scale": 0.05}}
    _mu_d_param = "params"

    #: The unit of each parameter, for the configuration reference ("1": dimensionless).
    param_units: ClassVar[dict[str, str]] = {"dist": "—", "params": "1"}

    def __init__(self, dist: str, params: Mapping[str, float] | None = None) -> None:
        law = getattr(stats, dist, None) if isinstance(dist, str) and not dist.startswith("_") else None
        if not isinstance(law, stats.rv_continuous):
            raise param_error("dist", "scipy", "the name of a continuous distribution of scipy.stats "
                              "(e.g. 'gamma')", dist)
        params = {} if params is None else params
        if not isinstance(params, Mapping) or not all(isinstance(k, str) for k in params):
            raise param_error("params", "scipy", "a table of named parameters", params)
        for key, value in params.items():
            # Checked only: scipy is given the values as written, as before.
            check_scalar(value, f"params.{key}", "scipy")
        wanted = f"the parameters of scipy.stats.{dist} ({law.shapes + ', ' if law.shapes else ''}loc, scale)"
        try:
            frozen = law(**params)
            lo, hi = (float(v) for v in frozen.support())
        except TypeError as exc:
            raise param_error("params", "scipy", f"{wanted}: {exc}", dict(params)) from None
        if not (lo < hi):  # scipy reports invalid shape, loc or scale as a NaN support
            raise param_error("params", "scipy", f"valid values of {wanted}", dict(params))
        self.dist = dist
        self.params = dict(params)
        self.frozen = frozen
        self._support = (lo, hi)

    def _params(self) -> dict[str, Any]:
        return {"dist": self.dist, "params": self.params}

    def support(self) -> tuple[float, float]:
        """The law's support, from scipy."""
        return self._support

    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        """``size`` draws, shape ``(size,)``, with ``rng`` as scipy's random_state."""
        return np.asarray(self.frozen.rvs(size=size, random_state=rng), dtype=float)

    def cdf(self, x: ArrayLike) -> np.ndarray:
        """P(mu_s <= x)."""
        return np.asarray(self.frozen.cdf(x), dtype=float)

    def sf(self, x: ArrayLike) -> np.ndarray:
        """P(mu_s > x), as accurate in the tail as scipy's."""
        return np.asarray(self.frozen.sf(x), dtype=float)

    def ppf(self, u: ArrayLike) -> np.ndarray:
        """The x with P(mu_s <= x) = u."""
        return np.asarray(self.frozen.ppf(u), dtype=float)

    def isf(self, q: ArrayLike) -> np.ndarray:
        """The x with P(mu_s > x) = q."""
        return np.asarray(self.frozen.isf(q), dtype=float)

    def mean_max_above(self, m: ArrayLike, lower: float) -> np.ndarray:
        """By quadrature; inf where scipy says the law's mean is infinite, NaN where undefined."""
        mean = float(self.frozen.mean())
        if not math.isfinite(mean):
            return np.full(check_array(m, "m", "mean_max", ">= 1").shape, mean if mean == math.inf else math.nan)
        return super().mean_max_above(m, lower)
