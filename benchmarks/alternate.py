"""Two source trees timed on `horde bench`'s workloads in alternated rounds: before and after a change.

    python -m benchmarks.alternate --before /tmp/engine-before [--rounds 3] [--only nexting:8000:td ...]

Each measurement is a fresh process (`python -c`, the tree's `backend/` first on PYTHONPATH) that builds the
workload's `Simulation` (the same `benchmarks.workloads` / `benchmarks.thesis` specs for both trees, from this
checkout), warms it up (the kernels load from numba's cache after the tree's first run) and times steps on one
thread: the best of three timings, in steps per CPU second (the process's user + system time) and per wall
second. Rounds alternate the trees (before, after, before, after, ...), so that a change in a shared
machine's load falls on both; the table gives each tree's median over the rounds and their ratio, with the
load average at the start and the end. Used for docs/performance.md's issue 29 table.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parents[1]
# (workload, demons, learner, timed steps per timing): the learners of `horde bench`'s full plan
WORKLOADS = (
    ("thesis", 2, "gq+gtd", 100_000),
    ("thesis", 100, "gq+gtd", 20_000),
    ("nexting", 100, "td", 2000),
    ("nexting", 8000, "td", 40),
    ("nexting", 8000, "gtd", 30),
    ("nexting", 8000, "true_online_td", 40),
    ("nexting", 8000, "etd", 40),
    ("nexting", 8000, "td+autostep", 20),
    ("nexting", 8000, "td+tidbd", 20),
    ("nexting", 8000, "true_online_gtd", 20),
    ("off_policy", 8000, "gtd", 30),
    ("control", 2000, "gq", 20),
)
# learners the tree before the change does not have (issue 29's TDRC; issue 25's GTD2 and original GTD)
NEW_ONLY = (("nexting", 8000, "tdrc", 30), ("nexting", 8000, "gtd2", 30), ("nexting", 8000, "gtd1", 30))

SNIPPET = """
import json, resource, sys, time
import numpy as np
sys.path.insert(1, {here!r})
workload, demons, learner, steps = {args!r}
from horde.core.simulation import Simulation
if workload == "thesis":
    from benchmarks import thesis
    sim = thesis.simulation(demons)
else:
    from benchmarks import workloads
    sim = Simulation(workloads.spec(workload, demons, learner), np.random.default_rng(0))
    sim.with_metrics = False
sim.threads = 1
sim.run(max(20, min(150, steps)))
def cpu():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime
best_cpu = best_wall = 0.0
for _ in range(3):
    c0, w0 = cpu(), time.perf_counter()
    sim.run(steps)
    best_cpu = max(best_cpu, steps / (cpu() - c0))
    best_wall = max(best_wall, steps / (time.perf_counter() - w0))
print(json.dumps({{"cpu": best_cpu, "wall": best_wall}}))
"""


def measure(tree: Path, workload: tuple[str, int, str, int], timeout: float) -> dict[str, float]:
    """One fresh process of `tree` timing `workload` (see the module)."""
    env = {**os.environ, "PYTHONPATH": str(tree / "backend"), "HORDE_THREADS": "1"}
    code = SNIPPET.format(here=str(HERE), args=workload)
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=timeout,
                         check=True)  # fmt: skip
    return dict(json.loads(out.stdout.strip().splitlines()[-1]))


def load() -> float:
    return os.getloadavg()[0]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--before", type=Path, required=True, help="the tree before the change (a git worktree)")
    parser.add_argument("--after", type=Path, default=HERE, help="the tree after (default: this checkout)")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--only", action="append", default=[], help="workload:demons:learner (repeatable)")
    parser.add_argument("--json", type=Path, help="also write the measurements as JSON")
    parser.add_argument("--timeout", type=float, default=1800.0, help="seconds one measurement may take")
    args = parser.parse_args(argv)
    chosen = [w for w in WORKLOADS + NEW_ONLY if not args.only or f"{w[0]}:{w[1]}:{w[2]}" in args.only]
    results: dict[str, dict[str, list[dict[str, float]]]] = {}
    began = load()
    for workload in chosen:
        key = f"{workload[0]} {workload[1]} {workload[2]}"
        trees = [("after", args.after)] if workload in NEW_ONLY else [("before", args.before), ("after", args.after)]
        results[key] = {name: [] for name, _ in trees}
        for r in range(args.rounds):
            for name, tree in trees if r % 2 == 0 else trees[::-1]:
                results[key][name].append(measure(tree, workload, args.timeout))
        row = {name: statistics.median(m["cpu"] for m in runs) for name, runs in results[key].items()}
        wall = {name: statistics.median(m["wall"] for m in runs) for name, runs in results[key].items()}
        nan = float("nan")
        ratio = row["after"] / row["before"] if "before" in row else nan
        cells = [key, f"{row.get('before', nan):,.1f}", f"{row['after']:,.1f}", f"{ratio:.3f}",
                 f"{wall.get('before', nan):,.1f}", f"{wall['after']:,.1f}", f"load {load():.1f}"]  # fmt: skip
        print("| " + " | ".join(cells) + " |", flush=True)
    print(f"load average {began:.1f} at the start, {load():.1f} at the end")
    if args.json:
        args.json.write_text(json.dumps(results, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
