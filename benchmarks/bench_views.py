"""What one published view costs (issue 23): its bytes and its microseconds, on each side of the worker boundary.

A worker publishes its run's view (`messages.Update`: the numbers of every demon, the agent, the counters, the
history rows and events since the last one) at most 60 times a second; the API process takes each in and makes
the `RunView` every reader reads. For a small run (the thesis's Experiment 1: 2 demons) and a Horde of 9,000
demons (the nexting world, a family of 9,000 TD demons over its sensors), this measures, as medians over
`--repeat` views made between batches of steps:

- worker: making the update (`Recorder.take_update`: the readout, copies of the [D] arrays) and pickling it;
- the wire: the pickled bytes, and sending them through a socket pair (`multiprocessing.connection`);
- API: unpickling it and applying it (`LiveRun._apply`: history rows recorded, events added, a new RunView).

Each figure is a median of CPU time of the thread that does it (`time.thread_time`), beside wall time.

Run: `python -m benchmarks.bench_views [--repeat 200] [--json PATH]`.
"""

from __future__ import annotations

import argparse
import json
import pickle
import socket
import statistics
import threading
import time
from collections.abc import Callable
from multiprocessing.connection import Connection
from pathlib import Path
from typing import Any

from benchmarks.bench_load import GAMMAS
from horde.runs import messages as m
from horde.runs.live_run import LiveRun
from horde.runs.recorder import Recorder
from horde.runs.run_setup import Limits, new_simulation
from horde.runs.session import RunSession
from horde.scenarios import load_scenario, scenario_dir
from horde.spec import RunSpec


def big_spec(demons: int = 9000) -> RunSpec:
    """The nexting world with a family of `demons` TD demons (its table shrunk to fit the weight limit)."""
    base = load_scenario(scenario_dir() / "nexting.toml").model_dump(by_alias=True)
    sensors = [t["sensor"] for t in base["features"]["sensors"]][:50]
    scales = list(range(1, demons // (50 * len(GAMMAS)) + 1))
    family = {"name": "{s}_g{gamma}_c{c}", "over": {"s": sensors, "gamma": GAMMAS, "c": scales},
              "demon": {"learner": "td", "policy": "uniform", "discount": "{gamma}",
                        "cumulant": {"mul": [{"sensor": "{s}"}, "{c}"]}}}  # fmt: skip
    base.update(demons=[], families=[family], features={**base["features"], "size": 800})
    return RunSpec.model_validate(base)


def timed(action: Callable[[], Any]) -> tuple[Any, float, float]:
    """(result, CPU seconds of this thread, wall seconds)."""
    cpu, wall = time.thread_time(), time.perf_counter()
    result = action()
    return result, time.thread_time() - cpu, time.perf_counter() - wall


def _through_socket(sender: Connection, receiver: Connection, data: bytes) -> tuple[bytes, float]:
    """The bytes as they arrive through the socket pair, and the wall seconds from sending to having them."""
    got: list[bytes] = []
    reader = threading.Thread(target=lambda: got.append(receiver.recv_bytes()))
    began = time.perf_counter()
    reader.start()
    sender.send_bytes(data)
    reader.join()
    return got[0], time.perf_counter() - began


def measure(spec: RunSpec, repeat: int, steps: int) -> dict[str, float]:
    sim = new_simulation(spec)
    session = RunSession(sim, Limits())
    recorder = Recorder("r", Limits(), lambda message: None, 0.0, sim.horde.names, persist=False)
    session.recorder = recorder
    run = LiveRun("r", spec, Limits(), lambda init, listener: None)  # type: ignore[arg-type,return-value]
    run._launched = True
    ours, theirs = socket.socketpair()
    sender, receiver = Connection(ours.detach()), Connection(theirs.detach())
    figures: dict[str, list[float]] = {k: [] for k in ("make_cpu", "make_wall", "pickle_cpu", "bytes", "send_wall",
                                                       "unpickle_cpu", "apply_cpu", "apply_wall")}  # fmt: skip
    for _ in range(repeat):
        sim.run(steps)
        recorder.record(session)  # one history row per view, as a run paced at 60 steps a second would send
        update, cpu, wall = timed(lambda: recorder.take_update(session))
        figures["make_cpu"].append(cpu)
        figures["make_wall"].append(wall)
        data, cpu, _ = timed(lambda u=update: pickle.dumps(u, protocol=pickle.HIGHEST_PROTOCOL))  # type: ignore[misc]
        figures["pickle_cpu"].append(cpu)
        figures["bytes"].append(len(data))
        got, wall = _through_socket(sender, receiver, data)
        figures["send_wall"].append(wall)
        received, cpu, _ = timed(lambda g=got: pickle.loads(g))  # type: ignore[misc]
        figures["unpickle_cpu"].append(cpu)
        _, cpu, wall = timed(lambda r=received: run._apply(r))  # type: ignore[misc]
        figures["apply_cpu"].append(cpu)
        figures["apply_wall"].append(wall)
    assert isinstance(received, m.Update) and run.view.total_steps == sim.total_steps
    return {k: statistics.median(v) for k, v in figures.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=200)
    parser.add_argument("--json", metavar="PATH")
    args = parser.parse_args()
    cases = {"experiment1 (2 demons)": (load_scenario(scenario_dir() / "experiment1.toml"), 200),
             "9,000 demons": (big_spec(), 1)}  # fmt: skip
    out = {}
    for name, (spec, steps) in cases.items():
        f = out[name] = measure(spec, args.repeat if "9,000" not in name else max(20, args.repeat // 10), steps)
        worker, api = f["make_cpu"] + f["pickle_cpu"], f["unpickle_cpu"] + f["apply_cpu"]
        print(f"{name}: {f['bytes'] / 1000:,.1f} kB a view; worker {1e6 * worker:,.0f} us CPU (make "
              f"{1e6 * f['make_cpu']:,.0f}, pickle {1e6 * f['pickle_cpu']:,.0f}); socket {1e6 * f['send_wall']:,.0f} "
              f"us wall; API {1e6 * api:,.0f} us CPU (unpickle {1e6 * f['unpickle_cpu']:,.0f}, apply "
              f"{1e6 * f['apply_cpu']:,.0f}; wall {1e6 * f['apply_wall']:,.0f})")  # fmt: skip
    if args.json:
        Path(args.json).write_text(json.dumps(out, indent=2) + "\n")


if __name__ == "__main__":
    main()
