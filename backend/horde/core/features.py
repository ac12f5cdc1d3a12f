"""Tile coders: sparse binary state features, kept as arrays of active indices.

Every coder has a fixed number `k` of active features in every state, so a batch of B states codes to
an index array of shape [B, k]. State-action features (thesis Table 4.1) place the state features in
the block of one action: index `a * n + i`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from horde.spec import FeatureSpec

HASH_MULTIPLIER = 2654435761  # Knuth's multiplicative hash: key * this mod 2^32, then mod the table size
HASH_MODULUS = 2**32


@njit(cache=True)
def hashed_tiles(values, low, high, tilings, tiles, size, out):
    """Active features of sensors tiled one by one and hashed into `size` entries: out[:tilings * S].

    Sensor s's reading, scaled by its range to u in [0, 1], falls in tile floor(u * tiles + t / tilings)
    (clipped to 0..tiles) of tiling t; the key (s, t, tile) hashes to (key * HASH_MULTIPLIER mod 2^32) mod
    size, and a hash already taken in this state moves to the next free entry (the active features stay
    distinct, as the learners need). The caller appends the bias, entry `size`.
    """
    m = 0
    for s in range(values.shape[0]):
        u = (values[s] - low[s]) / (high[s] - low[s])
        for t in range(tilings):
            tile = min(max(math.floor(u * tiles + t / tilings), 0), tiles)
            key = (s * tilings + t) * (tiles + 1) + tile
            index = (key * HASH_MULTIPLIER) % HASH_MODULUS % size
            taken = True
            while taken:
                taken = False
                for j in range(m):
                    if out[j] == index:
                        taken = True
                        index = (index + 1) % size
                        break
            out[m] = index
            m += 1


class StateCoder:
    """A compiled `FeatureSpec`: maps positions (and a condition demon's prediction) to active indices.

    Attributes:
        n: number of state features (all condition blocks included).
        k: number of active features in every state.
        base_n: number of state features of one condition block.
    """

    def __init__(self, spec: FeatureSpec, width: float, height: float, sensor_names: list[str] | None = None) -> None:
        self.spec = spec
        self.width = float(width)
        self.height = float(height)
        self.base_n = spec.base_size()
        self.k = spec.active_count()
        self.thresholds = np.asarray(spec.condition.thresholds if spec.condition else [], dtype=float)
        self.n = self.base_n * (len(self.thresholds) + 1)
        tiled = spec.sensors or []
        self.sensor_index = {name: i for i, name in enumerate(sensor_names or [])}
        self.tiled_columns = np.array([self.sensor_index[t.sensor] for t in tiled], dtype=np.int64)
        self.tiled_low = np.array([t.low for t in tiled], dtype=float)
        self.tiled_high = np.array([t.high for t in tiled], dtype=float)
        # kind "table": row v lists the active indices where the sensor reads v (sorted; an index twice is value 2)
        self.table = np.sort(np.array(spec.table or [[0]], dtype=np.int64), axis=1)  # [V, k]
        self.table_column = self.sensor_index.get(spec.sensor or "", -1)
        # tiles3-style asymmetric offsets: tiling t is shifted by t * (1, 3) / tilings of a tile.
        t = np.arange(spec.tilings)
        self._tile_offsets = np.stack([(t * 1 / spec.tilings) % 1.0, (t * 3 / spec.tilings) % 1.0], axis=1)

    def active(
        self,
        x: np.ndarray,
        y: np.ndarray,
        condition: np.ndarray | None = None,
        sensors: np.ndarray | None = None,
    ) -> np.ndarray:
        """Active state features.

        Args:
            x, y: [B] positions.
            condition: [B] the condition demon's prediction, required when the spec has a condition.
            sensors: [B, S] the sensor vectors (named by `sensor_index`), required by kinds "sensors" and "table".

        Returns:
            [B, k] int64 indices in [0, n), distinct within each row (sorted for kind "sensors"); kind "table"
            lists its rows sorted, where an index repeated is a feature of value 2.
        """
        if self.spec.kind in ("sensors", "table") and sensors is None:
            raise ValueError(f"{self.spec.kind} features need the sensor vectors")
        if self.spec.kind == "sensors":
            idx = self._sensor_active(np.asarray(sensors, dtype=float))
        elif self.spec.kind == "table":
            idx = self.table[self.table_row(np.asarray(sensors, dtype=float)[:, self.table_column])]
        else:
            idx = self._base_active(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        if len(self.thresholds):
            if condition is None:
                raise ValueError("conditioned features need the condition demon's prediction")
            block = np.searchsorted(self.thresholds, np.asarray(condition, dtype=float), side="right")  # [B]
            idx = idx + (block * self.base_n)[:, None]
        return idx

    def table_row(self, reading: np.ndarray) -> np.ndarray:
        """[B] the table's row of each reading: rounded to the nearest integer, clipped to the table."""
        return np.clip(np.rint(reading), 0, len(self.table) - 1).astype(np.int64)

    def block_of(self, condition: np.ndarray) -> np.ndarray:
        """[B] which condition block a prediction selects (0 below the first threshold)."""
        return np.searchsorted(self.thresholds, np.asarray(condition, dtype=float), side="right")

    def _cells(self, u: np.ndarray, parts: int) -> np.ndarray:
        """Index of the part of [0, 1) holding u, clipped into range."""
        return np.minimum(np.maximum(np.floor(u * parts).astype(np.int64), 0), parts - 1)

    def _sensor_active(self, sensors: np.ndarray) -> np.ndarray:
        """[B, k] hashed tiles of the tiled sensors plus the bias, sorted."""
        spec = self.spec
        size = spec.size or 0
        out = np.empty((sensors.shape[0], self.k), dtype=np.int64)
        for row in range(sensors.shape[0]):
            values = sensors[row, self.tiled_columns]
            hashed_tiles(values, self.tiled_low, self.tiled_high, spec.tilings, spec.tiles, size, out[row])
            out[row, -1] = size
        out.sort(axis=1)
        return out

    def _base_active(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        spec = self.spec
        batch = len(x)
        u, v = x / self.width, y / self.height
        if spec.kind == "constant":
            return np.zeros((batch, 1), dtype=np.int64)
        if spec.kind == "grid":
            i, j = self._cells(u, spec.tiles), self._cells(v, spec.tiles)
            return (i * spec.tiles + j)[:, None]
        if spec.kind == "stripes":
            p = spec.parts
            i, j = self._cells(u, p), self._cells(v, p)  # column, row
            columns = i
            rows = p + j
            diagonals = 2 * p + (i + j)
            anti_diagonals = 2 * p + (2 * p - 1) + (i - j + p - 1)
            bias = np.full(batch, self.base_n - 1)
            return np.stack([columns, rows, diagonals, anti_diagonals, bias], axis=1)
        # tiles: `tilings` grids of (tiles + 1)^2, each shifted, plus a bias
        side = spec.tiles + 1
        su = u[:, None] * spec.tiles + self._tile_offsets[None, :, 0]  # [B, T]
        sv = v[:, None] * spec.tiles + self._tile_offsets[None, :, 1]  # [B, T]
        i = np.minimum(np.maximum(np.floor(su).astype(np.int64), 0), spec.tiles)
        j = np.minimum(np.maximum(np.floor(sv).astype(np.int64), 0), spec.tiles)
        tiling_base = np.arange(spec.tilings) * side * side  # [T]
        tiles = tiling_base[None, :] + i * side + j  # [B, T]
        bias = np.full((batch, 1), self.base_n - 1)
        return np.concatenate([tiles, bias], axis=1)


def state_action_indices(state_idx: np.ndarray, actions: np.ndarray, n: int) -> np.ndarray:
    """Active indices of phi(s, a): the state features in the block of action a.

    Args:
        state_idx: [B, k] active state features.
        actions: [B] action per row.
        n: number of state features (block size).

    Returns:
        [B, k] indices into the [A * n] state-action vector.
    """
    return state_idx + (np.asarray(actions) * n)[:, None]


def all_action_indices(state_idx: np.ndarray, n: int, num_actions: int) -> np.ndarray:
    """[B, A, k]: the state features placed in every action block (the support of phi_bar)."""
    return state_idx[:, None, :] + (np.arange(num_actions) * n)[None, :, None]
