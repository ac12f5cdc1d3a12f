"""How many threads a run's step may use: every core when it runs alone, its share when several run.

The block kernels split a block's demons into runs of columns learned by threads without the GIL
(`scale_fast._columns_parallel`); the result does not depend on how many. A process has a budget of
cores (the cores it may run on, or `HORDE_THREADS`, or what `set_budget` gave a worker process) and
a count of the runs that are learning in it at the moment (`Simulation.run` counts itself while it
steps: live runs, protocol jobs, evaluations alike); each run's step takes
`share()` = budget // running runs threads, at least 1, so that two runs on a 2-core machine take one
core each and one run alone takes both.

The threading layer is numba's: TBB when its library is installed (thread- and fork-safe), else
OpenMP. GNU OpenMP is not safe in a process forked after it started its threads, so worker processes
(`core/batch.py`) learn on one thread each unless the layer is TBB.
"""

from __future__ import annotations

import ctypes
import os
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numba

_MAX: int = numba.config.NUMBA_NUM_THREADS  # type: ignore[attr-defined]  # threads numba may start
_lock = threading.Lock()
_running = 0
_budget: int | None = None


def _load_tbb() -> bool:
    """Make numba's TBB layer loadable: pip's `tbb` puts libtbb.so.12 in the environment's lib/, which
    the dynamic loader does not search; load it by path first. Whether the layer is usable."""
    for folder in (Path(sys.prefix) / "lib", Path(sys.base_prefix) / "lib"):
        library = folder / "libtbb.so.12"
        if library.exists():
            try:
                ctypes.CDLL(str(library), mode=ctypes.RTLD_GLOBAL)
            except OSError:
                continue
            break
    try:
        import numba.np.ufunc.tbbpool  # noqa: F401

        return True
    except ImportError:
        return False


LAYER = "tbb" if _load_tbb() else "omp"
if os.environ.get("NUMBA_THREADING_LAYER") is None:
    numba.config.THREADING_LAYER = LAYER  # type: ignore[attr-defined]


def cores() -> int:
    """The cores this process may use (its CPU affinity), or HORDE_THREADS if set."""
    env = os.environ.get("HORDE_THREADS", "")
    if env.isdigit() and int(env) > 0:
        return min(int(env), _MAX)
    try:
        count = len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        count = os.cpu_count() or 1
    return max(1, min(count, _MAX))


def budget() -> int:
    """The threads this process's runs share."""
    return _budget if _budget is not None else cores()


def set_budget(count: int | None) -> None:
    """Give this process `count` threads in all (None: its cores). Worker processes get their share."""
    global _budget
    _budget = None if count is None else max(1, min(int(count), _MAX))


def running_runs() -> int:
    return _running


def share(joining: int = 0) -> int:
    """Threads for one run's step now: the budget divided among the runs learning in this process
    (and `joining` more: a run that asks before it starts counts itself)."""
    return max(1, budget() // max(1, _running + joining))


def enter() -> None:
    """Count one more run learning in this process (`Simulation.run` counts itself while it steps)."""
    global _running
    with _lock:
        _running += 1


def leave() -> None:
    global _running
    with _lock:
        _running -= 1


@contextmanager
def running() -> Iterator[None]:
    """Count a run as learning while the block is open."""
    enter()
    try:
        yield
    finally:
        leave()


def worker_budget(workers: int) -> int:
    """Threads for each of `workers` forked worker processes: their share of the cores under TBB, 1 under
    OpenMP (not safe after a fork)."""
    return max(1, budget() // max(1, workers)) if LAYER == "tbb" else 1
