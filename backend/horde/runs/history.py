"""Per-demon time series of a run (prediction, cumulant, delta, RUPEE, UDE) in a bounded ring buffer.

The learner thread records; request threads read copies. One lock guards the buffer, held only for
a row write or a copy, so readers never slow learning down noticeably.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass

import numpy as np

QUANTITIES: tuple[str, ...] = ("prediction", "cumulant", "delta", "rupee", "ude")
# At most this many numbers per run (rows x demons x quantities), whatever the capacity asks for.
BUDGET = 5_000_000


@dataclass(frozen=True)
class Series:
    """One demon's history, oldest first."""

    steps: np.ndarray  # [T] int: the run's step count when each row was recorded
    values: dict[str, np.ndarray]  # quantity -> [T]


class History:
    """A ring buffer of `rows` samples of every quantity for every demon.

    Args:
        names: the demons, in the Horde's order.
        capacity: rows asked for (reduced to fit `BUDGET` when there are many demons).
        every: at least this many steps between two rows.
    """

    def __init__(self, names: list[str], capacity: int, every: int = 1) -> None:
        self.names = list(names)
        self.every = max(1, every)
        width = max(1, len(self.names)) * len(QUANTITIES)
        self.rows = max(16, min(capacity, BUDGET // width))
        self._lock = threading.Lock()
        self._steps = np.zeros(self.rows, dtype=np.int64)  # [T]
        self._data = np.full((len(QUANTITIES), self.rows, len(self.names)), np.nan)  # [Q, T, D]
        self._count = 0  # rows written so far (the next row goes to count % rows)

    def record(self, step: int, *values: np.ndarray) -> None:
        """Write one row: `values` are [D] arrays in the order of QUANTITIES."""
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
            values = {q: self._data[i, order, column].copy() for i, q in enumerate(QUANTITIES)}
        return Series(steps, values)

    def remap(self, names: list[str]) -> History:
        """A history for a new set of demons that keeps the rows of every demon still present."""
        new = History(names, self.rows, self.every)
        with self._lock:
            kept = min(self._count, self.rows, new.rows)
            order = np.arange(self._count - kept, self._count) % self.rows  # [T]
            new._steps[:kept] = self._steps[order]
            for column, name in enumerate(names):
                if name in self.names:
                    new._data[:, :kept, column] = self._data[:, order, self.names.index(name)]
            new._count = kept
        return new
