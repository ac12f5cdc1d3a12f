"""A robot-like stream of sensor readings, tile-coded into 6065 binary features with 457 active.

The nexting robot (Modayil, White & Sutton 2014) tile-coded its sensors into 6065 binary features, 457
of them active at every step, ten times a second. This stream has the same shape: 57 sensors, each
read into [0, 1) and tile-coded by 8 offset tilings (456 tilings: 136 of 14 tiles, 320 of 13), plus a
bias feature: 6064 + 1 = 6065 features, 456 + 1 = 457 active. A sensor moves as a slow sinusoid
(period 30 to 3000 steps) plus a fast one (5 to 50 steps) plus noise, so some sensors sweep their
range within a trace's memory and others barely move: the trace supports this produces are measured
and reported by `horde bench` (the `rows` column: mean support rows per block).

The stream is exogenous: actions (drawn by the benchmarks from a uniform behaviour) do not change it,
which does not matter for throughput. Everything is drawn from one seeded generator.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

SENSORS = 57
TILINGS = 8  # per sensor
NUM_FEATURES = 6065
ACTIVE = SENSORS * TILINGS + 1  # 457
TIMESCALES = np.array([0.0, 0.5, 0.75, 0.875, 0.9375])  # the nexting robot's gammas


@dataclass(frozen=True)
class Stream:
    """Sensor readings and their active features for a number of steps.

    Attributes:
        readings: [T, S] sensor values in [0, 1).
        features: [T, k] active feature indices (k = 457), sorted.
    """

    readings: np.ndarray
    features: np.ndarray

    @property
    def steps(self) -> int:
        return len(self.readings)


def tiles_per_tiling() -> np.ndarray:
    """[S * TILINGS] tiles of each tiling: 14 for the first 136, 13 for the rest (6064 in all)."""
    count = SENSORS * TILINGS
    tiles = np.full(count, 13)
    tiles[: NUM_FEATURES - 1 - 13 * count] = 14
    return tiles


def tile_code(readings: np.ndarray) -> np.ndarray:
    """[T, S] readings in [0, 1) -> [T, 457] active features (sensor s, tiling t offset by t / TILINGS of a tile)."""
    tiles = tiles_per_tiling()  # [S T]
    base = np.concatenate([[0], np.cumsum(tiles)[:-1]])  # [S T] first feature of each tiling
    offsets = np.tile(np.arange(TILINGS) / TILINGS, SENSORS)  # [S T]
    u = np.repeat(readings, TILINGS, axis=1)  # [T, S T]
    index = np.minimum(np.floor(u * (tiles - 1) + offsets).astype(np.int64), tiles - 1)  # [T, S T]
    bias = np.full((len(readings), 1), NUM_FEATURES - 1)
    return np.concatenate([base + index, bias], axis=1)


def make_stream(steps: int, seed: int = 0) -> Stream:
    """`steps` consecutive readings of the 57 sensors, and their features."""
    rng = np.random.default_rng(seed)
    t = np.arange(steps)[:, None]  # [T, 1]
    slow = np.exp(rng.uniform(np.log(30), np.log(3000), SENSORS))
    fast = np.exp(rng.uniform(np.log(5), np.log(50), SENSORS))
    phase = rng.uniform(0, 2 * np.pi, (2, SENSORS))
    readings = (
        0.5
        + 0.3 * np.sin(2 * np.pi * t / slow + phase[0])
        + 0.1 * np.sin(2 * np.pi * t / fast + phase[1])
        + rng.normal(0.0, 0.02, (steps, SENSORS))
    )
    readings = np.clip(readings, 0.0, np.nextafter(1.0, 0.0))
    return Stream(readings, tile_code(readings))


def threshold_cumulants(count: int, seed: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """Which sensor and threshold each of `count` questions reads: r = reading (threshold 0) or 1[reading > tau]."""
    rng = np.random.default_rng(seed)
    sensor = np.arange(count) % SENSORS
    threshold = np.where(np.arange(count) < SENSORS, 0.0, rng.uniform(0.2, 0.8, count))
    return sensor, threshold


def cumulants(readings: np.ndarray, sensor: np.ndarray, threshold: np.ndarray) -> np.ndarray:
    """[D] cumulants at one step from [S] readings."""
    values = readings[sensor]
    return np.where(threshold > 0.0, (values > threshold).astype(float), values)
