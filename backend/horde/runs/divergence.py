"""How a diverged demon's values are reported: as null, as any number beyond MAX_MAGNITUDE.

When a demon has diverged is the core's one rule (`horde.core.learner`: its TD error, prediction, action
values or any weight non-finite or beyond MAX_MAGNITUDE; it is then frozen). Every route reports the values
of a diverged demon, and any number beyond MAX_MAGNITUDE, as null (JSON has no NaN).
"""

from __future__ import annotations

import math

from horde.core.engine.layout import MAX_MAGNITUDE

__all__ = ["MAX_MAGNITUDE", "meaningful"]


def meaningful(value: float) -> float | None:
    """The number, or None where it is NaN, infinite or beyond MAX_MAGNITUDE (JSON has no NaN)."""
    value = float(value)
    return value if math.isfinite(value) and abs(value) <= MAX_MAGNITUDE else None
