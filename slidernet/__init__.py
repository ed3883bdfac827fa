"""slidernet: networks of frictional sliders driven by thermal dilation.

The quasi-static solver resolves every rearrangement exactly (no time
stepping). Start with :func:`run`::

    import slidernet
    ds = slidernet.run({...})   # an xarray.Dataset
"""

from __future__ import annotations

from slidernet._version import __version__
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
from slidernet.plugins.registry import register_distribution, register_driver

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


# Where each stage lives; the old flat names (slidernet.theory, slidernet.sweep, ...) still resolve.
_SUBMODULES = {
    "builders": "model.builders", "network": "model.network", "units": "model.units",
    "distributions": "plugins.distributions", "drivers": "plugins.drivers", "registry": "plugins.registry",
    "testing": "testing", "config": "config", "solver": "solver", "kernels": "kernels",
    "observables": "analysis.observables", "theory": "analysis.theory", "plots": "analysis.plots",
    "io": "io", "store": "io.store", "checkpoint": "io.checkpoint",
    "runner": "ensemble.runner", "execution": "ensemble.execution", "sweep": "ensemble.sweep",
    "paper": "paper", "dynamics": "validation.dynamics", "speed_error": "validation.speed_error",
    "model": "model", "plugins": "plugins", "analysis": "analysis", "ensemble": "ensemble",
    "validation": "validation",
}


def __getattr__(name: str):
    # Lazy: importing slidernet should not import numba and compile kernels.
    if name == "run":
        from slidernet.ensemble.runner import run

        return run
    if name == "load_config":
        from slidernet.config import load_config

        return load_config
    if name in _SUBMODULES:  # slidernet.theory etc. without an explicit import, as in scipy
        import importlib

        return importlib.import_module(f"slidernet.{_SUBMODULES[name]}")
    raise AttributeError(f"module 'slidernet' has no attribute {name!r}")
