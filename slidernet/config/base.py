"""The common ground of the configuration's tables.

The strict model every table derives from (an unknown key is refused, an
assignment is validated, chosen keys are left out of a dump when None) and
the number types of their fields.
"""

from __future__ import annotations

from typing import Annotated, Any, ClassVar

from pydantic import BaseModel, ConfigDict, Field, SerializerFunctionWrapHandler, model_serializer

PositiveFloat = Annotated[float, Field(gt=0, allow_inf_nan=False)]
FiniteFloat = Annotated[float, Field(allow_inf_nan=False)]


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
