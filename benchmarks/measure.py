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

import numba
import numpy as np
from numba import njit, prange


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
    """This machine's memory bandwidth, in bytes per second, measured on a large array.

    `copy`, `update` and `read` are numpy's on one core, counting a byte once when read and once when
    written (an update moves each byte twice). `in_place[t - 1]` is an in-place update (`a += 1`, the
    pattern of `theta += ...`) on t threads counting each byte once; the bench doubles it to count bytes read
    plus bytes written, its one convention (`bound.py`)."""

    copy: float  # numpy copyto: read one array, write another
    update: float  # a += 1.0 by numpy, bytes read plus bytes written
    read: float  # a.sum(): read only
    megabytes: int
    in_place: tuple[float, ...] = ()  # unique bytes per second of a += 1 on 1, 2, ... threads

    @property
    def best(self) -> float:
        """The largest of numpy's three."""
        return max(self.copy, self.update, self.read)

    def for_threads(self, threads: int) -> float:
        """Unique bytes per second of an in-place update on `threads` threads (the most measured, if more)."""
        return self.in_place[min(threads, len(self.in_place)) - 1]


@njit(parallel=True, cache=True)
def _add_one(a: np.ndarray, runs: int) -> None:
    """a += 1, in `runs` contiguous runs, one per thread, each a plain loop over unsigned offsets (so that it
    vectorizes). A prange over the elements themselves moved 21.6 GB/s read plus written on one thread and 42.3 on
    two where this, numpy's `a += 1` and a plain compiled loop move 34 to 36 and 64 to 66 (docs/performance.md,
    "Two rows at once"): every bound fraction measured with it came out about 1.6 times too high."""
    n = a.shape[0]
    width = (n + runs - 1) // runs
    for t in prange(runs):
        for i in range(min(t * width, n), min(t * width + width, n)):
            a[np.uint64(i)] += 1.0


def bandwidth(megabytes: int = 512, repeats: int = 5, threads: int = 1) -> Bandwidth:
    """Best-of-`repeats` bandwidth of numpy operations on a `megabytes` float64 array (far beyond caches),
    and of a compiled in-place update on 1 .. `threads` threads."""
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

    in_place = []
    before = numba.get_num_threads()
    try:
        for t in range(1, max(1, min(threads, numba.config.NUMBA_NUM_THREADS)) + 1):
            numba.set_num_threads(t)
            in_place.append(best(lambda runs=t: _add_one(a, runs), size))
    finally:
        numba.set_num_threads(before)
    return Bandwidth(
        copy=best(lambda: np.copyto(b, a), 2 * size),
        update=best(lambda: np.add(a, 1.0, out=a), 2 * size),
        read=best(lambda: a.sum(), size),
        megabytes=megabytes,
        in_place=tuple(in_place),
    )


def rss_bytes() -> int:
    """The resident memory of this process now (Linux /proc; 0 elsewhere)."""
    try:
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError):
        return 0
