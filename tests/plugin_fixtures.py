"""Plugins used by test_registry.py as the targets of fake entry points; broken ones for test_plugin_errors.py."""

from __future__ import annotations

import sys

import numpy as np
from scipy import special


class FakeDist:
    """A uniform p(mu_s) on [low, high], as a third-party package would ship it."""

    def __init__(self, low: float = 0.55, high: float = 0.65) -> None:
        self.low = float(low)
        self.high = float(high)

    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        return rng.uniform(self.low, self.high, size)

    def cdf(self, x):
        return np.clip((np.asarray(x, dtype=float) - self.low) / (self.high - self.low), 0.0, 1.0)


class NanDist:
    """A broken plugin: a valid cdf, but NaN draws."""

    def __init__(self) -> None:
        pass

    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        return np.full(size, np.nan)

    def cdf(self, x):
        return special.ndtr((np.asarray(x, dtype=float) - 0.6) / 0.01)


class ShortDriver:
    """A broken driver: one value too few."""

    def __init__(self, sigma_theta: float = 1e-6) -> None:
        self.sigma_theta = sigma_theta

    def thetas(self, rng: np.random.Generator, steps: int) -> np.ndarray:
        return self.sigma_theta * rng.standard_normal(steps)



class Raising(FakeDist):
    """A broken plugin: its draws raise (issue 43: the plugin's error, not a bug of slidernet)."""

    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        return np.full(size, self.low / 0)


class Exiting(FakeDist):
    """A broken plugin: its draws end the process."""

    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        sys.exit(5)


class Interrupting(FakeDist):
    """A plugin that raises KeyboardInterrupt in its draws, as Ctrl-C in its code would."""

    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        raise KeyboardInterrupt


class BrokenFactory(FakeDist):
    """A broken plugin: its factory raises."""

    def __init__(self, low: float = 0.55, high: float = 0.65) -> None:
        raise ValueError(f"cannot make a law on [{low}, {high}]")


class RaisingDriver(ShortDriver):
    """A broken driver: its thetas raise."""

    def thetas(self, rng: np.random.Generator, steps: int) -> np.ndarray:
        return {}["sigma"]
