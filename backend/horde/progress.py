"""A one-line progress bar on a terminal stream, shared by `horde run` and `horde study`."""

from __future__ import annotations

import math
import sys
import time
from typing import TextIO


class ProgressBar:
    """A one-line progress bar on a terminal stream (redrawn at most 10 times a second)."""

    def __init__(self, label: str, stream: TextIO | None = None, width: int = 30, unit: str = "episodes") -> None:
        self.label = label
        self.unit = unit
        self.stream = stream or sys.stderr
        self.width = width
        self.began = time.perf_counter()
        self.last_draw = 0.0
        self.finished = False

    def __call__(self, done: int, total: int) -> None:
        now = time.perf_counter()
        if (done < total and now - self.last_draw < 0.1) or (done >= total and self.finished):
            return
        self.finished = done >= total  # the full bar is drawn once, however often the end is reported
        self.last_draw = now
        fraction = done / total if total else 1.0
        filled = int(self.width * fraction)
        elapsed = now - self.began
        eta = elapsed / fraction - elapsed if fraction > 0 else math.nan
        bar = "#" * filled + "-" * (self.width - filled)
        eta_text = f"{eta:5.0f}s left" if math.isfinite(eta) else "  ...  "
        self.stream.write(f"\r{self.label} [{bar}] {done}/{total} {self.unit}  {elapsed:5.0f}s  {eta_text}")
        if done >= total:
            self.stream.write("\n")
        self.stream.flush()
