"""TD's read of its values at x_{t+1}, with and without the feature values (issue 29, docs/performance.md).

    python -m benchmarks.valued_read

TD's valued read of issue 29 (`read_in_pairs` below, each row multiplied by its feature's value; the engine
dropped it in issue 27, when TD's read joined its one pass) against the same loop adding the rows
as the kernel did before features carried values, at nexting scale (457 active rows of 6065, 8000 demons), in
one process, alternated rounds of 50 calls each; prints the median and best CPU milliseconds a call.
"""

from __future__ import annotations

import resource
import statistics

import numpy as np
from numba import njit

from horde.core.engine.rows import at


@njit(cache=True)
def read_in_pairs(flat, start, x, v, db, acc):  # type: ignore[no-untyped-def]
    """acc = sum_j v[j] * row x[j], two rows at a time (TD's read of its new values in issue 29)."""
    width = acc.shape[0]
    for i in range(width):
        acc[i] = 0.0
    k = x.shape[0]
    j = 0
    while j + 1 < k:
        u0 = at(start + x[j] * db)
        u1 = at(start + x[j + 1] * db)
        v0, v1 = v[j], v[j + 1]
        for i in range(width):
            acc[i] += v0 * flat[u0 + at(i)] + v1 * flat[u1 + at(i)]
        j += 2
    if j < k:
        u0 = at(start + x[j] * db)
        v0 = v[j]
        for i in range(width):
            acc[i] += v0 * flat[u0 + at(i)]


@njit(cache=True)
def added(flat, start, x, db, acc):  # type: ignore[no-untyped-def]
    """The read before issue 29: acc = the sum of the rows x, two at a time."""
    width = acc.shape[0]
    for i in range(width):
        acc[i] = 0.0
    k = x.shape[0]
    j = 0
    while j + 1 < k:
        u0 = at(start + x[j] * db)
        u1 = at(start + x[j + 1] * db)
        for i in range(width):
            acc[i] += flat[u0 + at(i)] + flat[u1 + at(i)]
        j += 2
    if j < k:
        u0 = at(start + x[j] * db)
        for i in range(width):
            acc[i] += flat[u0 + at(i)]


def cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def main(rows: int = 6065, demons: int = 8000, active: int = 457, rounds: int = 10, calls: int = 50) -> None:
    rng = np.random.default_rng(0)
    flat = rng.standard_normal(rows * demons)
    x = np.sort(rng.choice(rows, active, replace=False)).astype(np.int64)
    v = np.ones(active)
    acc = np.zeros(demons)
    kernels = {
        "valued": lambda: read_in_pairs(flat, 0, x, v, demons, acc),
        "added": lambda: added(flat, 0, x, demons, acc),
    }
    for run in kernels.values():
        run()
    times: dict[str, list[float]] = {name: [] for name in kernels}
    for r in range(rounds):
        for name in list(kernels) if r % 2 == 0 else list(kernels)[::-1]:
            start = cpu()
            for _ in range(calls):
                kernels[name]()
            times[name].append((cpu() - start) / calls * 1e3)
    for name, ms in times.items():
        print(f"{name}: {statistics.median(ms):.3f} ms a call (median of {rounds}), best {min(ms):.3f}")


if __name__ == "__main__":
    main()
