"""Conformance checks for plugin authors: run them in your own tests.

:func:`check_distribution` and :func:`check_driver` call a plugin the way
slidernet does and check the contract of ``plugins/README.md``: shapes,
dtypes, finite values, use of the given ``numpy.random.Generator`` only
(never the global RNGs), the same draws for the same seed, a cdf that is a
cdf and agrees with the draws, and ``sf = 1 - cdf``. A failure raises
:class:`PluginContractError` (an ``AssertionError``, so pytest reports it as
a failed test) with a message naming the plugin and the broken rule.

Plugins can advertise parameters that make a good example through two
optional attributes of their factory: ``example_params`` (a dict of keyword
arguments) and, for distributions, ``example_mu_d`` (a mu_d for which the
example makes sense; 0.5 when absent). slidernet's own contract test runs
every registered plugin with them. The two built-ins that read a file, the
``empirical`` distribution and the ``series`` driver, take their example from
the small files shipped in ``slidernet/plugins/data`` (see :func:`example_of`).

Examples
--------
>>> from slidernet.plugins.distributions import Gaussian
>>> from slidernet.plugins.drivers import GaussianSteps
>>> check_distribution(Gaussian, {"mean": 0.6, "std": 0.01}, mu_d=0.5)
Gaussian(mean=0.6, std=0.01)
>>> check_driver(GaussianSteps(sigma_theta=1e-6))
GaussianSteps(sigma_theta=1e-06)
"""

from __future__ import annotations

import inspect
import math
import random
from collections.abc import Callable, Mapping
from importlib.resources import files
from typing import Any

import numpy as np

from slidernet.errors import SlidernetError

__all__ = [
    "DEFAULT_MU_D",
    "PluginContractError",
    "check_distribution",
    "check_driver",
    "example_file",
    "example_of",
]

#: The mu_d used when a distribution declares no ``example_mu_d`` (the paper's value).
DEFAULT_MU_D = 0.5


class PluginContractError(SlidernetError, AssertionError):
    """A plugin breaks the contract of ``plugins/README.md``."""


def example_file(name: str) -> str:
    """The path of an example data file shipped in ``slidernet/plugins/data`` (see its README.md).

    >>> from pathlib import Path
    >>> Path(example_file("mu_s_example.txt")).is_file()
    True
    """
    return str(files("slidernet.plugins").joinpath("data", name))


def _file_examples() -> list[tuple[Any, dict[str, Any]]]:
    """Examples of the built-ins that read a file, which cannot declare a path of their own.

    The path depends on where slidernet is installed, so it is looked up when asked for.
    """
    from slidernet.plugins.distributions import Empirical
    from slidernet.plugins.drivers import Series

    return [
        (Empirical, {"path": example_file("mu_s_example.txt")}),
        # kappa of steel (1/K) about T0 = 15 degC, one sample (an hour) per tau_th.
        (Series, {"path": example_file("temperature_example.csv"), "kappa": 1.2e-5, "T0": 15.0, "tau_th": 1.0}),
    ]


def example_of(factory: Callable[..., Any]) -> dict[str, Any] | None:
    """The ``example_params`` a factory advertises, or None.

    The built-ins ``empirical`` and ``series`` read a file: their example
    points at the files shipped in ``slidernet/plugins/data``.

    >>> class Law:
    ...     example_params = {"mean": 0.6}
    >>> example_of(Law)
    {'mean': 0.6}
    >>> example_of(print) is None
    True
    >>> from slidernet.plugins.drivers import Series
    >>> sorted(example_of(Series))
    ['T0', 'kappa', 'path', 'tau_th']
    """
    params = getattr(factory, "example_params", None)
    if params is None:
        # Identity, not a dict lookup: a factory need not be hashable.
        return next((dict(p) for cls, p in _file_examples() if factory is cls), None)
    if not isinstance(params, Mapping):
        raise PluginContractError(f"{_label(factory)}: 'example_params' must be a dict of keyword arguments, "
                                  f"not {type(params).__name__}.")
    return dict(params)


def _label(obj: object, name: str | None = None) -> str:
    if name:
        return repr(name)
    target = obj if isinstance(obj, type) or inspect.isroutine(obj) else type(obj)
    return f"{getattr(target, '__module__', '?')}.{getattr(target, '__qualname__', repr(target))}"


