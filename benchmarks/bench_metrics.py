"""What RUPEE and UDE cost in a nexting step, on one thread and on the run's threads.

`horde bench` times the learning step with the metrics off (as protocols run). A live run keeps them on:
`fast._metrics` updates RUPEE's h and average of delta e (one pass over each trace's support and the
active rows, per demon) and UDE's averages. This script steps the nexting workload of `horde bench`
(`workloads.spec("nexting", D, learner)`) through a bare `Simulation` in four setups, alternated in rounds
in one process so that the machine's load falls on each alike: metrics off and on, on one thread and on
the run's share of the cores (`Simulation.threads`). It prints the wall and CPU milliseconds per step of
each and the metrics' share of a step.

Run: `python -m benchmarks.bench_metrics [--demons 8000] [--learner td] [--steps 200] [--json PATH]`.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np

from benchmarks import measure, workloads
from horde.core.simulation import Simulation


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--demons", type=int, default=8000)
    parser.add_argument("--learner", default="td", choices=["td", "gtd"])
    parser.add_argument("--steps", type=int, default=200, help="timed steps per setup")
    parser.add_argument("--warmup", type=int, default=150)
    parser.add_argument("--json", metavar="PATH")
    args = parser.parse_args(argv)

    sim = Simulation(workloads.spec("nexting", args.demons, args.learner), np.random.default_rng(0))
    sim.run(args.warmup)  # traces reach their working size; the kernels are loaded
    cores = sim.threads

    def setup(metrics: bool, threads: int | None) -> Callable[[], None]:
        def apply() -> None:
            sim.with_metrics = metrics
            sim.threads = threads

        return apply

    setups = {
        "metrics off, 1 thread": setup(False, 1),
        "metrics on, 1 thread": setup(True, 1),
        f"metrics off, {cores} threads": setup(False, None),
        f"metrics on, {cores} threads": setup(True, None),
    }
    chunk = 5
    timings = measure.time_alternating(lambda t: sim.run(chunk), list(setups.values()), args.steps // chunk, chunk)
    rows = {name: {"wall_ms": 1e3 * t.wall, "cpu_ms": 1e3 * t.cpu} for name, t in zip(setups, timings, strict=True)}
    print(f"nexting, {args.demons} {args.learner} demons, {cores} threads available; ms per step (median)")
    for name, row in rows.items():
        print(f"  {name:28s} wall {row['wall_ms']:8.3f}  cpu {row['cpu_ms']:8.3f}")
    for count in (1, cores):
        label = f"{count} thread" + ("s" if count > 1 else "")
        on, off = rows[f"metrics on, {label}"], rows[f"metrics off, {label}"]
        print(f"  metrics on {label}: +{on['wall_ms'] - off['wall_ms']:.3f} ms wall, "
              f"+{on['cpu_ms'] - off['cpu_ms']:.3f} ms cpu per step")  # fmt: skip
    if args.json:
        Path(args.json).write_text(json.dumps({"demons": args.demons, "learner": args.learner, "threads": cores,
                                               "rows": rows}, indent=2) + "\n")  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
