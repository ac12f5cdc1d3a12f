"""State features: a state coded into sparse active features, each with a value (DESIGN section 3).

One compiled coder (`code`) serves the learning loop, the rollouts and the batch coding of `StateCoder`
(value maps, the frozen Horde's `forward`); `reference.state_features` writes the same coding plainly, as
dense vectors. A state's active features are sorted distinct indices with values: binary kinds (stripes,
tiles, grid, constant, sensors) give value 1, a table its row's values (an index listed twice adds up), the
bases over named sensors real values. Sensors are scaled from their ranges to [0, 1] and clipped:

* polynomial: x_c(s) = prod_i s_i^{c_i}, and fourier: x_c(s) = cos(pi c . s), for every c in {0..order}^d,
  row c of the basis table in lexicographic order (Sutton & Barto 2018, section 9.5);
* rbf: x_c(s) = exp(-||s - c||^2 / (2 width^2)) for the centres c on an even grid of `centres` per input;
* linear: the scaled sensors themselves, then a bias 1.

State-action features (thesis Table 4.1) place the state features in the block of one action: index
`a * n + i`.

Why one module of about 420 lines: the compiled coder of every kind, its table (`pack_codes`) and its Python
face (`StateCoder`) read the same arrays; split, each would re-explain the others' layout.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
from numba import njit

from horde.core.engine.layout import NO_NRT, Codes
from horde.spec import FeatureSpec
from horde.spec.run import sensor_range

HASH_MULTIPLIER = 2654435761  # Knuth's multiplicative hash: key * this mod 2^32, then mod the table size
HASH_MODULUS = 2**32
FEATURE_KINDS = {"stripes": 0, "tiles": 1, "grid": 2, "constant": 3, "sensors": 4, "table": 5, "polynomial": 6,
                 "fourier": 7, "rbf": 8, "linear": 9}  # fmt: skip
STRIPES, TILES, GRID, CONSTANT, SENSORS, TABLE, POLYNOMIAL, FOURIER, RBF, LINEAR = range(10)


@njit(**NO_NRT)
def hashed_tiles(values, low, high, tilings, tiles, size, taken, out):
    """Active features of sensors tiled one by one and hashed into `size` entries: out[:tilings * S].

    Sensor s's reading, scaled by its range to u in [0, 1], falls in tile floor(u * tiles + t / tilings)
    (clipped to 0..tiles) of tiling t; the key (s, t, tile) hashes to (key * HASH_MULTIPLIER mod 2^32) mod
    size, and a hash already taken in this state moves to the next free entry (the active features stay
    distinct, as the learners need). The caller appends the bias, entry `size`.

    `taken` ([size] or more, zeros, left zeros) marks the entries taken so far: a hash finds out whether its
    entry is free in one read, where a search of the features placed before it made the coding quadratic in
    their count (456 for nexting: two thirds of a 10-demon step, with the insertion sort of the hashes after
    it). Where the table is small beside the count squared, the features are read off the marks in one scan,
    sorted; else they stay in the order placed and the marks are cleared one by one (the caller sorts them).
    """
    m = 0
    for s in range(values.shape[0]):
        u = (values[s] - low[s]) / (high[s] - low[s])
        for t in range(tilings):
            tile = min(max(math.floor(u * tiles + t / tilings), 0), tiles)
            key = (s * tilings + t) * (tiles + 1) + tile
            index = (key * HASH_MULTIPLIER) % HASH_MODULUS % size
            while taken[index]:
                index = (index + 1) % size
            taken[index] = 1
            out[m] = index
            m += 1
    if size < m * m:
        m = 0
        for index in range(size):
            if taken[index]:
                taken[index] = 0
                out[m] = index
                m += 1
    else:
        for j in range(m):
            taken[out[j]] = 0


@njit(**NO_NRT)
def _cell(u, parts):
    return min(max(math.floor(u * parts), 0), parts - 1)


@njit(**NO_NRT)
def _sort(index, value, m):
    """Insertion sort of (index, value)[:m] by index (coded features mostly come sorted: this costs one pass)."""
    for i in range(1, m):
        key, v = index[i], value[i]
        j = i - 1
        while j >= 0 and index[j] > key:
            index[j + 1] = index[j]
            value[j + 1] = value[j]
            j -= 1
        index[j + 1] = key
        value[j + 1] = v


@njit(**NO_NRT)
def _merge_repeats(index, value, m):
    """Sorted (index, value)[:m] with each repeated index once, its values added; returns the new count."""
    out = 0
    for j in range(m):
        if out > 0 and index[out - 1] == index[j]:
            value[out - 1] += value[j]
        else:
            index[out] = index[j]
            value[out] = value[j]
            out += 1
    return out


@njit(**NO_NRT)
def _positions(codes, g, x, y, index, value):
    """The binary kinds over a position (stripes, tiles, grid, constant): their sorted indices, values 1."""
    kind, base_n = codes.kind[g], codes.base_n[g]
    u = x / codes.plane_width
    v = y / codes.plane_height
    m = 0
    if kind == CONSTANT:
        index[0] = 0
        m = 1
    elif kind == GRID:
        tiles = codes.tiles[g]
        index[0] = _cell(u, tiles) * tiles + _cell(v, tiles)
        m = 1
    elif kind == STRIPES:
        p = codes.parts[g]
        i = _cell(u, p)
        j = _cell(v, p)
        index[0] = i
        index[1] = p + j
        index[2] = 2 * p + (i + j)
        index[3] = 2 * p + (2 * p - 1) + (i - j + p - 1)
        index[4] = base_n - 1
        m = 5
    else:  # tiles: `tilings` grids of (tiles + 1)^2, each shifted asymmetrically (tiles3), plus a bias
        tilings, tiles = codes.tilings[g], codes.tiles[g]
        side = tiles + 1
        for t in range(tilings):
            ou = (t * 1 / tilings) % 1.0
            ov = (t * 3 / tilings) % 1.0
            i = min(max(math.floor(u * tiles + ou), 0), tiles)
            j = min(max(math.floor(v * tiles + ov), 0), tiles)
            index[t] = t * side * side + i * side + j
        index[tilings] = base_n - 1
        m = tilings + 1
    for j in range(m):
        value[j] = 1.0
    return m


@njit(**NO_NRT)
def _basis(codes, g, inputs, index, value):
    """The real-valued kinds over the scaled inputs (polynomial, fourier, rbf, linear): every feature, sorted."""
    kind = codes.kind[g]
    d = codes.sensor_hi[g] - codes.sensor_lo[g]
    if kind == LINEAR:
        for i in range(d):
            index[i] = i
            value[i] = inputs[i]
        index[d] = d
        value[d] = 1.0
        return d + 1
    at, rows, basis = codes.basis_at[g], codes.basis_rows[g], codes.basis
    inv = 1.0 / (2.0 * codes.width[g] * codes.width[g])
    for r in range(rows):
        c = basis[at + r]
        if kind == POLYNOMIAL:
            x = 1.0
            for i in range(d):
                x *= inputs[i] ** c[i]
        elif kind == FOURIER:
            x = 0.0
            for i in range(d):
                x += c[i] * inputs[i]
            x = math.cos(math.pi * x)
        else:
            x = 0.0
            for i in range(d):
                x += (inputs[i] - c[i]) * (inputs[i] - c[i])
            x = math.exp(-x * inv)
        index[r] = r
        value[r] = x
    return rows


@njit(**NO_NRT)
def code(codes, g, x, y, sensors, condition, inputs, taken, index, value):
    """Group g's active features at a state into (index, value)[:m], sorted and distinct; returns m.

    Args:
        codes: how every group codes (`engine.layout.Codes`).
        g: the group.
        x, y: the position (the grid world's kinds).
        sensors: [S] the sensors there (kinds sensors, table and the bases).
        condition: the condition demon's prediction (conditioned features; else unused).
        inputs: [most sensors of a group] scratch.
        taken: [the largest table of hashed tiles] scratch of zeros (`hashed_tiles`), left zeros.
        index, value: [k] the output.
    """
    kind = codes.kind[g]
    m = 0
    lo, hi = codes.sensor_lo[g], codes.sensor_hi[g]
    if kind == TABLE:  # the row of the sensor's reading (rounded, clipped), its repeats added up
        width = codes.table_width[g]
        row = min(max(int(np.rint(sensors[codes.table_col[g]])), 0), codes.table_rows[g] - 1)
        start = codes.table_at[g] + row * width
        for j in range(width):
            index[j] = codes.table[start + j]
            value[j] = codes.table_values[start + j]
        _sort(index, value, width)
        m = _merge_repeats(index, value, width)
    elif kind == SENSORS:
        for j in range(lo, hi):
            inputs[j - lo] = sensors[codes.sensor_col[j]]
        hashed_tiles(inputs[: hi - lo], codes.sensor_low[lo:hi], codes.sensor_high[lo:hi], codes.tilings[g],
                     codes.tiles[g], codes.base_n[g] - 1, taken, index)  # fmt: skip
        m = codes.tilings[g] * (hi - lo) + 1
        index[m - 1] = codes.base_n[g] - 1  # the bias, after every hashed entry
        for j in range(m):
            value[j] = 1.0
        _sort(index, value, m)
    elif kind >= POLYNOMIAL:
        for j in range(lo, hi):
            u = (sensors[codes.sensor_col[j]] - codes.sensor_low[j]) / (codes.sensor_high[j] - codes.sensor_low[j])
            inputs[j - lo] = min(max(u, 0.0), 1.0)
        m = _basis(codes, g, inputs, index, value)
    else:
        m = _positions(codes, g, x, y, index, value)
    t0, t1 = codes.thr_lo[g], codes.thr_hi[g]
    if t1 > t0:
        block = 0
        for t in range(t0, t1):
            if condition >= codes.thresholds[t]:
                block += 1
        for j in range(m):
            index[j] += block * codes.base_n[g]
    return m


@njit(**NO_NRT)
def code_batch(codes, g, xs, ys, sensors, conditions, inputs, taken, index, value, count):
    """`code` for a batch of B states: row b of (index, value)[b, :count[b]], the rest of the row 0."""
    for b in range(xs.shape[0]):
        count[b] = code(codes, g, xs[b], ys[b], sensors[b], conditions[b], inputs, taken, index[b], value[b])
        for j in range(count[b], index.shape[1]):
            index[b, j] = 0
            value[b, j] = 0.0


class CodeEntry:
    """What packing one feature spec needs: the spec, the sensors' columns and ranges, the plane."""

    def __init__(self, spec: FeatureSpec, sensor_names: list[str] | None, bounds: dict[str, tuple[float, float]]):
        self.spec = spec
        self.columns = {name: i for i, name in enumerate(sensor_names or [])}
        self.ranges = [sensor_range(s.sensor, s.low, s.high, bounds) for s in spec.sensors or []]


def basis_rows(spec: FeatureSpec) -> np.ndarray:
    """[features, inputs] a basis' table: polynomial / fourier exponents in {0..order}^d (lexicographic), rbf
    centres on an even grid over [0, 1]^d (empty for the other kinds)."""
    inputs = len(spec.sensors or [])
    rows: list[tuple[float, ...]]
    if spec.kind in ("polynomial", "fourier"):
        rows = [tuple(map(float, c)) for c in itertools.product(range((spec.order or 0) + 1), repeat=inputs)]
    elif spec.kind == "rbf":
        count = spec.centres or 1
        grid = [0.5] if count == 1 else [j / (count - 1) for j in range(count)]
        rows = list(itertools.product(grid, repeat=inputs))
    else:
        return np.zeros((0, max(1, inputs)))
    return np.array(rows, dtype=float).reshape(-1, max(1, inputs))


def rbf_width(spec: FeatureSpec) -> float:
    """An rbf's sigma: its own, else the spacing of its centres (1 for a single centre)."""
    count = spec.centres or 1
    if spec.width is not None:
        return float(spec.width)
    return 1.0 / (count - 1) if count > 1 else 1.0


def pack_codes(entries: list[CodeEntry], plane: tuple[float, float]) -> Codes:
    """The compiled coder's table for a list of feature specs (one group each).

    Why 60 lines: one array per line, packed spec by spec."""
    columns: dict[str, list[float]] = {name: [] for name in Codes._fields[:16]}
    thresholds: list[float] = []
    sensor_col: list[int] = []
    low: list[float] = []
    high: list[float] = []
    table: list[int] = []
    table_values: list[float] = []
    basis: list[np.ndarray] = []
    most_inputs = max([1, *(len(e.spec.sensors or []) for e in entries)])
    for entry in entries:
        spec = entry.spec
        rows = basis_rows(spec)
        width = len((spec.table or [[0]])[0])
        values = [1.0] * len(spec.table or []) * width if spec.values is None else [v for r in spec.values for v in r]
        row = {
            "kind": FEATURE_KINDS[spec.kind], "parts": spec.parts, "tilings": spec.tilings, "tiles": spec.tiles,
            "base_n": spec.base_size(), "width": rbf_width(spec) if spec.kind == "rbf" else 1.0,
            "thr_lo": len(thresholds), "thr_hi": len(thresholds) + len(spec.condition.thresholds if spec.condition
                                                                         else []),
            "sensor_lo": len(sensor_col), "sensor_hi": len(sensor_col) + len(spec.sensors or []),
            "table_at": len(table), "table_rows": len(spec.table or []), "table_width": width,
            "table_col": entry.columns.get(spec.sensor or "", -1), "basis_at": sum(len(b) for b in basis),
            "basis_rows": len(rows),
        }  # fmt: skip
        for name, value in row.items():
            columns[name].append(value)
        thresholds.extend(spec.condition.thresholds if spec.condition else [])
        sensor_col.extend(entry.columns[s.sensor] for s in spec.sensors or [])
        low.extend(r[0] for r in entry.ranges)
        high.extend(r[1] for r in entry.ranges)
        table.extend(i for r in spec.table or [] for i in r)
        table_values.extend(values)
        padded = np.zeros((len(rows), most_inputs))
        if len(rows):
            padded[:, : rows.shape[1]] = rows
        basis.append(padded)
    per_group = {name: np.array(columns[name], dtype=float if name == "width" else np.int64)
                 for name in Codes._fields[:16]}  # fmt: skip
    return Codes(
        **per_group,
        thresholds=np.array(thresholds, dtype=float),
        sensor_col=np.array(sensor_col, dtype=np.int64),
        sensor_low=np.array(low, dtype=float),
        sensor_high=np.array(high, dtype=float),
        table=np.array(table or [0], dtype=np.int64),
        table_values=np.array(table_values or [0.0], dtype=float),
        basis=np.concatenate(basis) if sum(len(b) for b in basis) else np.zeros((1, most_inputs)),
        plane_width=float(plane[0]),
        plane_height=float(plane[1]),
    )


class StateCoder:
    """A compiled `FeatureSpec`: maps states (positions, sensors, a condition demon's prediction) to features.

    Attributes:
        n: number of state features (all condition blocks included).
        k: number of active features (the spec's active count; a state may have fewer distinct ones).
        base_n: number of state features of one condition block.
        binary: every active feature has the value 1.
    """

    def __init__(
        self,
        spec: FeatureSpec,
        width: float,
        height: float,
        sensor_names: list[str] | None = None,
        bounds: dict[str, tuple[float, float]] | None = None,
    ) -> None:
        self.spec = spec
        self.base_n = spec.base_size()
        self.k = spec.active_count()
        self.n = spec.state_size()
        self.binary = spec.binary
        self.sensor_names = list(sensor_names or [])
        self.entry = CodeEntry(spec, sensor_names, bounds or {})
        self.codes = pack_codes([self.entry], (width, height))
        self.thresholds = np.asarray(spec.condition.thresholds if spec.condition else [], dtype=float)

    def sparse(
        self,
        x: np.ndarray,
        y: np.ndarray,
        condition: np.ndarray | None = None,
        sensors: np.ndarray | None = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Active state features of a batch of B states.

        Args:
            x, y: [B] positions.
            condition: [B] the condition demon's prediction, required when the spec has a condition.
            sensors: [B, S] the sensor vectors (named by `sensor_names`), required by the kinds over sensors.

        Returns:
            (index [B, k] int64, value [B, k]): each row's active features sorted and distinct, then (0, 0.0)
            where a state has fewer than k (a table that lists an index twice).
        """
        x = np.asarray(x, dtype=float).reshape(-1)
        y = np.asarray(y, dtype=float).reshape(-1)
        batch = len(x)
        if self.spec.kind in ("sensors", "table", "polynomial", "fourier", "rbf", "linear") and sensors is None:
            raise ValueError(f"{self.spec.kind} features need the sensor vectors")
        if len(self.thresholds) and condition is None:
            raise ValueError("conditioned features need the condition demon's prediction")
        rows = np.zeros((batch, 1)) if sensors is None else np.ascontiguousarray(sensors, dtype=float)
        conditions = np.zeros(batch) if condition is None else np.asarray(condition, dtype=float).reshape(-1)
        index = np.zeros((batch, self.k), dtype=np.int64)
        value = np.zeros((batch, self.k))
        inputs = np.zeros(max(1, len(self.spec.sensors or [])))
        taken = np.zeros(self.base_n, np.uint8)
        code_batch(self.codes, 0, x, y, rows, conditions, inputs, taken, index, value, np.zeros(batch, np.int64))
        return index, value

    def active(self, x: np.ndarray, y: np.ndarray, condition: np.ndarray | None = None,
               sensors: np.ndarray | None = None) -> np.ndarray:  # fmt: skip
        """[B, k] the active indices of binary features (`sparse` without the values, which are all 1)."""
        return self.sparse(x, y, condition, sensors)[0]

    def dense(self, x: np.ndarray, y: np.ndarray, condition: np.ndarray | None = None,
              sensors: np.ndarray | None = None) -> np.ndarray:  # fmt: skip
        """[B, n] the feature vectors, dense (what `reference.state_features` gives, one state at a time)."""
        index, value = self.sparse(x, y, condition, sensors)
        out = np.zeros((len(index), self.n))
        np.add.at(out, (np.arange(len(index))[:, None], index), value)
        return out

    def block_of(self, condition: np.ndarray) -> np.ndarray:
        """[B] which condition block a prediction selects (0 below the first threshold)."""
        return np.searchsorted(self.thresholds, np.asarray(condition, dtype=float), side="right")


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
