"""Run configuration: pydantic models loaded from TOML or a dict.

Every check happens here, before any work: structure and ranges through
pydantic, plugin names and parameters by building the plugins. Errors are
raised as :class:`~slidernet.errors.ConfigError` with the dotted name of the
field and the reason.

From the bottom up (each module imports only those above it in this list):

- :mod:`~slidernet.config.base`: the strict model the tables derive from,
  and the number types of their fields;
- :mod:`~slidernet.config.rules`: the rules a scene and the checks of a
  configuration share: :func:`choose_kernel`, :func:`choose_tilt_at`;
- :mod:`~slidernet.config.plugins`: :class:`PluginSpec`,
  :class:`FrictionConfig`, and building the plugins they name
  (:func:`build_distribution`);
- :mod:`~slidernet.config.network`, :mod:`~slidernet.config.units`,
  :mod:`~slidernet.config.solver`, :mod:`~slidernet.config.execution`,
  :mod:`~slidernet.config.creep`, :mod:`~slidernet.config.tilt`,
  :mod:`~slidernet.config.shs`, :mod:`~slidernet.config.dynamics`: one table each;
- :mod:`~slidernet.config.run`: :class:`Config`, the whole run, and the
  names of the observables;
- :mod:`~slidernet.config.loading`: :func:`load_config`, :func:`read_toml`,
  :func:`build_network`.

>>> cfg = load_config({"steps": 10, "network": {"Ntilde": 1e-7},
...                    "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6,
...                                 "std": 0.01}},
...                    "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6}})
>>> cfg.network.kind, cfg.realizations
('two_slider', 1)
>>> load_config({"steps": 0})
Traceback (most recent call last):
...
slidernet.errors.ConfigError: Invalid configuration:
  - The 'steps' field must be >= 1. Got 0 instead.
  - The 'network' field is required.
  - The 'friction' field is required.
  - The 'driver' field is required.
"""

from __future__ import annotations

from slidernet.config.base import FiniteFloat, PositiveFloat
from slidernet.config.creep import CreepConfig
from slidernet.config.dynamics import DynamicsConfig
from slidernet.config.execution import SCHEDULER_REQUIREMENT, ExecutionConfig, is_scheduler_address
from slidernet.config.loading import build_network, load_config, read_toml
from slidernet.config.loading import tomllib as tomllib  # the TOML reader the tests share
from slidernet.config.network import NetworkConfig
from slidernet.config.plugins import (
    FrictionConfig,
    PluginSpec,
    StrengtheningConfig,
    build_distribution,
    is_finite,
)
from slidernet.config.rules import PAIR_TILT_ONLY, choose_kernel, choose_tilt_at
from slidernet.config.run import NETWORK_OBSERVABLES, OBSERVABLES, Config, Observable
from slidernet.config.shs import ShsConfig
from slidernet.config.solver import SolverConfig
from slidernet.config.tilt import InjectConfig, TiltConfig
from slidernet.config.units import UnitsConfig

__all__ = ["NETWORK_OBSERVABLES", "OBSERVABLES", "PAIR_TILT_ONLY", "SCHEDULER_REQUIREMENT", "Config",
           "CreepConfig", "DynamicsConfig", "ExecutionConfig", "FiniteFloat", "FrictionConfig", "InjectConfig",
           "NetworkConfig",
           "Observable", "PluginSpec", "PositiveFloat", "ShsConfig", "SolverConfig", "StrengtheningConfig",
           "TiltConfig", "UnitsConfig", "build_distribution", "build_network",
           "choose_kernel", "choose_tilt_at", "is_finite", "is_scheduler_address", "load_config", "read_toml"]
