"""The law of mu_s: :class:`Distribution`, and :class:`TruncatedBelow`, the law slidernet draws from.

:class:`Distribution` is the interface of every built-in law (``sample``,
``cdf``, ``sf``, ``ppf``, ``isf``, ``support``, ``mean_max``).
:class:`TruncatedBelow` is any plugin's law conditioned on mu_s > mu_d
(the model needs p(mu_s) = 0 for mu_s <= mu_d), itself a Distribution.
The two share a module because each needs the other: a Distribution with
no closed form for the mean of its maximum integrates its law conditioned
on mu_s > lower, which is a TruncatedBelow.
"""

from __future__ import annotations

import abc
import math
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike

from slidernet._validation import checked_output
from slidernet.errors import ConfigError, param_error
from slidernet.plugins.distributions.quadrature import mean_max_quadrature

# The least probability a law may put above mu_d (check_mu_d): rejection
# sampling then costs at most 1000 draws per accepted threshold.
MIN_MASS = 1e-3


class Distribution(abc.ABC):
    """A law of mu_s: the built-ins, and the law slidernet draws from.

    One interface in the style of ``scipy.stats``: ``sample``, ``cdf``,
    ``sf``, ``ppf``, ``isf``, ``support`` and :meth:`mean_max`. The built-ins
    subclass it (each a law before truncation at mu_d), and so does
    :class:`TruncatedBelow`, the law conditioned on mu_s > mu_d that
    ``load_config(...).distribution()`` returns. A third-party plugin need
    not subclass it (``sample`` and ``cdf`` are enough): slidernet wraps it in
    a TruncatedBelow, which is a Distribution.

    A subclass defines the abstract methods; this class adds
    :meth:`check_mu_d`, :meth:`mean_max` and :meth:`mean_max_above` (by
    :func:`mean_max_quadrature`). A law with a closed form for the mean of
    the maximum overrides :meth:`mean_max_above` only, and :meth:`mean_max`
    follows. ``name`` is the registered name, ``_mu_d_param`` the parameter
    blamed when the law leaves too little mass above mu_d, and
    ``example_params`` (on the built-ins) a valid parameter set for
    mu_d = 0.5, used by :func:`slidernet.testing.check_distribution` and the
    contract tests.
    """

    name = "distribution"
    _mu_d_param = "loc"
    # Every built-in is conditioned on mu_s > mu_d by TruncatedBelow (rejection):
    # a law whose support starts above mu_d loses nothing.
    truncate_below_mu_d: ClassVar[bool] = True

    def compiled_law(self) -> tuple[int, float, float, float] | None:
        """``(code, a, b, c)`` of :mod:`slidernet.kernels.draws` if compiled code draws this law to the
        bit of :meth:`sample`, else None (the default: plugins keep the batched path)."""
        return None

    @abc.abstractmethod
    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        """``size`` independent draws of mu_s (dimensionless), using only ``rng``.

        Parameters
        ----------
        rng : numpy.random.Generator
            The stream to draw from.
        size : int
            Number of draws, >= 0.

        Returns
        -------
        numpy.ndarray
            float64, shape ``(size,)``.
        """

    @abc.abstractmethod
    def cdf(self, x: ArrayLike) -> np.ndarray:
        """P(mu_s <= x), elementwise; x dimensionless, any shape; result of the shape of ``x``."""

    @abc.abstractmethod
    def sf(self, x: ArrayLike) -> np.ndarray:
        """P(mu_s > x) = 1 - cdf(x), accurate in the upper tail; shape of ``x``."""

    @abc.abstractmethod
    def ppf(self, u: ArrayLike) -> np.ndarray:
        """The quantile: the x with P(mu_s <= x) = u, u in [0, 1]; shape of ``u``."""

    @abc.abstractmethod
    def isf(self, q: ArrayLike) -> np.ndarray:
        """The x with P(mu_s > x) = q, q in [0, 1], accurate for tiny q; shape of ``q``."""

    @abc.abstractmethod
    def support(self) -> tuple[float, float]:
        """Lower and upper end of the support (may be infinite)."""

    def _params(self) -> dict[str, Any]:
        return {}

    def check_mu_d(self, mu_d: float) -> None:
        """Refuse a law with less than :data:`MIN_MASS` of probability above ``mu_d``.

        Raises
        ------
        ConfigError
            If the support lies at or below mu_d, or P(mu_s > mu_d) < MIN_MASS;
            the message names the parameter to change.
        """
        mu_d = float(mu_d)
        param = self._mu_d_param
        got = self._params().get(param)
        if self.support()[1] <= mu_d:
            raise param_error(param, self.name, f"such that the support reaches above mu_d = {mu_d!r} "
                              f"(it ends at {self.support()[1]!r})", got)
        mass = float(self.sf(mu_d))
        if not mass >= MIN_MASS:
            raise param_error(param, self.name, f"such that P(mu_s > mu_d = {mu_d!r}) >= {MIN_MASS!r} "
                              f"(it is {mass:.3g})", got)

    def _truncated(self, lower: float) -> Distribution:
        """This law conditioned on mu_s > lower (itself where that changes nothing)."""
        if float(lower) <= self.support()[0]:
            return self
        return TruncatedBelow(self, float(lower), self.name, min_mass=np.finfo(float).tiny)

    def mean_max(self, m: ArrayLike) -> np.ndarray:
        """Exact mean of the largest of ``m`` i.i.d. draws of this law.

        On the law slidernet draws from (``load_config(...).distribution()``,
        a :class:`TruncatedBelow`) this is mu_max of the two-slider system
        after ``n = m - 2`` rearrangements, on average.

        Parameters
        ----------
        m : float or array_like
            Number(s) of draws, >= 1 (need not be integers), any shape.

        Returns
        -------
        numpy.ndarray
            E[max], dimensionless like mu_s, shape of ``m``.

        Raises
        ------
        ConfigError
            If an ``m`` is not finite or is below 1.
        """
        # Conditioning on mu_s > -inf leaves the law as it is: one code path
        # (closed form or quadrature) per law.
        return self.mean_max_above(m, -math.inf)

    def mean_max_above(self, m: ArrayLike, lower: float) -> np.ndarray:
        """Exact mean of the largest of ``m`` i.i.d. draws, conditioned on mu_s > ``lower``.

        This is what :meth:`TruncatedBelow.mean_max` asks of a built-in, with
        ``lower = mu_d``. A ``lower`` at or below the support changes nothing.
        Here by :func:`mean_max_quadrature`; some subclasses have a closed form.

        Parameters
        ----------
        m : float or array_like
            Number(s) of draws, >= 1, any shape.
        lower : float
            Truncation point (mu_d), dimensionless; ``-inf`` for none.

        Returns
        -------
        numpy.ndarray
            E[max | mu_s > lower], dimensionless like mu_s, shape of ``m``.
        """
        return mean_max_quadrature(self._truncated(lower), m)

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self._params().items())
        return f"{type(self).__name__}({args})"


