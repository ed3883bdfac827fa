"""Input checks shared by every stage (as scikit-learn's ``utils/validation``).

This module sits below everything else, so that the plugins, the model, the
theory and the solver can all check values without importing one another:

- :func:`is_real` and :func:`is_integral`: the rule itself, for a real
  number and for a whole one (the configuration's number types use it too);
- :func:`check_scalar`: one real parameter (a plugin's, a material value);
- :func:`check_array`: a real parameter that may be an array (the theory's
  vectorised functions);
- :func:`checked_output`: what a plugin returns;
- :func:`read_real`: a number read from a data file (a graph, a series, measured
  thresholds), refused naming the file and the line or element; :func:`is_number_text`
  tells a header from a line of numbers;
- :func:`did_you_mean`: the nearest spelling of an unknown name, for the error that refuses it.

One rule for every parameter: a real number is an ``int`` or a ``float``
(any :class:`numbers.Real`, numpy's scalars included), never a ``bool`` and
never a string, even one that reads as a number (``"0.1"`` in a TOML file is
a typo to report, not a value to guess). A whole number (a count, a size, a
seed) is a real number with no fractional part: ``3`` and ``3.0`` (TOML and
JSON may give either; ``1e4`` is a float in TOML), never ``True`` or ``"3"``.
"""

from __future__ import annotations

import difflib
import math
import numbers
from collections.abc import Callable, Iterable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from slidernet.errors import ConfigError, PluginError, param_error

# What a requirement asks of a finite float, or elementwise of a finite float array.
_TESTS: dict[str, Callable[[Any], Any]] = {
    "finite": np.isfinite,
    "> 0": lambda x: x > 0,
    ">= 0": lambda x: x >= 0,
    "!= 0": lambda x: x != 0,
    ">= 1": lambda x: x >= 1,
    "> 1": lambda x: x > 1,
    "in (0, 1)": lambda x: (x > 0) & (x < 1),   # a probability: a confidence, a level, a power
}


def is_real(value: object) -> bool:
    """True for a real number: an int or a float (numpy's too), never a bool or a string.

    >>> is_real(0.1), is_real(2), is_real(True), is_real("0.1")
    (True, True, False, False)
    """
    return not isinstance(value, (bool, np.bool_)) and isinstance(value, numbers.Real)


def is_integral(value: object) -> bool:
    """True for a finite real number with no fractional part (``3``, ``3.0``, ``1e4``); never a bool or a string.

    >>> is_integral(3), is_integral(1e4), is_integral(2.5), is_integral(True), is_integral("3")
    (True, True, False, False, False)
    """
    return is_real(value) and math.isfinite(value) and int(value) == value


def _requirement(requirement: str) -> Callable[[Any], Any]:
    try:
        return _TESTS[requirement]
    except KeyError:  # pragma: no cover - a caller's typo, not a user's
        raise ValueError(f"unknown requirement {requirement!r}; one of {sorted(_TESTS)}") from None


def check_scalar(value: object, param: str, owner: str, requirement: str = "finite") -> float:
    """``value`` as a float, refused unless it is a finite real number meeting ``requirement``.

    Parameters
    ----------
    value : object
        What the user gave.
    param, owner : str
        The parameter's name and who owns it (a plugin's registered name,
        ``units``, a theory function), for the message.
    requirement : {"finite", "> 0", ">= 0", "!= 0", ">= 1", "> 1", "in (0, 1)"}
        What the value must satisfy beyond being finite.

    Returns
    -------
    float

    Raises
    ------
    ConfigError
        Naming the parameter, its owner, the requirement and the value.

    Examples
    --------
    >>> check_scalar(2, "period", "sinusoidal", "> 0")
    2.0
    >>> check_scalar("0.1", "std", "gaussian", "> 0")
    Traceback (most recent call last):
    ...
    slidernet.errors.ConfigError: The 'std' parameter of gaussian must be a real number > 0. Got '0.1' instead.
    >>> check_scalar(float("inf"), "mean", "gaussian")
    Traceback (most recent call last):
    ...
    slidernet.errors.ConfigError: The 'mean' parameter of gaussian must be finite. Got inf instead.
    """
    test = _requirement(requirement)
    if not is_real(value):
        kind = "a real number" if requirement == "finite" else f"a real number {requirement}"
        raise param_error(param, owner, kind, value)
    x = float(value)
    if not math.isfinite(x):
        # NaN fails "> 0" too, but "finite" is then the useful word.
        raise param_error(param, owner, "finite" if requirement == "finite" else f"finite and {requirement}", x)
    if not bool(test(x)):
        raise param_error(param, owner, requirement, x)
    return x


