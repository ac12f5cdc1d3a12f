"""Horde Lab beside RLLib on one dumped nexting stream: steps per second, CPU beside wall, rounds alternated.

    python -m benchmarks.rllib.side_by_side --rllib /tmp/rllib [--steps 900] [--rounds 3] [--dir /tmp/rllib-bench]

The stream is `benchmarks.workloads`'s nexting workload with 8000 demons (57 sensors tiled into 6065 features,
457 active, lambda 0.9, five gammas, seed 0, the uniform random behaviour), the first `--steps` transitions of
its first episode (fewer than the world's 1000 steps: no episode ends inside). It is dumped once (`dump`:
every x_t's active features, the sensors at every s_{t+1}, each demon's cumulant sensor, scale and gamma, the
step sizes and the trace cut) for the C++ driver `nexting_driver.cpp`, built against RLLib's headers
(`--rllib`: a tree of RLLib's sources; see README.md). Each round times, each in a fresh process, alternating
the two sides: Horde Lab TD, RLLib TD with a trace per demon (its TDLambda, as its NextingTest), RLLib TD with
one trace per gamma, Horde Lab GTD, RLLib GTD with a trace per demon (its GTDLambda), and RLLib TD with a trace
per demon at ATrace's own threshold (1e-8 on alpha e: shorter traces than Horde Lab's cut, other predictions).
Horde Lab runs `Simulation` from the same seed over the same steps, on one thread (`--threads`), so its time
includes the grid world and the tile coding that the driver reads from the file; RLLib's is its learning only.
Each side writes its predictions at s_N after the N steps; the table gives the largest difference.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
DEMONS = 8000
# (name, Horde Lab's learner, or None: RLLib's mode)
RUNS = (("horde td", "td"), ("rllib td", "td"), ("rllib td-gamma", "td-gamma"), ("horde gtd", "gtd"),
        ("rllib gtd", "gtd"), ("rllib td-own-cut", "td-own-cut"))  # fmt: skip
AGAINST = {"rllib td": "horde td", "rllib td-gamma": "horde td", "rllib gtd": "horde gtd",
           "rllib td-own-cut": "horde td"}  # fmt: skip


def _simulation(learner: str, threads: int):  # type: ignore[no-untyped-def]
    from benchmarks import workloads
    from horde.core.simulation import Simulation

    sim = Simulation(workloads.spec("nexting", DEMONS, learner), np.random.default_rng(0))
    sim.with_metrics = False
    sim.threads = threads
    return sim


def dump(path: Path, steps: int) -> None:
    """Write the stream file the driver reads (its layout: nexting_driver.cpp's header)."""
    from benchmarks import workloads
    from horde.core.engine.blocks import TRACE_CUT

    sim = _simulation("gtd", 1)
    engine = sim.learner.engine
    coder = sim.horde.groups[0].coder
    names = list(sim.world.sensor_names)
    tiled = workloads.sensors()
    where = [names.index(s) for s in tiled]

    def features() -> tuple[np.ndarray, np.ndarray]:
        """x at the agent's state, as the engine coded it: [k] indices and values (padded with index 0, value 0)."""
        m = int(engine.t.coded.counts[0])
        index, value = np.zeros(coder.k, dtype=np.int32), np.zeros(coder.k)
        index[:m], value[:m] = engine.t.coded.features[0, :m], engine.t.coded.values[0, :m]
        return index, value

    xs = [features()]
    readings = []
    for _ in range(steps):
        result = sim.step()
        assert not (result.terminated or result.truncated), "an episode ended inside the stream: fewer steps"
        readings.append(np.asarray(sim.sensors, dtype=np.float64)[where])
        xs.append(features())
    alpha = np.unique(engine.per_demon(engine.t.lay.alpha))
    alpha_w = np.unique(engine.per_demon(engine.t.lay.alpha_w))
    assert len(alpha) == 1 and len(alpha_w) == 1, "one step size for every demon"
    sensor, scale, gamma = [], [], []
    for i, demon in enumerate(sim.spec.demons):
        rest = i // len(tiled)
        sensor.append(i % len(tiled))
        scale.append(1.0 + rest // len(workloads.TIMESCALES))
        gamma.append(workloads.TIMESCALES[rest % len(workloads.TIMESCALES)])
        assert demon.discount == gamma[-1]
        assert demon.cumulant.model_dump() == {"mul": [{"sensor": tiled[sensor[-1]]}, scale[-1]]}, demon.cumulant
    k = len(xs[0][0])
    with path.open("wb") as out:
        np.array([steps, k, coder.n, len(tiled), DEMONS, 0, 0, 0], dtype="<i8").tofile(out)
        np.array([alpha[0], alpha_w[0], workloads.LAMBDA, TRACE_CUT], dtype="<f8").tofile(out)
        np.array(sensor, dtype="<i4").tofile(out)
        np.array(scale, dtype="<f8").tofile(out)
        np.array(gamma, dtype="<f8").tofile(out)
        np.concatenate([x[0] for x in xs]).astype("<i4").tofile(out)
        np.concatenate([x[1] for x in xs]).astype("<f8").tofile(out)
        np.concatenate(readings).astype("<f8").tofile(out)


def horde_side(learner: str, steps: int, threads: int, predictions: Path) -> dict[str, float]:
    """Time Horde Lab over the stream's steps (a warm-up simulation first loads the kernels), in this process."""
    warm = _simulation(learner, threads)
    warm.run(5)
    del warm
    sim = _simulation(learner, threads)
    usage = resource.getrusage(resource.RUSAGE_SELF)
    cpu, wall = usage.ru_utime + usage.ru_stime, time.perf_counter()
    sim.run(steps)
    wall = time.perf_counter() - wall
    usage = resource.getrusage(resource.RUSAGE_SELF)
    cpu = usage.ru_utime + usage.ru_stime - cpu
    engine = sim.learner.engine
    engine.observe()  # the predictions at s_N with the weights after the N steps (what RLLib's predict reads)
    engine.prediction().astype("<f8").tofile(predictions)
    return {"wall": wall, "cpu": cpu, "steps": steps}


def build(rllib: Path, out: Path) -> None:
    include = rllib / "include"
    command = ["g++", "-O3", "-march=native", "-DNDEBUG", "-std=c++11", "-I", str(include),
               str(HERE / "nexting_driver.cpp"), "-o", str(out)]  # fmt: skip
    subprocess.run(command, check=True, timeout=600)


def _one(name: str, what: str, args: argparse.Namespace, stream: Path, driver: Path, out: Path) -> dict[str, float]:
    if name.startswith("horde"):
        command = [sys.executable, "-m", "benchmarks.rllib.side_by_side", "--horde", what, "--steps",
                   str(args.steps), "--threads", str(args.threads), "--predictions", str(out)]  # fmt: skip
        done = subprocess.run(command, cwd=ROOT, capture_output=True, text=True, timeout=3600, check=True)
        return dict(json.loads(done.stdout.strip().splitlines()[-1]))
    done = subprocess.run([str(driver), str(stream), what, str(out)], capture_output=True, text=True, timeout=7200,
                          check=True)  # fmt: skip
    fields = done.stdout.split()
    found = dict(zip(fields[1::2], fields[2::2], strict=False))
    return {"wall": float(found["wall"]), "cpu": float(found["cpu"]), "steps": float(found["steps"])}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--rllib", type=Path, help="a tree of RLLib's sources (its include/ is used)")
    parser.add_argument("--steps", type=int, default=900)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--threads", type=int, default=1, help="Horde Lab's threads")
    parser.add_argument("--dir", type=Path, default=Path("/tmp/rllib-bench"), help="the stream, driver, outputs")
    parser.add_argument("--only", nargs="*", default=None, help="of: " + ", ".join(n for n, _ in RUNS))
    parser.add_argument("--horde", default=None, help=argparse.SUPPRESS)  # one Horde Lab timing, in this process
    parser.add_argument("--predictions", type=Path, default=None, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.horde:
        print(json.dumps(horde_side(args.horde, args.steps, args.threads, args.predictions)))
        return 0
    if args.rllib is None:
        parser.error("--rllib is required")
    args.dir.mkdir(parents=True, exist_ok=True)
    stream, driver = args.dir / f"nexting-{args.steps}.bin", args.dir / "nexting_driver"
    if not stream.exists():
        began = time.perf_counter()
        dump(stream, args.steps)
        print(f"dumped {args.steps} steps to {stream} ({stream.stat().st_size / 1e6:.1f} MB) in "
              f"{time.perf_counter() - began:.0f} s", flush=True)  # fmt: skip
    build(args.rllib, driver)
    runs = [(n, w) for n, w in RUNS if args.only is None or n in args.only]
    load = [os.getloadavg()[0]]
    timings: dict[str, list[dict[str, float]]] = {n: [] for n, _ in runs}
    for round_ in range(args.rounds):
        for name, what in runs:
            found = _one(name, what, args, stream, driver, args.dir / f"{name.replace(' ', '-')}.f8")
            timings[name].append(found)
            print(
                f"round {round_ + 1} {name}: {found['steps'] / found['wall']:.2f} steps/s wall, "
                f"{found['steps'] / found['cpu']:.2f} per CPU s (load {os.getloadavg()[0]:.1f})",
                flush=True,
            )
        load.append(os.getloadavg()[0])
    print(
        f"\nload average (1 min) over the rounds: {min(load):.1f} to {max(load):.1f}; {args.steps} steps, "
        f"{DEMONS} demons, Horde Lab on {args.threads} thread(s); medians over {args.rounds} rounds\n"
    )
    print(
        "| run | steps/s (wall) | steps per CPU s | CPU ms a step | Horde Lab / this (wall; CPU) | "
        "largest prediction difference (relative) |"
    )
    print("|---|---|---|---|---|---|")
    median = {n: (statistics.median(t["steps"] / t["wall"] for t in ts), statistics.median(t["steps"] / t["cpu"]
              for t in ts)) for n, ts in timings.items()}  # fmt: skip
    for name, _ in runs:
        wall, cpu = median[name]
        ratio = difference = "-"
        horde = AGAINST.get(name)
        if horde in median:
            ratio = f"{median[horde][0] / wall:.1f}; {median[horde][1] / cpu:.1f}"
            mine = np.fromfile(args.dir / f"{name.replace(' ', '-')}.f8", dtype="<f8")
            theirs = np.fromfile(args.dir / f"{horde.replace(' ', '-')}.f8", dtype="<f8")
            gap = float(np.abs(mine - theirs).max())
            difference = f"{gap:.2e} ({gap / float(np.abs(theirs).max()):.1e})"
        print(f"| {name} | {wall:.2f} | {cpu:.2f} | {1000 / cpu:.2f} | {ratio} | {difference} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
