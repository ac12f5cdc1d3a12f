"""When a demon has diverged, and how its values are reported then.

The engine marks a demon diverged, and freezes it, when its TD error, prediction or action values go
non-finite or beyond MAX_MAGNITUDE (`core.horde`); the run layer also marks one whose weights do, even
where its predictions still read small. Every route reports the values of a diverged demon, and any
number beyond MAX_MAGNITUDE, as null.
"""

from __future__ import annotations

import math

import numpy as np

from horde.core.horde import MAX_MAGNITUDE, Horde, HordeState

__all__ = ["MAX_MAGNITUDE", "beyond_magnitude", "meaningful"]


def meaningful(value: float) -> float | None:
    """The number, or None where it is NaN, infinite or beyond MAX_MAGNITUDE (JSON has no NaN)."""
    value = float(value)
    return value if math.isfinite(value) and abs(value) <= MAX_MAGNITUDE else None


def beyond_magnitude(horde: Horde, state: HordeState) -> np.ndarray:
    """[D] bool: demons whose prediction or any weight is non-finite or beyond MAX_MAGNITUDE."""
    out = ~(np.abs(state.prediction) <= MAX_MAGNITUDE)  # [D]; NaN compares False, so it counts
    per_block = [
        np.maximum(np.abs(theta).max(axis=0, initial=0.0), np.abs(w).max(axis=0, initial=0.0))  # [Db]; NaN propagates
        for theta, w in zip(state.theta, state.w, strict=True)
    ]
    if per_block:
        out[horde.slot_demon] |= ~(np.concatenate(per_block) <= MAX_MAGNITUDE)
    return out