def _build(factory_or_obj: Any, params: Mapping[str, Any] | None, methods: tuple[str, ...],
           name: str | None) -> tuple[Any, str]:
    """The plugin object: ``factory_or_obj`` itself, or what its factory returns for ``params``."""
    if all(hasattr(factory_or_obj, m) for m in methods) and not isinstance(factory_or_obj, type):
        if params:
            raise TypeError("params are for a factory; an already built plugin object was given")
        return factory_or_obj, _label(factory_or_obj, name)
    label = _label(factory_or_obj, name)
    if not callable(factory_or_obj):
        raise PluginContractError(f"{label} is neither a factory nor an object with {', '.join(methods)}.")
    if params is None:
        params = example_of(factory_or_obj) or {}
    obj = factory_or_obj(**dict(params))
    for m in methods:
        if not callable(getattr(obj, m, None)):
            raise PluginContractError(f"{label}: the object built by the factory has no method {m}().")
    return obj, label


class _GlobalRNGGuard:
    """Fails if numpy's legacy global RNG or Python's ``random`` changed inside the block."""

    def __init__(self, label: str, call: str) -> None:
        self.label, self.call = label, call

    def __enter__(self) -> _GlobalRNGGuard:
        self.np_state = np.random.get_state()  # noqa: NPY002 - reading the legacy global state is the point
        self.py_state = random.getstate()
        return self

    def __exit__(self, exc_type: object, *rest: object) -> None:
        if exc_type is not None:
            return
        after = np.random.get_state()  # noqa: NPY002 - ('MT19937', keys, pos, has_gauss, cached_gaussian)
        before = self.np_state
        if not (np.array_equal(after[1], before[1]) and after[2:] == before[2:]):
            raise PluginContractError(
                f"{self.label}: {self.call} used numpy's global RNG (np.random.*); use only the "
                f"Generator it is given."
            )
        if random.getstate() != self.py_state:
            raise PluginContractError(
                f"{self.label}: {self.call} used Python's global 'random' module; use only the "
                f"Generator it is given."
            )


def _as_values(out: object, shape: tuple[int, ...], label: str, call: str) -> np.ndarray:
    if not isinstance(out, np.ndarray):
        raise PluginContractError(f"{label}: {call} returned {type(out).__name__}, not a numpy array.")
    if out.shape != shape:
        raise PluginContractError(f"{label}: {call} returned shape {out.shape}; expected {shape}.")
    if not np.issubdtype(out.dtype, np.floating):
        raise PluginContractError(f"{label}: {call} returned dtype {out.dtype}; expected floats.")
    values = out.astype(np.float64)
    bad = ~np.isfinite(values)
    if bad.any():
        raise PluginContractError(
            f"{label}: {call} returned {int(bad.sum())} NaN or inf values (first at index "
            f"{int(np.flatnonzero(bad)[0])}); every value must be finite."
        )
    return values


def _same_draws(make: Callable[[np.random.Generator], np.ndarray], seed: int, label: str, call: str) -> None:
    a = make(np.random.default_rng(seed))
    b = make(np.random.default_rng(seed))
    if not np.array_equal(a, b):
        raise PluginContractError(
            f"{label}: {call} gave different values for two Generators of the same seed {seed}; "
            f"draw only from the Generator it is given (no hidden RNG or state)."
        )


