"""Plugin registries: built-ins plus ``importlib.metadata`` entry points.

Two registries exist, one per entry-point group:

* ``slidernet.plugins.distributions`` -- distributions of the static threshold mu_s;
* ``slidernet.plugins.drivers`` -- temperature (thermal dilation theta) drivers.

A registry maps a name to a *factory*: ``factory(**params)`` returns the plugin
object. The built-ins are always there; third-party packages add names through
their entry points, which are looked up lazily (on the first lookup) and
cached. Names registered at run time with :func:`register_distribution` or
:func:`register_driver` take precedence over entry points.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from importlib.metadata import EntryPoint, entry_points
from typing import Any

from slidernet._validation import did_you_mean
from slidernet.errors import UnknownPluginError

Factory = Callable[..., Any]

#: The function that registers a name of each kind at run time, as the unknown-name error names it.
_REGISTER_FUNCTIONS = {"distribution": "slidernet.register_distribution", "driver": "slidernet.register_driver"}


class Registry:
    """A name -> factory mapping, backed by an entry-point group.

    Parameters
    ----------
    group : str
        The entry-point group searched for third-party plugins.
    kind : str
        Human-readable name of what is registered, used in error messages.
    builtins : dict of str to callable, or a callable that returns one
        The factories that ship with slidernet; a callable is called on the
        first lookup, so that importing slidernet imports no plugin module
        (nor scipy.stats, which some of them need).

    Examples
    --------
    >>> reg = Registry("slidernet.examples", "example", {"one": lambda: 1})
    >>> reg.get("one")()
    1
    >>> reg.get("two")  # doctest: +NORMALIZE_WHITESPACE
    Traceback (most recent call last):
    ...
    slidernet.errors.UnknownPluginError: Unknown example 'two'. Available: 'one'. To add one, install a
    package that declares it as an entry point of the group 'slidernet.examples', list the Python file or
    module that registers it under plugins = [...] in the configuration or with --plugin on the command
    line, or call Registry.register(name, factory) in Python.
    """

    def __init__(self, group: str, kind: str,
                 builtins: dict[str, Factory] | Callable[[], dict[str, Factory]]) -> None:
        self.group = group
        self.kind = kind
        self._builtin_source = builtins
        self._builtin_factories: dict[str, Factory] | None = None
        self._runtime: dict[str, Factory] = {}
        self._entry_points: dict[str, EntryPoint] | None = None
        self._loaded: dict[str, Factory] = {}
        self._errors: dict[str, str] = {}

    @property
    def _builtins(self) -> dict[str, Factory]:
        if self._builtin_factories is None:
            source = self._builtin_source
            self._builtin_factories = dict(source() if callable(source) else source)
        return self._builtin_factories

    def _discover(self) -> dict[str, EntryPoint]:
        if self._entry_points is None:
            self._entry_points = {ep.name: ep for ep in entry_points(group=self.group)}
        return self._entry_points

    def register(self, name: str, factory: Factory) -> None:
        """Register ``factory`` under ``name`` for this process."""
        if not isinstance(name, str) or not name:
            raise TypeError(f"A {self.kind} name must be a non-empty string. Got {name!r}.")
        if not callable(factory):
            raise TypeError(f"The factory of {self.kind} {name!r} must be callable.")
        self._runtime[name] = factory

    def names(self) -> list[str]:
        """Every available name: built-ins, entry points and run-time registrations."""
        return sorted(set(self._builtins) | set(self._discover()) | set(self._runtime))

    def get(self, name: str) -> Factory:
        """Return the factory registered as ``name``.

        Raises
        ------
        UnknownPluginError
            If no plugin has that name; the message lists the available ones and
            the ways to add one.
        """
        if name in self._runtime:
            return self._runtime[name]
        if name in self._builtins:
            return self._builtins[name]
        if name in self._loaded:
            return self._loaded[name]
        ep = self._discover().get(name)
        if ep is not None:
            try:
                factory = ep.load()
            except Exception as exc:  # a broken third-party package must not break the registry
                self._errors[name] = f"({ep.value}): {exc!r}"
                warnings.warn(
                    f"The {self.kind} plugin {name!r} ({ep.value}) failed to load: {exc!r}",
                    RuntimeWarning,
                    stacklevel=2,
                )
            else:
                self._loaded[name] = factory
                return factory
        raise self._unknown(name)

    def _unknown(self, name: str) -> UnknownPluginError:
        """The error for a name no plugin has: the names there are, and the ways to add one."""
        available = ", ".join(repr(n) for n in self.names())
        register = _REGISTER_FUNCTIONS.get(self.kind, "Registry.register")
        nearest = did_you_mean(name, self.names())
        return UnknownPluginError(
            f"Unknown {self.kind} {name!r}" + (f"; {nearest}" if nearest else ".")
            + f" Available: {available}. To add one, install a package that "
            f"declares it as an entry point of the group {self.group!r}, list the Python file or module that "
            f"registers it under plugins = [...] in the configuration or with --plugin on the command line, "
            f"or call {register}(name, factory) in Python."
        )

    def load_error(self, name: str) -> str | None:
        """Why the entry point ``name`` failed to load (its target and exception), or None."""
        return self._errors.get(name)

    def origin(self, name: str) -> str:
        """Where ``name`` comes from: ``"run time"``, ``"built-in"``, or the package of its entry point.

        >>> distributions.origin("gaussian")
        'built-in'
        """
        if name in self._runtime:
            return "run time"
        if name in self._builtins:
            return "built-in"
        ep = self._discover().get(name)
        if ep is None:
            raise self._unknown(name)
        dist = getattr(ep, "dist", None)
        return f"{dist.name} {dist.version}" if dist is not None else f"entry point {ep.value}"

    def create(self, name: str, **params: Any) -> Any:
        """Look up ``name`` and call its factory with ``params``."""
        return self.get(name)(**params)

    def clear_cache(self) -> None:
        """Forget discovered entry points (for tests and for newly installed packages)."""
        self._entry_points = None
        self._loaded.clear()
        self._errors.clear()


def _builtin_distributions() -> dict[str, Factory]:
    from slidernet.plugins.distributions import BUILTINS

    return BUILTINS


def _builtin_drivers() -> dict[str, Factory]:
    from slidernet.plugins.drivers import BUILTINS

    return BUILTINS


distributions = Registry("slidernet.distributions", "distribution", _builtin_distributions)
drivers = Registry("slidernet.drivers", "driver", _builtin_drivers)


def register_distribution(name: str, factory: Factory) -> None:
    """Register a distribution of mu_s under ``name``.

    ``factory(**params)`` must return an object with ``sample(rng, size)``
    (an ndarray of ``size`` floats) and ``cdf(x)``; ``sf(x)`` is optional and
    improves the accuracy of the extreme-value theory in the far tail.
    """
    distributions.register(name, factory)


def register_driver(name: str, factory: Factory) -> None:
    """Register a temperature driver under ``name``.

    ``factory(**params)`` must return an object with ``thetas(rng, steps)``,
    the ``steps + 1`` values of theta at t = 0, 1, ..., steps (in tau_th).
    """
    drivers.register(name, factory)
