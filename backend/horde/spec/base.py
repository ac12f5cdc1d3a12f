"""What every spec model shares: the frozen, strict base model, names, bounded numbers, and the size limits.

Every model is frozen and forbids unknown keys, so a typo in a scenario file or an API request is a
422 naming the field instead of a silently ignored setting. Every size is bounded (DESIGN section 8,
security).
"""

from __future__ import annotations

import re
from typing import Annotated, Any

from pydantic import BaseModel, ConfigDict, Field, ValidationError
from pydantic_core import InitErrorDetails, PydanticCustomError

MAX_WORLD_SIZE = 1e6
MAX_REGIONS = 64
MAX_COLORS = 16
MAX_DEMONS = 10_000
MAX_FEATURES = 1_000_000
MAX_EXPR_NODES = 256
MAX_EXPR_DEPTH = 16  # expressions inside expressions, checked before pydantic validates them
MAX_STEPS = 1_000_000
MAX_EPISODES = 1_000_000
MAX_TRIALS = 1_000
MAX_ACTIONS = 64
MAX_SENSORS = 1024

NAME_MAX = 64
NAME_PATTERN = r"^[A-Za-z_][A-Za-z0-9_.-]*$"
NAME_RULE = f"1 to {NAME_MAX} letters, digits, '_', '.' or '-', the first a letter or '_'"
NAME = re.compile(NAME_PATTERN)
Name = Annotated[str, Field(min_length=1, max_length=NAME_MAX, pattern=NAME_PATTERN)]
SensorName = Annotated[str, Field(min_length=1, max_length=80, pattern=r"^[A-Za-z_][A-Za-z0-9_.:-]*$")]
Finite = Annotated[float, Field(allow_inf_nan=False)]
Probability = Annotated[float, Field(ge=0.0, le=1.0, allow_inf_nan=False)]
PositiveSize = Annotated[float, Field(gt=0.0, le=MAX_WORLD_SIZE, allow_inf_nan=False)]
MIN_HZ = 0.01  # paced runs: one step every 100 s at the slowest
MAX_HZ = 10_000.0  # beyond this, run at full speed (hz = null)
Hz = Annotated[
    float,
    Field(
        ge=MIN_HZ,
        le=MAX_HZ,
        allow_inf_nan=False,
        description=f"steps per second, {MIN_HZ} to {MAX_HZ:g}; null: as fast as possible",
    ),
]


class Model(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid", populate_by_name=True)


def field_error(title: str, loc: tuple[str | int, ...], kind: str, message: str, value: Any) -> ValidationError:
    """A ValidationError at `loc`, so that the 422 names the field (a model validator's would name the model)."""
    detail = InitErrorDetails(type=PydanticCustomError(kind, message), loc=loc, input=value)
    return ValidationError.from_exception_data(title, [detail])


def error_detail(error: Any, loc: tuple[Any, ...]) -> InitErrorDetails:
    """A pydantic error again, at another loc (custom error types are rebuilt from their message)."""
    ctx = error.get("ctx")
    try:
        detail = InitErrorDetails(type=error["type"], loc=loc, input=error["input"])
        if ctx:
            detail["ctx"] = ctx
        ValidationError.from_exception_data("check", [detail])
    except (KeyError, TypeError):
        detail = InitErrorDetails(type=PydanticCustomError(error["type"], error["msg"]), loc=loc, input=error["input"])
    return detail
