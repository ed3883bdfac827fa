"""Distributions p(mu_s) of the static friction threshold.

A distribution plugin is any object with

* ``sample(rng, size) -> ndarray`` -- ``size`` independent draws, using only
  the ``numpy.random.Generator`` it is given;
* ``cdf(x) -> ndarray`` -- the cumulative distribution function;
* optionally ``sf(x)`` (the survival function, 1 - cdf, accurate in the
  tail), ``isf(q)`` (its inverse, used by :meth:`TruncatedBelow.mean_max`)
  and ``check_mu_d(mu_d)`` (raise :class:`~slidernet.errors.ConfigError`
  when the parameters make no sense for that mu_d).

A *law of mu_s* is a :class:`Distribution`: ``sample``, ``cdf``, ``sf``,
``ppf``, ``isf``, ``support`` and ``mean_max(m)``, the exact mean of the
largest of ``m`` draws of that law. The built-ins are Distributions, and so
is the law slidernet draws from.

The model requires p(mu_s) = 0 for mu_s <= mu_d (the paper, section II.A).
slidernet enforces this for every plugin with :class:`TruncatedBelow`, the
Distribution that ``load_config(...).distribution()`` returns and the
solver, the theory and the paper figures use: draws at or below mu_d are
rejected and redrawn, and the cdf is renormalised. For a law whose support
starts above mu_d the truncation changes nothing. The solver reads its
draws through a :class:`TruncatedStream`, which calls the plugin with a
fixed number of draws (:data:`RAW_CHUNK`) and keeps the accepted ones it has
not handed out yet, so that the values never depend on ``solver.batch``.

The built-ins (:data:`BUILTINS`, by the name a config uses) and the
extreme-value class of the maximum of many draws (what mu_max ages like).
The ``weibull`` law has no upper end, so its maximum is in the Gumbel
class; the Weibull class is that of laws bounded above (limit law: the
reversed Weibull):

===============  =========================================  =========================
name             law                                        class of the maximum
===============  =========================================  =========================
``gaussian``     Normal(mean, std)                          Gumbel
``uniform``      Uniform(low, high)                         Weibull (bounded above)
``constant``     every mu_s equals value                    none (a point mass)
``weibull``      loc + scale * Weibull(shape)               Gumbel (no upper end)
``lognormal``    loc + median * exp(sigma * Normal(0, 1))   Gumbel
``exponential``  loc + Exponential(scale)                   Gumbel
``pareto``       loc + scale * Pareto(alpha), x >= 1        Frechet
``empirical``    resampling of measured values (ECDF)       bounded (largest value)
``scipy``        any continuous ``scipy.stats`` law         depends on the law
===============  =========================================  =========================

``mean_max(m)`` is the same on every Distribution: the exact mean of the
largest of ``m`` draws of *that* law -- a built-in as its parameters give
it, a :class:`TruncatedBelow` conditioned on mu_s > mu_d. The truncated law
takes it from the built-in's ``mean_max_above(m, lower)``, the same mean
conditioned on mu_s > lower, in closed form where one exists (uniform,
exponential, pareto, empirical) and otherwise by :func:`mean_max_quadrature`.

One subject a module; each imports only the modules above it in this list,
and every name below is imported from the package itself, as before:

==================  ===========================================================
module              holds
==================  ===========================================================
``quadrature``      :func:`mean_max_quadrature` and :func:`mean_min_quadrature` (a tanh-sinh rule on the quantile)
``law``             :class:`Distribution`, :class:`TruncatedBelow`, :data:`MIN_MASS`
``stream``          :class:`TruncatedStream`, :data:`RAW_CHUNK`
``bounded``         ``uniform``, ``constant``
``unbounded``       ``gaussian``, ``weibull``, ``lognormal``, ``exponential``, ``pareto``
``empirical``       ``empirical``
``scipy_laws``      ``scipy``
==================  ===========================================================
"""

from __future__ import annotations

from slidernet.plugins.distributions.bounded import Constant, Uniform
from slidernet.plugins.distributions.empirical import Empirical
from slidernet.plugins.distributions.law import MIN_MASS, Distribution, TruncatedBelow
from slidernet.plugins.distributions.quadrature import mean_max_quadrature, mean_min_quadrature
from slidernet.plugins.distributions.scipy_laws import ScipyStats
from slidernet.plugins.distributions.stream import RAW_CHUNK, TruncatedStream
from slidernet.plugins.distributions.unbounded import Exponential, Gaussian, Lognormal, Pareto, Weibull

__all__ = [
    "BUILTINS",
    "MIN_MASS",
    "RAW_CHUNK",
    "Constant",
    "Distribution",
    "Empirical",
    "Exponential",
    "Gaussian",
    "Lognormal",
    "Pareto",
    "ScipyStats",
    "TruncatedBelow",
    "TruncatedStream",
    "Uniform",
    "Weibull",
    "mean_max_quadrature",
    "mean_min_quadrature",
]

# The built-in distributions, by the name a config uses (``friction.static.name``).
BUILTINS: dict[str, type] = {
    cls.name: cls
    for cls in (Gaussian, Uniform, Constant, Weibull, Lognormal, Exponential, Pareto, Empirical, ScipyStats)
}
