"""The common ground of the configuration's tables.

The strict model every table derives from (an unknown key is refused, an
assignment is validated, chosen keys are left out of a dump when None) and
the number types of their fields.

A number in a configuration follows the rule of the plugins' parameters
(:func:`slidernet._validation.is_real`, :func:`~slidernet._validation.is_integral`):
``steps = "200"`` or ``realizations = true`` is refused, by name, not read
as 200 or 1, as pydantic's lax mode would. A whole number may be written
as a float without a fractional part (``steps = 1e4``: TOML has no other
way to write a power of ten).
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

#: The pydantic error types of the two rules below, which loading.py words as "must be an integer" and
#: "must be a real number".
NOT_INTEGER = "not_integer"
NOT_REAL = "not_real"


def _integer(value: Any) -> int:
    if not is_integral(value):
        raise PydanticCustomError(NOT_INTEGER, "must be an integer")
    return int(value)


def _real(value: Any) -> float:
    if not is_real(value):
        raise PydanticCustomError(NOT_REAL, "must be a real number")
    # A Python int or float as given, so that a bound's message quotes what the user wrote.
    return value if isinstance(value, (int, float)) else float(value)


# The rule's validator comes last in each Annotated, so that it runs first and pydantic keeps the bounds
# inside its float schema (NaN is then "must be a finite number", not "must be > 0").

#: A whole number: an int, or a float with no fractional part; never a bool or a string.
Integer = Annotated[int, BeforeValidator(_integer)]
#: A finite real number > 0.
PositiveFloat = Annotated[float, Field(gt=0, allow_inf_nan=False), BeforeValidator(_real)]
#: A finite real number.
FiniteFloat = Annotated[float, Field(allow_inf_nan=False), BeforeValidator(_real)]
#: A finite real number >= 0.
NonNegativeFloat = Annotated[float, Field(ge=0, allow_inf_nan=False), BeforeValidator(_real)]
#: A real number > 0, inf included (a duration that may be "never").
PositiveReal = Annotated[float, Field(gt=0), BeforeValidator(_real)]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", validate_assignment=True)
    # Keys left out of a dump when None: a configuration that does not use a key added later dumps as it
    # did before the key existed, so that the config stored with earlier results and the identity of
    # interrupted runs (run.json) still match it.
    _omit_if_none: ClassVar[tuple[str, ...]] = ()

    @model_serializer(mode="wrap")
    def _dump(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        data = handler(self)
        for key in self._omit_if_none:
            if isinstance(data, dict) and key in data and data[key] is None:
                del data[key]
        return data
