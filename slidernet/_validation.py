"""Input checks shared by every stage (as scikit-learn's ``utils/validation``): what a plugin returns.

This module sits below everything else, so that the plugins, the registry
and the solver can all check values without importing one another.
"""

from __future__ import annotations

import numpy as np

from slidernet.errors import PluginError


def checked_output(values: object, shape: tuple[int, ...], kind: str, name: str, call: str) -> np.ndarray:
    """A plugin's returned array as float64, refused unless it has ``shape`` and is finite.

    >>> checked_output([1.0, float("nan")], (2,), "driver", "mine", "thetas(rng, 1)")
    Traceback (most recent call last):
    ...
    slidernet.errors.PluginError: The driver 'mine' returned NaN or inf values from thetas(rng, 1).
    """
    arr = np.asarray(values, dtype=np.float64)
    if arr.shape != shape:
        raise PluginError(
            f"The {kind} {name!r} returned shape {arr.shape} from {call}; expected {shape}."
        )
    if not np.isfinite(arr).all():
        raise PluginError(f"The {kind} {name!r} returned NaN or inf values from {call}.")
    return arr
