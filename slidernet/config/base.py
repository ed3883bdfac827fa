"""The common ground of the configuration's tables.

The strict model every table derives from (an unknown key is refused, an
assignment is validated, chosen keys are left out of a dump when None) and
the number types of their fields.

A number in a configuration follows the rule of the plugins' parameters
(:func:`slidernet._validation.is_real`, :func:`~slidernet._validation.is_integral`):
``steps = "200"`` or ``realizations = true`` is refused, by name, not read
as 200 or 1, as pydantic's lax mode would. A whole number may be written
as a float without a fractional part (``steps = 1e4``: TOML has no other
way to write a power of ten), and must fit int64, where the kernels and the
result files hold it (``steps = 1e300`` is refused, not overflowed); a seed
may take the 128 bits of numpy's SeedSequence. Every numeric field of every
table is one of the types below (``tests/test_config_fields.py`` walks the
models to check it): a bound is added as ``Annotated[FiniteFloat, Field(ge=0,
le=1)]``, never with a bare ``int`` or ``float``, which pydantic reads in its
lax mode.
"""

from __future__ import annotations

from typing import Annotated, Any, ClassVar

from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    SerializerFunctionWrapHandler,
    model_serializer,
)
from pydantic_core import PydanticCustomError

from slidernet._validation import is_integral, is_real

#: The pydantic error types of the rules below, which loading.py words as "must be an integer", "must be a
#: real number", "must be an integer within int64 ..." and "must be an integer in [0, 2^128)".
NOT_INTEGER = "not_integer"
NOT_REAL = "not_real"
NOT_INT64 = "not_int64"
NOT_SEED = "not_seed"

#: The range of a whole number of the configuration: int64, the type the kernels and the result files hold.
INT64_MIN, INT64_MAX = -(2**63), 2**63 - 1
#: A seed's bound: numpy's SeedSequence draws 128 bits of fresh entropy (the seed of a run without one).
SEED_BOUND = 2**128


def _whole(value: Any) -> int:
    if not is_integral(value):
        raise PydanticCustomError(NOT_INTEGER, "must be an integer")
    return int(value)


def _integer(value: Any) -> int:
    n = _whole(value)
    if not INT64_MIN <= n <= INT64_MAX:
        raise PydanticCustomError(NOT_INT64, "must be an integer within int64 (-2^63 to 2^63 - 1)")
    return n


def _seed(value: Any) -> int:
    n = _whole(value)
    if n >= SEED_BOUND:  # a negative seed is left to the field's bound ("must be >= 0")
        raise PydanticCustomError(NOT_SEED, "must be an integer in [0, 2^128)")
    return n


def _real(value: Any) -> float:
    if not is_real(value):
        raise PydanticCustomError(NOT_REAL, "must be a real number")
    # A Python int or float as given, so that a bound's message quotes what the user wrote.
    return value if isinstance(value, (int, float)) else float(value)


# The rule's validator comes last in each Annotated, so that it runs first and pydantic keeps the bounds
# inside its float schema (NaN is then "must be a finite number", not "must be > 0").

#: A whole number within int64: an int, or a float with no fractional part; never a bool or a string.
Integer = Annotated[int, BeforeValidator(_integer)]
#: A seed of numpy's SeedSequence: a whole number in [0, 2^128).
Seed = Annotated[int, Field(ge=0), BeforeValidator(_seed)]
#: A finite real number > 0.
PositiveFloat = Annotated[float, Field(gt=0, allow_inf_nan=False), BeforeValidator(_real)]
#: A finite real number.
FiniteFloat = Annotated[float, Field(allow_inf_nan=False), BeforeValidator(_real)]
#: A finite real number >= 0.
NonNegativeFloat = Annotated[float, Field(ge=0, allow_inf_nan=False), BeforeValidator(_real)]
#: A real number > 0, inf included (a duration that may be "never").
PositiveReal = Annotated[float, Field(gt=0), BeforeValidator(_real)]


def unit(symbol: str, constraint: str | None = None) -> dict[str, str]:
    """A field's unit, for its ``json_schema_extra``, where the reference (:mod:`slidernet.config.reference`)
    and the JSON schema read it: ``"1"`` for a dimensionless number. Every numeric field has one
    (``tests/test_reference.py``). ``constraint``: what a validator of the field checks beyond its bounds, in
    words (``"< steps"``)."""
    return {"unit": symbol} if constraint is None else {"unit": symbol, "constraint": constraint}


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", validate_assignment=True)
    # Keys left out of a dump when None: a configuration that does not use a key added later dumps as it
    # did before the key existed, so that the config stored with earlier results and the identity of
    # interrupted runs (run.json) still match it.
    _omit_if_none: ClassVar[tuple[str, ...]] = ()
    # Keys added later with a default that is the behaviour from before them: left out of a dump at that
    # default, given or not, for the same reason (and a run that writes the default is the same run).
    _omit_if_default: ClassVar[tuple[str, ...]] = ()

    @model_serializer(mode="wrap")
    def _dump(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        data = handler(self)
        if not isinstance(data, dict):
            return data
        for key in self._omit_if_none:
            if key in data and data[key] is None:
                del data[key]
        for key in self._omit_if_default:
            if key in data and data[key] == type(self).model_fields[key].default:
                del data[key]
        return data