def check_array(value: ArrayLike, param: str, owner: str, requirement: str = "finite") -> np.ndarray:
    """``value`` as a float array, refused unless every element is finite and meets ``requirement``.

    The same rule as :func:`check_scalar`, element by element: strings and
    booleans are refused. The message reports one offending element, not a
    whole (possibly huge) array.

    Examples
    --------
    >>> check_array([1, 2.5], "n", "mu_max_moments", ">= 0").tolist()
    [1.0, 2.5]
    >>> check_array([1.0, -2.0], "n", "mu_max_moments", ">= 0")
    Traceback (most recent call last):
    ...
    slidernet.errors.ConfigError: The 'n' parameter of mu_max_moments must be >= 0. Got -2.0 instead.
    """
    test = _requirement(requirement)
    kind = "a real number or an array of them" + ("" if requirement == "finite" else f", {requirement}")
    raw = np.asarray(value)
    if raw.dtype.kind not in "iuf":
        raise param_error(param, owner, kind, value)
    arr = raw.astype(np.float64, copy=False)
    finite = np.isfinite(arr)
    if not finite.all():
        bad = float(arr[~finite].flat[0])
        raise param_error(param, owner, "finite" if requirement == "finite" else f"finite and {requirement}", bad)
    ok = np.broadcast_to(test(arr), arr.shape)
    if not ok.all():
        raise param_error(param, owner, requirement, float(arr[~ok].flat[0]))
    return arr


def is_number_text(text: str) -> bool:
    """Whether Python's ``float`` reads ``text``: how a reader tells a header's words from a line of numbers
    that :func:`read_real` refuses (``nan``, ``1_0``), which is no header.

    >>> is_number_text("celsius"), is_number_text("nan"), is_number_text(" 1_0 ")
    (False, True, True)
    """
    try:
        float(text)
    except ValueError:
        return False
    return True


def read_real(value: object, what: str, where: str) -> float:
    """A finite real number from a data file's field: its text, or a value its format already typed.

    The one rule of every reader of a data file: the text of a number as Python's
    ``float`` reads it, without the underscores Python allows in its own literals
    (``1_0`` in a data file is a typo, not 10), or an int or a float the format
    typed (GraphML's ``double``); never a boolean, never empty.

    Parameters
    ----------
    value : object
        The field as the file gives it.
    what : str
        The field's name, quoted as the message should show it (``"'k'"``).
    where : str
        The file and the line (or the element), for the message.

    Raises
    ------
    ConfigError
        ``"{where}: {what} must be a number. Got ... instead."``, or ``must be finite``.

    Examples
    --------
    >>> read_real(" 2.5 ", "'k'", "net.csv, line 2")
    2.5
    >>> read_real("1_0", "'k'", "net.csv, line 2")
    Traceback (most recent call last):
    ...
    slidernet.errors.ConfigError: net.csv, line 2: 'k' must be a number. Got '1_0' instead.
    >>> read_real("inf", "'k'", "net.csv, line 2")
    Traceback (most recent call last):
    ...
    slidernet.errors.ConfigError: net.csv, line 2: 'k' must be finite. Got 'inf' instead.
    """
    if isinstance(value, str) and "_" not in value:
        try:
            number = float(value)
        except ValueError:
            number = None
    else:
        number = float(value) if is_real(value) else None
    if number is None:
        raise ConfigError(f"{where}: {what} must be a number. Got {value!r} instead.")
    if not math.isfinite(number):
        raise ConfigError(f"{where}: {what} must be finite. Got {value!r} instead.")
    return number


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


def did_you_mean(name: object, known: Iterable[str]) -> str:
    """A question naming the known name nearest to an unknown ``name``, or ``""`` when none is near.

    Near is :func:`difflib.get_close_matches`'s rule (a similarity ratio of
    at least 0.6), so a typo is answered and an unrelated word is not.

    >>> did_you_mean("realisations", ["seed", "realizations", "steps"])
    "did you mean 'realizations'?"
    >>> did_you_mean("colour", ["material", "size"])
    ''
    """
    # Never the name itself: one listed but broken (a plugin that failed to load) is no suggestion.
    close = difflib.get_close_matches(str(name), [k for k in known if k != str(name)], n=1)
    return f"did you mean {close[0]!r}?" if close else ""
