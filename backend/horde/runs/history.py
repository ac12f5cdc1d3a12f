"""Per-demon time series of a run (prediction, cumulant, delta, RUPEE, UDE; RMSVE and RMSPBE on a world of
discrete states with known transitions) in a bounded ring buffer.

The learner thread records; request threads read copies. One lock guards the buffer, held only for
a row write or a copy, so readers never slow learning down noticeably.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass

import numpy as np

from horde.spec import RunSpec
from horde.worlds.state_values import has_model

QUANTITIES: tuple[str, ...] = ("prediction", "cumulant", "delta", "rupee", "ude")
# Recorded beside QUANTITIES where the world's states are discrete and its transitions known (the chains, Baird's
# star: `horde.worlds.state_values.StateErrors`); elsewhere they are absent, not 0.
STATE_ERRORS: tuple[str, ...] = ("rmsve", "rmspbe")
ALL_QUANTITIES: tuple[str, ...] = QUANTITIES + STATE_ERRORS
# At most this many numbers per run (rows x demons x quantities), whatever the capacity asks for.
BUDGET = 5_000_000


def quantities_of(spec: RunSpec) -> tuple[str, ...]:
    """What a history row of a run of this spec holds: ALL_QUANTITIES where its world has discrete states with
    known transitions, else QUANTITIES."""
    return ALL_QUANTITIES if has_model(spec) else QUANTITIES


@dataclass(frozen=True)
class Series:
    """One demon's history, oldest first."""

    steps: np.ndarray  # [T] int: the run's step count when each row was recorded
    values: dict[str, np.ndarray]  # quantity -> [T], the history's quantities only


class History:
    """A ring buffer of `rows` samples of every quantity for every demon.

    Args:
        names: the demons, in the Horde's order.
        capacity: rows asked for (reduced to fit `BUDGET` when there are many demons).
        every: at least this many steps between two rows.
        quantities: what a row holds (QUANTITIES, or ALL_QUANTITIES on a world with state errors).
    """

    def __init__(self, names: list[str], capacity: int, every: int = 1,
                 quantities: tuple[str, ...] = QUANTITIES) -> None:  # fmt: skip
        self.names = list(names)
        self.every = max(1, every)
        self.quantities = quantities
        width = max(1, len(self.names)) * len(quantities)
        self.rows = max(16, min(capacity, BUDGET // width))
        self._lock = threading.Lock()
        self._steps = np.zeros(self.rows, dtype=np.int64)  # [T]
        self._data = np.full((len(quantities), self.rows, len(self.names)), np.nan)  # [Q, T, D]
        self._count = 0  # rows written so far (the next row goes to count % rows)

    def record(self, step: int, *values: np.ndarray) -> None:
        """Write one row: `values` are [D] arrays in the order of `quantities`."""
        with self._lock:
            row = self._count % self.rows
            self._steps[row] = step
            for q, value in enumerate(values):
                self._data[q, row] = value
            self._count += 1

    def series(self, name: str, limit: int | None = None) -> Series:
        """The last `limit` rows (default all kept) of one demon.

        Raises:
            KeyError: an unknown demon.
        """
        column = self.names.index(name) if name in self.names else None
        if column is None:
            raise KeyError(name)
        with self._lock:
            kept = min(self._count, self.rows)
            order = (np.arange(self._count - kept, self._count) % self.rows)[-limit if limit else 0 :]  # [T]
            steps = self._steps[order].copy()
            values = {q: self._data[i, order, column].copy() for i, q in enumerate(self.quantities)}
        return Series(steps, values)

    def remap(self, names: list[str]) -> History:
        """A history for a new set of demons that keeps the rows of every demon still present."""
        new = History(names, self.rows, self.every, self.quantities)
        with self._lock:
            kept = min(self._count, self.rows, new.rows)
            order = np.arange(self._count - kept, self._count) % self.rows  # [T]
            new._steps[:kept] = self._steps[order]
            for column, name in enumerate(names):
                if name in self.names:
                    new._data[:, :kept, column] = self._data[:, order, self.names.index(name)]
            new._count = kept
        return new
