"""Records of a stream world: checked one by one, learned in order, read from a CSV log at full speed.

A record is what a robot (or a replayed log) sends at every time step t:

    observation   [S] one reading per sensor of the stream world, in its order
    action        the action a_t taken after observing it, in [0, A)
    behaviour_probabilities (optional) [A] b(. | s_t); uniform when left out

The first record is observed (traces start); every later record t completes the transition
(s_{t-1}, a_{t-1}) -> s_t, which the Horde learns with rho_{t-1} = pi(a_{t-1} | s_{t-1}) / b(a_{t-1} | s_{t-1}).
A stream is one continuing episode. A record that is refused (wrong number of sensors, a sensor that
is not a finite number, an action outside the world's actions, behaviour probabilities that are not a
distribution giving the action a positive probability) is reported, naming its field, and not learned;
the next good record is then observed afresh (a transition across a gap would be a transition the world
never made).

A CSV log has a header naming the sensors (every sensor of the world, any order), `action`, and
optionally `b0 .. b{A-1}`; one record per line. A Parquet log (`.parquet`) has columns of the same
names, one record per row; its refusals name the row (from 1) where a CSV log's name the line.
`read_log` yields chunks of checked records.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from horde.core.horde import Horde
from horde.core.learner import Learner
from horde.spec import RunSpec, StreamWorldSpec

Layout = tuple[list[int], int, list[int] | None]  # a log's sensor columns, action column, probability columns


class RecordError(ValueError):
    """A refused record: `field` names what is wrong (observation.<sensor>, action, behaviour_probabilities)."""

    def __init__(self, field: str, message: str) -> None:
        super().__init__(f"{field}: {message}")
        self.field = field
        self.message = message


@dataclass
class Records:
    """Checked records in order: observations [N, S], actions [N], b(a_t | s_t) [N].

    `gaps`: positions g (in these records) before which a refused record came; the stream restarts there.
    """

    observations: np.ndarray
    actions: np.ndarray
    b_probs: np.ndarray
    gaps: list[int] = field(default_factory=list)

    def __len__(self) -> int:
        return len(self.actions)


def stream_world(spec: RunSpec) -> StreamWorldSpec:
    if not isinstance(spec.world, StreamWorldSpec):
        raise ValueError(f"records need a stream world (world.kind = 'stream'), not {spec.world.kind!r}")
    return spec.world


def check_record(world: StreamWorldSpec, record: Any) -> tuple[np.ndarray, int, float]:
    """One record (a mapping) as (observation [S], action, b(action | s)).

    Raises:
        RecordError: naming the field that is wrong.
    """
    if not isinstance(record, dict):
        raise RecordError("record", "a record is an object {observation, action, behaviour_probabilities?}")
    unknown = sorted(set(record) - {"observation", "action", "behaviour_probabilities"})
    if unknown:
        raise RecordError(unknown[0], "unknown field (a record has observation, action, behaviour_probabilities)")
    names = world.sensor_names()
    observation = record.get("observation")
    if not isinstance(observation, list) or len(observation) != len(names):
        count = len(observation) if isinstance(observation, list) else "no list of"
        raise RecordError("observation", f"{count} readings; the stream has {len(names)} sensors ({', '.join(names)})")
    values = np.empty(len(names))
    for i, value in enumerate(observation):
        if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
            raise RecordError(f"observation.{names[i]}", f"{value!r} is not a finite number")
        values[i] = value
    action = record.get("action")
    if isinstance(action, bool) or not isinstance(action, int) or not 0 <= action < world.actions:
        raise RecordError("action", f"{action!r} is not one of the stream's {world.actions} actions (0 to "
                                    f"{world.actions - 1})")  # fmt: skip
    probs = record.get("behaviour_probabilities")
    if probs is None:
        return values, action, 1.0 / world.actions
    if (
        not isinstance(probs, list)
        or len(probs) != world.actions
        or not all(isinstance(p, int | float) and not isinstance(p, bool) and 0.0 <= p <= 1.0 for p in probs)
        or not math.isclose(sum(probs), 1.0, abs_tol=1e-4)
    ):
        raise RecordError(
            "behaviour_probabilities", f"{world.actions} probabilities in [0, 1] summing to 1 (within 1e-4)"
        )
    if probs[action] <= 0.0:
        raise RecordError("behaviour_probabilities", f"the action taken ({action}) has probability 0")
    return values, action, float(probs[action])


@dataclass
class Refusal:
    index: int  # the record's number in the stream (0 = the first record ever sent)
    field: str
    message: str


@dataclass
class RecordLearner:
    """The Horde of a stream world, learning records in order (see the module for the semantics)."""

    spec: RunSpec
    loop: Learner = field(init=False)  # the Horde learning the records
    received: int = 0  # records seen, good or refused
    learned: int = 0  # good records taken in (the first of a run of good records is observed, the rest learned)
    refused: int = 0
    _pending: tuple[int, float] | None = None  # (a_t, b(a_t | s_t)) of the last good record

    def __post_init__(self) -> None:
        self.world = stream_world(self.spec)
        self.loop = Learner(Horde(self.spec))

    def check(self, items: list[Any]) -> tuple[Records, list[Refusal]]:
        """Check raw records (numbered from `received` on); returns the good ones and the refusals."""
        records, refusals = check_records(self.world, items, list(range(self.received, self.received + len(items))))
        self.received += len(items)
        self.refused += len(refusals)
        return records, refusals

    def learn(self, records: Records, keep_predictions: bool = False) -> np.ndarray | None:
        """Learn checked records in order; a gap (a refused record before index g) restarts the stream there.

        Returns:
            with keep_predictions, [N, D] every demon's prediction at each record's observation (after
            learning the transition into it), else None.
        """
        gaps = set(records.gaps)
        kept: list[np.ndarray] = []
        start = 0
        for stop in [*sorted(gaps), len(records)]:
            self._learn_run(records, start, stop, kept if keep_predictions else None)
            if stop in gaps:
                self._pending = None  # the next good record is observed afresh
            start = stop
        if not keep_predictions:
            return None
        return np.concatenate(kept) if kept else np.zeros((0, self.loop.horde.num_demons))

    def _learn_run(self, records: Records, lo: int, hi: int, kept: list[np.ndarray] | None) -> None:
        if hi <= lo:
            return
        if self._pending is None:
            self.loop.observe(records.observations[lo])
            self._pending = (int(records.actions[lo]), float(records.b_probs[lo]))
            self.learned += 1
            if kept is not None:
                kept.append(self.loop.prediction()[None])
            lo += 1
            if hi <= lo:
                return
        actions = np.concatenate([[self._pending[0]], records.actions[lo : hi - 1]])  # a_{t-1} of each row
        probs = np.concatenate([[self._pending[1]], records.b_probs[lo : hi - 1]])
        out = self.loop.learn(records.observations[lo:hi], actions, probs, keep_predictions=kept is not None)
        if kept is not None and out is not None:
            kept.append(out)
        self._pending = (int(records.actions[hi - 1]), float(records.b_probs[hi - 1]))
        self.learned += hi - lo

    def predictions(self) -> np.ndarray:
        """[D] every demon's prediction at the last observation, in demon order."""
        return self.loop.prediction()


