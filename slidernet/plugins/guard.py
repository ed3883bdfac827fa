"""Calls into a plugin's own code: what it raises is the plugin's error, said in one line that names it.

slidernet calls a plugin at two places only: its factory, once, when the
configuration is loaded (:func:`build_plugin`), and the methods of the object
the factory returns, for as long as the run lasts (``sample``, ``cdf``,
``sf``, ``thetas``, ``check_mu_d``, ...). :func:`build_plugin` wraps both,
so that the rule holds for every call, in the main process and in every
worker:

- an exception of slidernet's own (:class:`~slidernet.errors.ConfigError`
  from ``check_mu_d``, a :class:`~slidernet.errors.PluginError`) passes as
  it is;
- any other exception, and ``SystemExit`` (a plugin may not end the
  process: a worker's exit would leave the run to guess why), becomes a
  :class:`~slidernet.errors.PluginError` naming the plugin, where it comes
  from, the call, the exception's type and message and the plugin's own
  line: a one-line error of the command (exit 2), never "a bug of slidernet";
- ``KeyboardInterrupt`` passes: the run stops as on Ctrl-C.

The built-ins are slidernet's own code: an error of theirs is a bug of
slidernet, and they are returned unwrapped.

Examples
--------
>>> class Broken:
...     def thetas(self, rng, steps):
...         return 1 / 0
>>> driver = guarded(Broken(), "driver", "broken", "run time")
>>> driver.thetas(None, 3)
Traceback (most recent call last):
...
slidernet.errors.PluginError: The driver 'broken' (run time) failed in thetas(): ZeroDivisionError: \
division by zero (line 3 of <doctest slidernet.plugins.guard[0]>).
>>> isinstance(driver, Broken)  # the plugin's class, for code that asks
True
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from slidernet.errors import PluginError, SlidernetError
from slidernet.plugins.loader import exception_line
from slidernet.plugins.registry import Registry


def source_of(factory: Callable[..., Any]) -> Path | None:
    """The file that defines ``factory`` (a class or a function), or None if Python cannot tell."""
    target = factory if inspect.isclass(factory) or inspect.isroutine(factory) else type(factory)
    try:
        name = inspect.getsourcefile(target)
    except (TypeError, OSError):
        return None
    return Path(name).resolve() if name else None


def origin_of(reg: Registry, name: str, factory: Callable[..., Any]) -> str:
    """Where the plugin ``name`` comes from, for a message: its file, or the package of its entry point."""
    origin = reg.origin(name)
    if origin != "run time":
        return origin
    source = source_of(factory)
    return str(source) if source is not None else origin


def build_plugin(reg: Registry, name: str, factory: Callable[..., Any], params: Mapping[str, Any]) -> Any:
    """``factory(**params)``, guarded (see the module's docstring); a built-in's object as it is.

    Raises
    ------
    PluginError
        If the factory raises anything but slidernet's own errors or KeyboardInterrupt.
    """
    if reg.origin(name) == "built-in":
        return factory(**params)
    label = f"The {reg.kind} {name!r} ({origin_of(reg, name, factory)})"
    source = source_of(factory)
    args = ", ".join(f"{k}={v!r}" for k, v in params.items())
    plugin = _call(label, source, f"its factory, {getattr(factory, '__name__', 'factory')}({args})",
                   factory, **params)
    return guarded(plugin, reg.kind, name, label=label, source=source)


def guarded(plugin: Any, kind: str, name: str, origin: str = "run time", *, label: str | None = None,
            source: Path | None = None) -> Any:
    """``plugin``, whose every method call raises its errors as :class:`~slidernet.errors.PluginError`."""
    return _Guarded(plugin, label or f"The {kind} {name!r} ({origin})",
                    source if source is not None else source_of(type(plugin)))


def _call(label: str, source: Path | None, call: str, fn: Callable[..., Any], *args: Any,
          passing: tuple[type[BaseException], ...] = (SlidernetError,), **kwargs: Any) -> Any:
    """``fn(*args, **kwargs)``, a plugin's code: its errors as PluginError (module docstring), but ``passing``."""
    try:
        return fn(*args, **kwargs)
    except passing:
        raise
    except SystemExit as exc:
        raise PluginError(f"{label} called sys.exit({exc.code!r}) in {call}: a plugin may not end the process; "
                          "raise an exception instead.") from None
    except Exception as exc:
        # The plugin's frames only: the line is the plugin's, never this function's.
        tb = exc.__traceback__.tb_next if exc.__traceback__ is not None else None
        raise PluginError(f"{label} failed in {call}: {exception_line(exc.with_traceback(tb), source)}") from exc


class _Guarded:
    """A plugin object whose methods are called through :func:`_call`; anything else is the plugin's own.

    ``isinstance`` sees the plugin's class (``__class__``), so that code
    which asks (a :class:`~slidernet.plugins.distributions.Distribution`
    subclass has compiled draws) treats the plugin as it is.
    """

    __slots__ = ("_label", "_plugin", "_source")

    def __init__(self, plugin: Any, label: str, source: Path | None) -> None:
        self._plugin = plugin
        self._label = label
        self._source = source

    @property  # type: ignore[misc]
    def __class__(self) -> type:
        return type(self._plugin)

    def __getattr__(self, attr: str) -> Any:
        # A property's own error is the plugin's too; AttributeError stays what hasattr() reads.
        value = _call(self._label, self._source, attr, getattr, self._plugin, attr,
                      passing=(SlidernetError, AttributeError))
        if not callable(value) or inspect.isclass(value):
            return value

        def method(*args: Any, **kwargs: Any) -> Any:
            return _call(self._label, self._source, f"{attr}()", value, *args, **kwargs)

        method.__name__ = attr
        method.__doc__ = getattr(value, "__doc__", None)
        return method

    def __repr__(self) -> str:
        return repr(self._plugin)

    def __reduce__(self) -> tuple[Any, ...]:
        return _Guarded, (self._plugin, self._label, self._source)

