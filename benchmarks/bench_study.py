"""A parameter study on Ray with 1 and with 2 workers: does a second core halve the time?

Runs the same study (`STUDY` below: 24 configurations x 2 runs of the classroom world, 48 tasks of about
a second each) with `horde study --workers 1` and `--workers 2`, alternately (1, 2, 1, 2...: the machine's
background load drifts, so the means are compared), each in a fresh data directory and a fresh process
(Ray's start-up, about 5 s, is part of what a user waits for and is counted). It prints each round's wall
time and the tasks' own compute time (the sum of the time spent inside tasks, from the store), the mean
wall times and their ratio (the goal: at most 0.6 with 2 workers). A tiny warm-up study first loads the
compiled kernels into the cache, so that neither side pays for compiling them.

Run: `python benchmarks/bench_study.py [--rounds 2] [--json PATH]`.
"""

from __future__ import annotations

import argparse
import json
import os
import sqlite3
import subprocess
import sys
import tempfile
import time
from pathlib import Path

STUDY = """\
scenario = "classroom-offpolicy"
runs = 2
[measure]
episodes = 3000
checkpoints = 4
[[axes]]
path = "learning.alpha"
values = [0.01, 0.03, 0.1, 0.3]
[[axes]]
path = "learning.lambda"
values = [0.0, 0.5, 0.9]
[[axes]]
path = "demons.*.learner"
values = ["td", "gtd"]
"""
WARM_UP = STUDY.replace("episodes = 3000", "episodes = 5").replace("runs = 2", "runs = 1")


def run_study(text: str, workers: int) -> tuple[float, float, float]:
    """(wall seconds of `horde study`, wall and CPU seconds spent inside its tasks)."""
    with tempfile.TemporaryDirectory(prefix="horde-bench-study-") as folder:
        path = Path(folder) / "study.toml"
        path.write_text(text)
        data = Path(folder) / "data"
        command = [sys.executable, "-m", "horde.cli", "study", str(path), "--workers", str(workers), "--quiet"]
        began = time.perf_counter()
        subprocess.run([*command, "--data", str(data)], check=True, capture_output=True, timeout=1800)
        wall = time.perf_counter() - began
        with sqlite3.connect(data / "horde.db") as db:
            tasks = [json.loads(row[0]) for row in db.execute("SELECT data FROM study_tasks")]
    return wall, sum(t["seconds"] for t in tasks), sum(t["cpu_seconds"] for t in tasks)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--rounds", type=int, default=2, help="rounds of (1 worker, 2 workers)")
    parser.add_argument("--json", metavar="PATH", help="also write the figures as JSON")
    args = parser.parse_args()
    print(f"cores: {os.cpu_count()}; warming up the compiled kernels...", flush=True)
    run_study(WARM_UP, 1)
    walls: dict[int, list[float]] = {1: [], 2: []}
    rounds = []
    for r in range(args.rounds):
        for workers in (1, 2):
            wall, inside, cpu = run_study(STUDY, workers)
            walls[workers].append(wall)
            rounds.append({"round": r + 1, "workers": workers, "wall": wall, "task_wall": inside, "task_cpu": cpu})
            print(
                f"round {r + 1}, {workers} worker(s): {wall:6.1f} s wall; inside tasks {inside:6.1f} s wall, "
                f"{cpu:6.1f} s CPU",
                flush=True,
            )
    one, two = (sum(walls[w]) / len(walls[w]) for w in (1, 2))
    print(f"mean wall: 1 worker {one:.1f} s, 2 workers {two:.1f} s; ratio {two / one:.2f} (goal <= 0.6)")
    if args.json:
        Path(args.json).write_text(
            json.dumps({"rounds": rounds, "mean_1": one, "mean_2": two, "ratio": two / one}, indent=2)
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