def check_distribution(
    factory_or_obj: Any,
    params: Mapping[str, Any] | None = None,
    mu_d: float | None = None,
    *,
    name: str | None = None,
    size: int = 4000,
    seed: int = 20100510,
    alpha: float = 1e-9,
) -> Any:
    """Check that a distribution of mu_s follows slidernet's plugin contract.

    Parameters
    ----------
    factory_or_obj : callable or object
        A factory (a class, or the callable of an entry point), called as
        ``factory(**params)``, or an already built object with ``sample`` and ``cdf``.
    params : dict, optional
        The factory's keyword arguments; default: its ``example_params`` attribute, or none.
    mu_d : float, optional
        The dynamic coefficient the plugin is used with. When given, ``check_mu_d``
        (if any) must accept it and slidernet's truncation below mu_d must work:
        enough mass above mu_d (at least 1e-6) and truncated draws > mu_d.
    name : str, optional
        The plugin's registered name, for messages.
    size : int
        Number of draws for the statistical checks.
    seed : int
        Seed of the Generators (the checks are deterministic).
    alpha : float
        Probability that a correct plugin fails the draws-versus-cdf check
        (Dvoretzky-Kiefer-Wolfowitz bound; valid for continuous and discrete laws).

    Returns
    -------
    object
        The plugin object that was checked.

    Raises
    ------
    PluginContractError
        If any rule is broken; the message names the plugin and the rule.

    Examples
    --------
    >>> import numpy as np
    >>> class Uniform:
    ...     def __init__(self, low=0.55, high=0.65):
    ...         self.low, self.high = low, high
    ...     def sample(self, rng, size):
    ...         return rng.uniform(self.low, self.high, size)
    ...     def cdf(self, x):
    ...         return np.clip((np.asarray(x, float) - self.low) / (self.high - self.low), 0, 1)
    >>> d = check_distribution(Uniform, {"low": 0.5, "high": 0.7}, mu_d=0.5)
    >>> class Legacy(Uniform):
    ...     def sample(self, rng, size):
    ...         return np.random.uniform(self.low, self.high, size)
    >>> check_distribution(Legacy, name="legacy")
    Traceback (most recent call last):
    ...
    slidernet.plugins.contract.PluginContractError: 'legacy': sample(rng, 1) used numpy's global RNG \
(np.random.*); use only the Generator it is given.
    """
    dist, label = _build(factory_or_obj, params, ("sample", "cdf"), name)

    # Shapes, dtypes, finiteness, and nothing but the given Generator.
    for n in (1, 7, size):
        call = f"sample(rng, {n})"
        with _GlobalRNGGuard(label, call):
            _as_values(dist.sample(np.random.default_rng(seed), n), (n,), label, call)
    draws_of = lambda rng: _as_values(dist.sample(rng, size), (size,), label, f"sample(rng, {size})")  # noqa: E731
    _same_draws(draws_of, seed, label, f"sample(rng, {size})")
    draws = np.sort(draws_of(np.random.default_rng(seed + 1)))

    # The cdf: vectorised, in [0, 1], non-decreasing, and in agreement with the draws.
    lo, hi = float(draws[0]), float(draws[-1])
    pad = max(hi - lo, abs(hi), 1e-12)
    grid = np.unique(np.concatenate([np.linspace(lo - pad, hi + pad, 201), draws]))
    with _GlobalRNGGuard(label, "cdf(x)"):
        cdf = np.asarray(dist.cdf(grid), dtype=float)
        cdf = _as_values(cdf, grid.shape, label, f"cdf(x) on {grid.size} points")
    if cdf.min() < 0.0 or cdf.max() > 1.0:
        raise PluginContractError(
            f"{label}: cdf(x) left [0, 1] (min {float(cdf.min())!r}, max {float(cdf.max())!r})."
        )
    drops = np.flatnonzero(np.diff(cdf) < -1e-12)
    if drops.size:
        i = int(drops[0])
        raise PluginContractError(
            f"{label}: cdf(x) decreases, from {float(cdf[i])!r} at x = {float(grid[i])!r} to "
            f"{float(cdf[i + 1])!r} at x = {float(grid[i + 1])!r}."
        )
    scalar = np.asarray(dist.cdf(float(grid[len(grid) // 2])), dtype=float)
    if scalar.size != 1 or not math.isclose(float(scalar.reshape(())), cdf[len(grid) // 2], rel_tol=1e-9,
                                            abs_tol=1e-12):
        raise PluginContractError(f"{label}: cdf(x) of a scalar disagrees with cdf of an array.")
    # Empirical cdf at the draws (right-continuous, so exact for atoms too).
    at = np.flatnonzero(np.isin(grid, draws))
    ecdf = np.searchsorted(draws, grid[at], side="right") / size
    gap = np.abs(ecdf - cdf[at])
    eps = math.sqrt(math.log(2.0 / alpha) / (2.0 * size))
    if gap.max() > eps:
        i = int(np.argmax(gap))
        raise PluginContractError(
            f"{label}: the draws do not follow cdf(x): at x = {float(grid[at][i])!r} the fraction of "
            f"draws <= x is {float(ecdf[i])!r} but cdf(x) = {float(cdf[at][i])!r} (allowed gap {eps:.3g} "
            f"for {size} draws)."
        )

    # The optional survival function: sf = 1 - cdf.
    sf_fn = getattr(dist, "sf", None)
    if sf_fn is not None:
        with _GlobalRNGGuard(label, "sf(x)"):
            sf = np.asarray(sf_fn(grid), dtype=float)
            sf = _as_values(sf, grid.shape, label, f"sf(x) on {grid.size} points")
        worst = np.abs(sf - (1.0 - cdf))
        if worst.max() > 1e-9:
            i = int(np.argmax(worst))
            raise PluginContractError(
                f"{label}: sf(x) is not 1 - cdf(x): at x = {float(grid[i])!r}, sf = {float(sf[i])!r} and "
                f"1 - cdf = {float(1.0 - cdf[i])!r}."
            )

    if mu_d is not None:
        _check_truncation(dist, float(mu_d), label, name, seed, size)
    return dist


def _check_truncation(dist: Any, mu_d: float, label: str, name: str | None, seed: int, size: int) -> None:
    from slidernet.errors import ConfigError, PluginError
    from slidernet.plugins.distributions import TruncatedBelow

    check = getattr(dist, "check_mu_d", None)
    if check is not None:
        try:
            check(mu_d)
        except ConfigError as exc:
            raise PluginContractError(f"{label}: check_mu_d({mu_d!r}) refused these parameters: {exc}") from None
    try:
        trunc = TruncatedBelow(dist, mu_d, name or label)
    except ConfigError as exc:
        raise PluginContractError(f"{label}: cannot be truncated below mu_d = {mu_d!r}: {exc}") from None
    with _GlobalRNGGuard(label, "sample(rng, n) truncated below mu_d"):
        try:
            kept = trunc.sample(np.random.default_rng(seed), size)
        except PluginError as exc:
            raise PluginContractError(f"{label}: {exc}") from None
    if not (kept > mu_d).all():  # pragma: no cover - TruncatedBelow guarantees it
        raise PluginContractError(f"{label}: truncated draws at or below mu_d = {mu_d!r}.")


def check_driver(
    factory_or_obj: Any,
    params: Mapping[str, Any] | None = None,
    *,
    name: str | None = None,
    steps: tuple[int, ...] = (1, 2, 100),
    seed: int = 20100510,
) -> Any:
    """Check that a temperature driver follows slidernet's plugin contract.

    ``thetas(rng, steps)`` must return a numpy array of the ``steps + 1`` finite
    values of theta at t = 0 ... steps (in tau_th), drawn only from the given
    Generator, the same for two Generators of the same seed.

    Parameters
    ----------
    factory_or_obj : callable or object
        A factory called as ``factory(**params)``, or an object with ``thetas``.
    params : dict, optional
        The factory's keyword arguments; default: its ``example_params`` attribute, or none.
    name : str, optional
        The plugin's registered name, for messages.
    steps : tuple of int
        The numbers of steps tried.
    seed : int
        Seed of the Generators.

    Returns
    -------
    object
        The driver object that was checked.

    Raises
    ------
    PluginContractError
        If any rule is broken; the message names the driver and the rule.

    Examples
    --------
    >>> import numpy as np
    >>> class Off:
    ...     def thetas(self, rng, steps):
    ...         return np.zeros(steps)
    >>> check_driver(Off(), name="off")
    Traceback (most recent call last):
    ...
    slidernet.plugins.contract.PluginContractError: 'off': thetas(rng, 1) returned shape (1,); expected (2,).
    """
    driver, label = _build(factory_or_obj, params, ("thetas",), name)
    for n in steps:
        call = f"thetas(rng, {n})"
        make = lambda rng, n=n, call=call: _as_values(driver.thetas(rng, n), (n + 1,), label, call)  # noqa: E731
        with _GlobalRNGGuard(label, call):
            make(np.random.default_rng(seed))
        _same_draws(make, seed, label, call)
    return driver
