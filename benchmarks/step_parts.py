"""Where a nexting TD step's time goes: the step, and its walk over the weight rows alone.

    python -m benchmarks.step_parts [--demons 8000] [--rounds 2]

A nexting TD Horde (`benchmarks.workloads`) is stepped on one thread in float64 and in float32 (150 steps to warm
up, then the best of five timings of 40 steps); then `td_pass.walk`, the step's one pass over the support's rows
and x_{t+1}'s, is timed alone on the engine's own arrays (x_{t+1} taken as the current features: a row set of its
size, mostly in the support). What is left, the step minus the walk, is the work the walk does not do: the features'
coding, the TD errors, values, predictions, continuations and cumulants per demon, the divergence check, the
traces' merge. It is the same in both dtypes (the per-demon numbers are float64 in both), so it bounds how much
faster a float32 step can be, and, run on one thread but for the TD errors, how much two threads can gain
(docs/performance.md, "Two rows at once, and the machine's rate corrected").
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from benchmarks import workloads
from horde.core.engine.layout import Step
from horde.core.learners import td_pass
from horde.core.simulation import Simulation
from horde.spec import RunSpec


def best_of(operation, repeats: int = 5, count: int = 40) -> float:
    """The best of `repeats` timings of `count` calls, in ms a call."""
    operation()
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        for _ in range(count):
            operation()
        best = min(best, (time.perf_counter() - start) / count)
    return 1e3 * best


def measure(demons: int, dtype: str) -> tuple[float, float]:
    """A nexting TD step and its walk alone, ms, one thread."""
    data = workloads.spec("nexting", demons, "td").model_dump(by_alias=True)
    data["learning"]["dtype"] = dtype
    sim = Simulation(RunSpec.model_validate(data), np.random.default_rng(0))
    sim.with_metrics = False
    sim.threads = 1
    sim.run(150)
    step = best_of(lambda: sim.run(40), count=1) / 40  # (one call of 40 steps: a call's own cost spread thin)
    t = sim.learner.engine.t
    count = int(t.coded.counts[0])
    x, v = t.coded.features[0, :count].copy(), t.coded.values[0, :count].copy()
    stp = Step(x, v, x, v, 0, 0.25, 0)
    width = int(t.lay.block_hi[0] - t.lay.block_lo[0])
    walk = best_of(lambda: td_pass.walk(0, 0, width, t.lay, t.wts, stp, t.scr, False))
    return step, walk


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--demons", type=int, default=8000)
    parser.add_argument("--rounds", type=int, default=2)
    args = parser.parse_args()
    print("| round | dtype | step ms | walk alone ms | the rest ms |\n|---|---|---|---|---|")
    for round_ in range(1, args.rounds + 1):
        for dtype in ("float64", "float32"):
            step, walk = measure(args.demons, dtype)
            print(f"| {round_} | {dtype} | {step:.3f} | {walk:.3f} | {step - walk:.3f} |", flush=True)


if __name__ == "__main__":
    main()