# ---------------------------------------------------------------------------
# truncation below mu_d


class TruncatedBelow(Distribution):
    """A law of mu_s conditioned on mu_s > ``lower`` (normally mu_d), or checked to be.

    This is the law slidernet draws from: ``load_config(...).distribution()``
    returns one, the solver draws its thresholds from it (through a
    :class:`TruncatedStream`), and :mod:`slidernet.analysis.theory` and the
    paper figures compare against it. It is a :class:`Distribution` like the
    built-ins, whatever the plugin it wraps: ``sample``, ``cdf``, ``sf``,
    ``ppf``, ``isf``, ``support`` and ``mean_max(m)`` all describe the
    conditioned law.

    The model needs p(mu_s) = 0 for mu_s <= mu_d. A plugin that declares
    ``truncate_below_mu_d = True`` (every built-in does) is conditioned on
    mu_s > lower: sampling is by rejection in batches, so a plugin written in
    plain numpy stays fast, and one whose mass above ``lower`` is below
    ``min_mass`` is refused, since rejection would then never end. Any other
    plugin must put no mass at or below ``lower``: its ``sf(lower)`` must be
    1 (checked here, before any work), and a draw at or below ``lower`` stops
    the run with a :class:`~slidernet.errors.PluginError` naming the plugin.

    Parameters
    ----------
    dist : Distribution or object
        The plugin distribution: a :class:`Distribution`, or any object with
        ``sample`` and ``cdf`` (``sf``, ``isf`` and ``support`` optional).
    lower : float
        The truncation point (mu_d); draws must be strictly above it.
    name : str
        The plugin's registered name, used in error messages.
    min_mass : float
        Smallest acceptable P(mu_s > lower).

    Examples
    --------
    >>> import numpy as np
    >>> from slidernet.plugins.distributions import Gaussian, Uniform
    >>> d = TruncatedBelow(Gaussian(0.6, 0.1), lower=0.5, name="gaussian")
    >>> bool((d.sample(np.random.default_rng(1), 1000) > 0.5).all())
    True
    >>> round(float(d.cdf(0.5)), 12)
    0.0
    >>> u = TruncatedBelow(Uniform(0.4, 0.6), lower=0.5, name="uniform")
    >>> isinstance(u, Distribution), u.support()
    (True, (0.5, 0.6))
    >>> round(float(u.mean_max(3)), 12)  # the max of 3 draws of Uniform(0.5, 0.6)
    0.575
    """

    def __init__(self, dist: object, lower: float, name: str, min_mass: float = 1e-6) -> None:
        self.dist = dist
        self.lower = float(lower)
        self.name = name
        mass = float(self._raw_sf(self.lower))
        self.truncate = bool(getattr(dist, "truncate_below_mu_d", False))
        if not self.truncate and not mass >= 1.0 - 1e-12:
            raise ConfigError(
                f"The distribution {name!r} puts probability {1.0 - mass!r} at or below mu_d = {lower!r}, "
                "but p(mu_s) must vanish for mu_s <= mu_d. Move its support above mu_d, or declare "
                "'truncate_below_mu_d = True' on its factory to have slidernet condition it on mu_s > mu_d."
            )
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

    def support(self) -> tuple[float, float]:
        """(max(lower, plugin's lower end), plugin's upper end); inf for an end the plugin does not give."""
        plugin = getattr(self.dist, "support", None)
        lo, hi = plugin() if plugin is not None else (-math.inf, math.inf)
        return max(self.lower, float(lo)), float(hi)

    def check_mu_d(self, mu_d: float) -> None:
        """Refuse a law with less than :data:`MIN_MASS` of probability above ``mu_d``.

        The plugin's own ``check_mu_d`` is asked first, since its message
        names the parameter to change; then the conditioned law's mass.

        Raises
        ------
        ConfigError
            If the plugin refuses ``mu_d``, or P(mu_s > mu_d | mu_s > lower) < MIN_MASS.
        """
        check = getattr(self.dist, "check_mu_d", None)
        if check is not None:
            check(mu_d)
        mass = float(self.sf(float(mu_d)))
        if not mass >= MIN_MASS:
            raise ConfigError(
                f"The distribution {self.name!r}, conditioned on mu_s > {self.lower!r}, puts probability "
                f"{mass!r} above mu_d = {mu_d!r}; at least {MIN_MASS!r} is needed."
            )

    def _checked(self, draws: object, size: int) -> np.ndarray:
        return checked_output(draws, (size,), "distribution", self.name, f"sample(rng, {size})")

    def _refuse_below(self, draws: np.ndarray, bad: np.ndarray, size: int) -> None:
        """Stop the run if a plugin that does not ask for truncation drew at or below ``lower``."""
        if bad.size and not self.truncate:
            from slidernet.errors import PluginError

            raise PluginError(
                f"The distribution {self.name!r} returned {bad.size} values at or below mu_d = {self.lower!r} "
                f"from sample(rng, {size}) (the first: {float(draws[bad[0]])!r}), although its cdf puts no "
                "mass there; p(mu_s) must vanish for mu_s <= mu_d."
            )

    def compiled_law(self) -> tuple[int, float, float, float] | None:
        """The law's compiled draws, for a built-in that has them (a plugin's ``sample`` is always called)."""
        law = getattr(self.dist, "compiled_law", None)
        return law() if self.truncate and isinstance(self.dist, Distribution) and law is not None else None

    def accepted(self, rng: np.random.Generator, size: int) -> np.ndarray:
        """The draws strictly above ``lower`` among ``size`` draws of the plugin, in their order.

        One call of the plugin's ``sample(rng, size)``; the draws at or below
        ``lower`` are dropped (rejection), so the result has ``size`` values
        or fewer. This is the building block of :class:`TruncatedStream`.

        Parameters
        ----------
        rng : numpy.random.Generator
            The stream to draw from.
        size : int
            Number of raw draws asked of the plugin.

        Returns
        -------
        numpy.ndarray
            The accepted draws (dimensionless, like mu_s), float64, shape ``(k,)`` with ``k <= size``.

        Raises
        ------
        PluginError
            If the plugin returns the wrong shape, NaN or inf, or (for a plugin
            that does not declare ``truncate_below_mu_d``) a value at or below ``lower``.
        """
        draws = self._checked(self.dist.sample(rng, size), size)
        keep = draws > self.lower
        if keep.all():
            return draws
        self._refuse_below(draws, np.flatnonzero(~keep), size)
        return draws[keep]

    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        """``size`` draws strictly above ``lower``, shape ``(size,)``.

        Rejected draws are replaced from further calls of the plugin, so the
        values depend on ``size``: ``sample(rng, 2)`` then ``sample(rng, 3)``
        need not be the first five values of ``sample(rng, 5)`` when draws are
        rejected. The solver reads its thresholds through a
        :class:`TruncatedStream` instead, whose values never depend on how
        many are asked for at a time.
        """
        out = self._checked(self.dist.sample(rng, size), size)
        bad = np.flatnonzero(out <= self.lower)
        self._refuse_below(out, bad, size)
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

    def isf(self, q: ArrayLike) -> np.ndarray:
        """The x > lower with P(mu_s > x | mu_s > lower) = q, for q in [0, 1].

        Uses the plugin's own ``isf`` where it has one, and a bisection on
        ``sf`` otherwise.
        """
        q = np.asarray(q, dtype=float)
        isf = getattr(self.dist, "isf", None)
        if isf is not None:
            return np.maximum(np.asarray(isf(q * self.mass), dtype=float), self.lower)
        return self._bisect_isf(q)

    def ppf(self, u: ArrayLike) -> np.ndarray:
        """The x with P(mu_s <= x | mu_s > lower) = u, for u in [0, 1]."""
        return self.isf(1.0 - np.asarray(u, dtype=float))

    def _bisect_isf(self, q: np.ndarray) -> np.ndarray:
        """isf by vectorised bisection on sf, for plugins without isf."""
        lo = np.full(q.shape, self.lower)
        width = max(abs(self.lower), 1.0) * 1e-3
        target = float(q.min()) if q.size else 1.0
        # Double until sf(hi) <= every target (or the doubling runs out).
        for _ in range(1100):
            if float(self.sf(self.lower + width)) <= target or not math.isfinite(self.lower + 2 * width):
                break
            width *= 2.0
        hi = np.full(q.shape, self.lower + width)
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            moving = (mid > lo) & (mid < hi)
            if not moving.any():
                break
            above = self.sf(mid) > q  # mid is below the quantile
            lo = np.where(above & moving, mid, lo)
            hi = np.where(~above & moving, mid, hi)
        return hi

    def mean_max(self, m: ArrayLike) -> np.ndarray:
        """Exact mean of the largest of ``m`` i.i.d. draws of this (truncated) law.

        This is the law slidernet draws from: after ``n`` rearrangements of
        the two-slider system, mu_max is the largest of ``m = n + 2`` draws.
        A built-in computes it itself (``dist.mean_max_above(m, lower)``, a
        closed form where there is one); any other plugin goes through
        :func:`mean_max_quadrature` on this object. Where the plugin's
        support starts above ``lower`` it equals the plugin's ``mean_max(m)``.

        Parameters
        ----------
        m : float or array_like
            Number(s) of draws, >= 1 (need not be integers), any shape.

        Returns
        -------
        numpy.ndarray
            E[max | mu_s > lower], dimensionless like mu_s, shape of ``m``.
        """
        return self.mean_max_above(m, self.lower)

    def mean_max_above(self, m: ArrayLike, lower: float) -> np.ndarray:
        """Exact mean of the largest of ``m`` draws of this law, conditioned further on mu_s > ``lower``.

        Conditioning on mu_s > a and then on mu_s > b is conditioning on
        mu_s > max(a, b); a ``lower`` at or below :attr:`lower` changes nothing.
        See :meth:`Distribution.mean_max_above`.
        """
        if isinstance(self.dist, Distribution):
            return self.dist.mean_max_above(m, max(self.lower, float(lower)))
        return super().mean_max_above(m, lower)

    def __repr__(self) -> str:
        return f"TruncatedBelow({self.dist!r}, lower={self.lower!r})"