def read_log(path: Path, world: StreamWorldSpec, chunk: int = 10_000) -> Iterator[tuple[Records, list[Refusal]]]:
    """Chunks of checked records from a CSV or Parquet log (see the module); refusals name `FILE:LINE: field`
    (`FILE:ROW: field` for Parquet)."""
    if path.suffix.lower() == ".parquet":
        yield from _read_parquet(path, world, chunk)
        return
    with path.open(newline="") as handle:
        reader = csv.reader(handle)
        header = next(reader, None)
        if header is None:
            raise ValueError(f"{path}:1: the log is empty (a header line names the sensors and action)")
        layout = _layout(path, world, [h.strip() for h in header])
        rows: list[list[str]] = []
        first = 2
        for row in reader:
            rows.append(row)
            if len(rows) >= chunk:
                yield _log_chunk(world, rows, first, layout, path)
                first += len(rows)
                rows = []
        if rows:
            yield _log_chunk(world, rows, first, layout, path)


def log_length(path: Path) -> int:
    """The number of records in a CSV log (its lines after the header) or a Parquet log (its rows)."""
    if path.suffix.lower() == ".parquet":
        import pyarrow.parquet as pq

        try:
            return int(pq.ParquetFile(path).metadata.num_rows)
        except Exception as exc:  # pyarrow's ArrowInvalid, OSError
            raise ValueError(f"{path}: not a Parquet file ({exc})") from exc
    with path.open(newline="") as handle:
        return max(sum(1 for _ in handle) - 1, 0)


def _layout(path: Path, world: StreamWorldSpec, header: list[str]) -> Layout:
    """Where a log's sensors, action and (optional) behaviour probabilities are, by the header's names."""
    names = world.sensor_names()
    missing = [n for n in [*names, "action"] if n not in header]
    if missing:
        raise ValueError(f"{path}:1: the header lacks {', '.join(missing)} (it names {', '.join(header)})")
    columns = [header.index(n) for n in names]
    action_column = header.index("action")
    prob_columns = [header.index(f"b{a}") for a in range(world.actions)] if "b0" in header else None
    return columns, action_column, prob_columns


