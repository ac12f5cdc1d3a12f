"""A demon's value map over the plane of two sensors (a phase plane: position and velocity for MountainCar).

The other sensors are held at the values given (the agent's current ones), and the Horde is read frozen
(`Horde.forward` with those sensor vectors), so a value map shows what the demon would predict if only the
two chosen sensors changed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from horde.core.horde import Horde, HordeState

MAX_PHASE_RESOLUTION = 128


@dataclass(frozen=True)
class Axis:
    sensor: str
    low: float
    high: float

    def centres(self, resolution: int) -> np.ndarray:
        """[R] the centres of `resolution` equal cells from low to high."""
        return self.low + (np.arange(resolution) + 0.5) * (self.high - self.low) / resolution


def axis_of(horde: Horde, sensor: str) -> Axis:
    """The sensor's range as an axis (its bounds, else the range a tiling gives it).

    Raises:
        ValueError: an unknown sensor, or one whose range nothing gives.
    """
    bounds = horde.spec.world.sensor_bounds()
    if sensor not in bounds:
        raise ValueError(f"unknown sensor {sensor!r} (known: {', '.join(horde.spec.world.sensor_names())})")
    low, high = bounds[sensor]
    if not (np.isfinite(low) and np.isfinite(high)):
        tiled = [t for g in horde.groups for t in (g.coder.spec.sensors or []) if t.sensor == sensor]
        ranged = [(t.low, t.high) for t in tiled if t.low is not None and t.high is not None]
        if not ranged:
            raise ValueError(f"sensor {sensor!r} has no finite range to draw")
        low, high = ranged[0]
    return Axis(sensor, float(low), float(high))


def phase_plane(horde: Horde, state: HordeState, demon: str, x: Axis, y: Axis, held: np.ndarray,
                resolution: int = 32) -> np.ndarray:  # fmt: skip
    """[R, R] the demon's prediction over the (x, y) sensor plane, row j at y's j-th cell, column i at x's i-th.

    Args:
        held: [S] the values of every sensor; x's and y's are replaced cell by cell.
    """
    if not 2 <= resolution <= MAX_PHASE_RESOLUTION:
        raise ValueError(f"resolution must be in [2, {MAX_PHASE_RESOLUTION}]")
    names = horde.spec.world.sensor_names()
    gx, gy = np.meshgrid(x.centres(resolution), y.centres(resolution))  # [R, R] each, row = y
    sensors = np.tile(np.asarray(held, dtype=float), (resolution * resolution, 1))  # [R * R, S]
    sensors[:, names.index(x.sensor)] = gx.ravel()
    sensors[:, names.index(y.sensor)] = gy.ravel()
    zeros = np.zeros(resolution * resolution)
    forward = horde.forward(state, zeros, zeros, sensors=sensors, demons=[demon])
    values = forward.prediction[:, horde.index[demon]].reshape(resolution, resolution)
    return np.where(state.diverged[horde.index[demon]], np.nan, values)
