"""slidernet: networks of frictional sliders driven by thermal dilation.

The quasi-static solver resolves every rearrangement exactly (no time
stepping). Start with :func:`run`::

    import slidernet
    ds = slidernet.run({...})   # an xarray.Dataset
"""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

from slidernet.errors import (
    AvalancheError,
    CheckpointError,
    ConfigError,
    PluginError,
    RunInterrupted,
    SlidernetError,
    TiltTestError,
    UnknownPluginError,
)
from slidernet.registry import register_distribution, register_driver

try:
    __version__ = version("slidernet")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0+unknown"

__all__ = [
    "AvalancheError",
    "CheckpointError",
    "ConfigError",
    "PluginError",
    "RunInterrupted",
    "SlidernetError",
    "TiltTestError",
    "UnknownPluginError",
    "__version__",
    "load_config",
    "register_distribution",
    "register_driver",
    "run",
]


_SUBMODULES = {"builders", "checkpoint", "distributions", "drivers", "dynamics", "execution", "io", "network",
               "observables", "plots", "registry", "solver", "speed_error", "store", "sweep", "testing", "theory",
               "units"}


def __getattr__(name: str):
    # Lazy: importing slidernet should not import numba and compile kernels.
    if name == "run":
        from slidernet.runner import run

        return run
    if name == "load_config":
        from slidernet.config import load_config

        return load_config
    if name in _SUBMODULES:  # slidernet.testing etc. without an explicit import, as in scipy
        import importlib

        return importlib.import_module(f"slidernet.{name}")
    raise AttributeError(f"module 'slidernet' has no attribute {name!r}")
