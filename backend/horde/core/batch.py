"""Independent trials of a protocol, side by side in worker processes.

Each trial of `experiment.run_trial` learns from scratch with its own generator, seeded from the run
seed and the trial number, so trials share nothing and can run at once. The thesis-scale loop is
already one compiled call per episode (`fast.py`); what is left to win is the machine's other cores.
`run_trials_batched` hands the trials to a process pool and returns exactly what single-trial runs of
`run_trial` with the same seeds return (the tests compare them); with one worker, or one trial, it
runs them in this process.
"""

from __future__ import annotations

import multiprocessing
import os
import time
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed

from horde.core import threads
from horde.core.experiment import Progress, ProtocolResult, TrialResult, run_trial, summarize
from horde.spec import RunSpec


def default_workers() -> int:
    """The cores this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not Linux
        return max(1, os.cpu_count() or 1)


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
        workers: processes (default: the usable cores; 1 runs in this process).
        progress: called with (episodes done, episodes in all) as trials finish.

    Returns:
        The trial results, in the order of `trials`.
    """
    numbers = list(range(spec.protocol.trials)) if trials is None else list(trials)
    workers = min(default_workers() if workers is None else max(1, workers), max(1, len(numbers)))
    episodes = spec.protocol.episodes
    total = len(numbers) * episodes
    if workers == 1:
        results = []
        for done, trial in enumerate(numbers):
            results.append(run_trial(spec, trial))
            if progress:
                progress((done + 1) * episodes, total)
        return results
    # fork where the platform has it: the children inherit the imported, compiled engine
    method = "fork" if "fork" in multiprocessing.get_all_start_methods() else None
    context = multiprocessing.get_context(method)
    out: dict[int, TrialResult] = {}
    # each worker learns on its share of the cores (one thread unless numba's layer is fork-safe TBB)
    share = (threads.worker_budget(workers),)
    with ProcessPoolExecutor(max_workers=workers, mp_context=context, initializer=threads.set_budget,
                             initargs=share) as pool:  # fmt: skip
        futures = {pool.submit(run_trial, spec, trial): trial for trial in numbers}
        for future in as_completed(futures):
            out[futures[future]] = future.result()
            if progress:
                progress(len(out) * episodes, total)
    return [out[trial] for trial in numbers]


def run_protocol_batched(spec: RunSpec, workers: int | None = None, progress: Progress | None = None) -> ProtocolResult:
    """`experiment.run_protocol` with its trials run by `run_trials_batched`: the same result, sooner."""
    began = time.perf_counter()
    trials = run_trials_batched(spec, workers=workers, progress=progress)
    return summarize(spec, trials, time.perf_counter() - began)
