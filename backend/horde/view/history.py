"""`Ring`: the last T samples of every demon's prediction and RUPEE, in preallocated arrays."""

from __future__ import annotations

import numpy as np


class Ring:
    """A fixed-size ring of (step, predictions [D], RUPEE [D]) samples; not thread-safe.

    Args:
        length: T, the samples kept.
        num_demons: D.
    """

    def __init__(self, length: int, num_demons: int) -> None:
        self.steps = np.zeros(length, dtype=np.int64)  # [T]
        self.predictions = np.zeros((length, num_demons))  # [T, D]
        self.rupee = np.zeros((length, num_demons))  # [T, D]
        self.count = 0  # samples ever appended

    def append(self, step: int, predictions: np.ndarray, rupee: np.ndarray) -> None:
        row = self.count % len(self.steps)
        self.steps[row] = step
        self.predictions[row] = predictions
        self.rupee[row] = rupee
        self.count += 1

    def columns(self, demons: list[int]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Copies, oldest first: steps [t], predictions [t, d] and RUPEE [t, d] of the given demons."""
        length = len(self.steps)
        full = self.count > length
        order = (np.arange(length) + self.count) % length if full else np.arange(self.count)  # oldest first
        return self.steps[order], self.predictions[order][:, demons], self.rupee[order][:, demons]
