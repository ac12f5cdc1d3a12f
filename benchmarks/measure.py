"""Timing, memory and memory-bandwidth helpers for the benchmarks.

Every figure is measured in the running process, so that ratios (to the reference, to the bandwidth)
compare like with like on a machine that other work may be sharing. Times are wall-clock medians over
many steps after a warm-up; the process's CPU time is kept beside them, and a CPU time well below the
wall time means the machine was busy with something else.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Timing:
    """Median seconds per step (wall and this thread's CPU) over `steps` timed steps."""

    wall: float
    cpu: float
    steps: int


def time_steps(step: Callable[[int], object], first: int, count: int, per_call: int = 1) -> Timing:
    """Call `step(t)` for t = first .. first + count - 1, timing each call; `per_call` steps per call.
    CPU time is the process's (every thread a step uses; the benchmark runs nothing else meanwhile)."""
    walls, cpus = [], []
    for t in range(first, first + count):
        w0, c0 = time.perf_counter(), time.process_time()
        step(t)
        walls.append(time.perf_counter() - w0)
        cpus.append(time.process_time() - c0)
    return Timing(float(np.median(walls)) / per_call, float(np.median(cpus)) / per_call, count * per_call)


def time_alternating(
    step: Callable[[int], object],
    setups: Sequence[Callable[[], object]],
    count: int,
    per_call: int = 1,
    rounds: int = 4,
) -> list[Timing]:
    """`time_steps` under each of `setups` (say, a thread count), in `rounds` alternating rounds of
    count / rounds calls, so that a change in the machine's load falls on every setup alike."""
    walls: list[list[float]] = [[] for _ in setups]
    cpus: list[list[float]] = [[] for _ in setups]
    per_round = max(1, count // rounds)
    for _ in range(rounds):
        for i, setup in enumerate(setups):
            setup()
            timing = time_steps(step, 0, per_round, per_call)
            walls[i].append(timing.wall)
            cpus[i].append(timing.cpu)
    return [Timing(float(np.median(w)), float(np.median(c)), per_round * rounds * per_call)
            for w, c in zip(walls, cpus, strict=True)]  # fmt: skip


@dataclass(frozen=True)
class Bandwidth:
    """This machine's memory bandwidth from one core, in bytes per second, measured three ways on a
    large array (bytes counted once per read and once per write)."""

    copy: float  # numpy copyto: read one array, write another
    update: float  # a += 1.0: read and write the same array (the pattern of theta += ...)
    read: float  # a.sum(): read only
    megabytes: int

    @property
    def best(self) -> float:
        """The largest of the three: the denominator of `bandwidth_fraction`."""
        return max(self.copy, self.update, self.read)


def bandwidth(megabytes: int = 512, repeats: int = 5) -> Bandwidth:
    """Best-of-`repeats` bandwidth of numpy operations on a `megabytes` float64 array (far beyond caches)."""
    a = np.ones(megabytes * 2**20 // 8)
    b = np.ones_like(a)
    size = a.nbytes

    def best(operation: Callable[[], object], bytes_moved: int) -> float:
        operation()
        seconds = []
        for _ in range(repeats):
            start = time.perf_counter()
            operation()
            seconds.append(time.perf_counter() - start)
        return bytes_moved / min(seconds)

    result = Bandwidth(
        copy=best(lambda: np.copyto(b, a), 2 * size),
        update=best(lambda: np.add(a, 1.0, out=a), 2 * size),
        read=best(lambda: a.sum(), size),
        megabytes=megabytes,
    )
    return result


def rss_bytes() -> int:
    """The resident memory of this process now (Linux /proc; 0 elsewhere)."""
    try:
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError):
        return 0
