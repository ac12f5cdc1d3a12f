"""Independent trials of a protocol, side by side in worker processes.

Each trial of `experiment.run_trial` learns from scratch with its own generator, seeded from the run
seed and the trial number, so trials share nothing and can run at once. The thesis-scale loop is
already one compiled call per many episodes (`engine/loop.py`); what is left to win is the machine's other cores.
`run_trials_batched` hands the trials to a process pool and returns exactly what single-trial runs of
`run_trial` with the same seeds return (the tests compare them); with one worker, or one trial, it
runs them in this process. By default it takes this process's share of the cores (`threads.share`: every
core when nothing else learns in the process, `HORDE_THREADS` to cap it). Workers report their episodes
as they go, so that a progress bar moves while the first trials are under way.
"""

from __future__ import annotations

import multiprocessing
import queue
import time
from collections.abc import Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from typing import Any

from horde.core import threads
from horde.core.experiment import Progress, ProtocolResult, TrialResult, run_trial, summarize
from horde.spec import RunSpec

POLL_SECONDS = 0.2  # how often the parent reads the workers' progress while it waits
_progress_queue: Any = None  # a worker's queue of (trial, episodes done), set by `_start_worker`


def default_workers(trials: int) -> int:
    """Processes for `trials` trials: this process's share of the cores (`threads.share`), at most one a trial."""
    return max(1, min(threads.share(1), trials))


def warm_up(spec: RunSpec) -> None:
    """Load (or compile) the engine's kernels in this process by running a one-episode trial of the spec with a
    few short rollouts: forked workers inherit them, instead of each loading or compiling its own copy (on a
    cold numba cache each worker would compile the loop, about a minute of CPU each)."""
    protocol = spec.protocol
    tiny = protocol.model_copy(
        update={
            "trials": 1,
            "episodes": min(1, protocol.episodes),
            "stop": None,
            "evaluation": protocol.evaluation.model_copy(update={"rollouts": min(2, protocol.evaluation.rollouts),
                                                                 "cap": min(5, protocol.evaluation.cap)}),
            "test": protocol.test.model_copy(update={"runs": 1}) if protocol.test is not None else None,
        }
    )  # fmt: skip
    run_trial(spec.model_copy(update={"protocol": tiny}), 0)


def _start_worker(budget: int, progress_queue: Any) -> None:
    global _progress_queue
    threads.set_budget(budget)
    _progress_queue = progress_queue


def _trial_in_worker(spec: RunSpec, trial: int) -> TrialResult:
    """`run_trial` in a worker process, telling the parent how many episodes it has learned."""
    sink = _progress_queue

    def report(episodes: int) -> None:
        if sink is not None:
            sink.put((trial, episodes))

    return run_trial(spec, trial, report)


def run_trials_batched(
    spec: RunSpec,
    trials: Sequence[int] | None = None,
    workers: int | None = None,
    progress: Progress | None = None,
) -> list[TrialResult]:
    """Run trials of the spec's protocol at once, each exactly as `run_trial(spec, trial)` would.

    Args:
        spec: the run spec.
        trials: which trial numbers (default: all of the protocol's).
        workers: processes (default: `default_workers`; 1 runs in this process).
        progress: called with (episodes done, episodes in all) as the trials learn.

    Returns:
        The trial results, in the order of `trials`.
    """
    numbers = list(range(spec.protocol.trials)) if trials is None else list(trials)
    count = max(1, len(numbers))
    workers = default_workers(count) if workers is None else min(max(1, workers), count)
    episodes = spec.protocol.episodes
    total = len(numbers) * episodes
    if workers == 1:
        results = []
        for done, trial in enumerate(numbers):

            def report(learned: int, before: int = done * episodes) -> None:
                if progress:
                    progress(before + learned, total)

            results.append(run_trial(spec, trial, report))
            if progress:
                progress((done + 1) * episodes, total)
        return results
    # fork where the platform has it: the children inherit the imported engine, its kernels loaded
    method = "fork" if "fork" in multiprocessing.get_all_start_methods() else None
    if method == "fork":
        warm_up(spec)
    context = multiprocessing.get_context(method)
    learned = dict.fromkeys(numbers, 0)  # episodes each trial has learned, as its worker reports them
    out: dict[int, TrialResult] = {}
    sink = context.Queue() if progress else None
    # each worker learns on its share of the cores (one thread unless numba's layer is fork-safe TBB)
    with ProcessPoolExecutor(max_workers=workers, mp_context=context, initializer=_start_worker,
                             initargs=(threads.worker_budget(workers), sink)) as pool:  # fmt: skip
        futures: dict[Future[TrialResult], int] = {pool.submit(_trial_in_worker, spec, t): t for t in numbers}
        pending = set(futures)
        while pending:
            finished, pending = wait(pending, timeout=POLL_SECONDS, return_when=FIRST_COMPLETED)
            for future in finished:
                trial = futures[future]
                out[trial] = future.result()
                learned[trial] = episodes
            if progress and sink is not None:
                _drain(sink, learned, out)
                progress(sum(learned.values()), total)
    return [out[trial] for trial in numbers]


def _drain(sink: Any, learned: dict[int, int], finished: dict[int, TrialResult]) -> None:
    """Read the workers' reports without waiting; a finished trial keeps its full count."""
    while True:
        try:
            trial, episodes = sink.get_nowait()
        except queue.Empty:
            return
        if trial not in finished:
            learned[trial] = max(learned[trial], episodes)


def run_protocol_batched(spec: RunSpec, workers: int | None = None, progress: Progress | None = None) -> ProtocolResult:
    """`experiment.run_protocol` with its trials run by `run_trials_batched`: the same result, sooner."""
    began = time.perf_counter()
    trials = run_trials_batched(spec, workers=workers, progress=progress)
    return summarize(spec, trials, time.perf_counter() - began)