def _read_parquet(path: Path, world: StreamWorldSpec, chunk: int) -> Iterator[tuple[Records, list[Refusal]]]:
    """`read_log` for a Parquet file: its columns by name, read a batch of rows at a time; a missing value
    (null) is refused like an empty CSV cell, naming its column."""
    import pyarrow.parquet as pq  # only when a Parquet log is read: pyarrow takes a while to import

    try:
        log = pq.ParquetFile(path)
    except Exception as exc:  # pyarrow raises its own ArrowInvalid (and OSError) for a file that is no Parquet
        raise ValueError(f"{path}: not a Parquet file ({exc})") from exc
    layout = _layout(path, world, list(log.schema_arrow.names))
    first = 1
    for batch in log.iter_batches(batch_size=chunk):
        columns = [batch.column(i).to_pylist() for i in range(batch.num_columns)]
        rows = [["" if value is None else value for value in row] for row in zip(*columns, strict=True)]
        yield _log_chunk(world, rows, first, layout, path)
        first += len(rows)


def _row_record(row: list[str], layout: tuple[list[int], int, list[int] | None]) -> dict[str, Any]:
    """One CSV row as a record (cells that are not numbers stay text, to be refused naming their column)."""
    columns, action_column, prob_columns = layout
    record: dict[str, Any] = {
        "observation": [_number(row[c]) if c < len(row) else None for c in columns],
        "action": _number(row[action_column]) if action_column < len(row) else None,
    }
    if prob_columns is not None:
        record["behaviour_probabilities"] = [_number(row[c]) if c < len(row) else None for c in prob_columns]
    return record


def _log_chunk(
    world: StreamWorldSpec, rows: list[list[str]], first: int, layout: Layout, path: Path
) -> tuple[Records, list[Refusal]]:
    """Check a chunk of CSV rows (line numbers from `first`): in bulk with numpy, and row by row only where
    the bulk check fails (so that the refusals name the field)."""
    columns, action_column, prob_columns = layout
    lines = list(range(first, first + len(rows)))
    try:
        table = np.array(rows, dtype=float)  # [N, columns]; raises on a ragged row or a cell that is no number
    except ValueError:
        table = None
    if table is not None and table.ndim == 2:
        observations = table[:, columns]  # [N, S]
        actions = table[:, action_column]  # [N]
        good = np.isfinite(observations).all(axis=1) & (actions == np.floor(actions))
        good &= (actions >= 0) & (actions < world.actions)
        whole = np.where(good, actions, 0).astype(np.int64)
        if prob_columns is None:
            probs = np.full(len(rows), 1.0 / world.actions)
        else:
            table_b = table[:, prob_columns]  # [N, A]
            good &= ((table_b >= 0) & (table_b <= 1)).all(axis=1) & (np.abs(table_b.sum(axis=1) - 1) <= 1e-4)
            probs = table_b[np.arange(len(rows)), whole]
            good &= probs > 0
        if good.all():
            return Records(observations, whole, probs), []
    items = [_row_record(row, layout) for row in rows]
    records, refusals = check_records(world, items, lines)
    for refusal in refusals:
        refusal.field = f"{path}:{refusal.index}: {refusal.field}"
    return records, refusals


def _number(text: str) -> float | int | str:
    """A CSV cell as an int (a whole number), a float, or the text itself (refused, naming its column)."""
    try:
        value = float(text)
    except ValueError:
        return text.strip()
    return int(value) if value.is_integer() else value


def check_records(world: StreamWorldSpec, items: list[Any], numbers: list[int]) -> tuple[Records, list[Refusal]]:
    """Check raw records; `numbers` name them in refusals (record indices, or log lines)."""
    observations: list[np.ndarray] = []
    actions: list[int] = []
    probs: list[float] = []
    refusals: list[Refusal] = []
    gaps: list[int] = []
    for item, number in zip(items, numbers, strict=True):
        try:
            o, a, b = check_record(world, item)
        except RecordError as exc:
            refusals.append(Refusal(number, exc.field, exc.message))
            gaps.append(len(actions))
            continue
        observations.append(o)
        actions.append(a)
        probs.append(b)
    records = Records(np.array(observations).reshape(-1, len(world.sensors)), np.array(actions, dtype=np.int64),
                      np.array(probs, dtype=float), gaps)  # fmt: skip
    return records, refusals
