"""`horde bench`: every workload, one table, and the same figures as JSON.

Every workload is a `RunSpec` run by `Simulation`, the step a user's run takes (`workloads.py`,
`thesis.py`). For each workload and size: demon-updates per second and milliseconds per step
(wall-clock median of many steps after a warm-up; the process's CPU time beside it), the ratio to
`reference.py` in the same run (on a subset of the demons, fed the same transitions), and the memory
traffic of a step in bytes read plus bytes written (`bound.step_bytes`) against an in-place update's rate
measured at the start of the run in the same convention (`bound.py`): `bandwidth_fraction` on wall time and
`bound_fraction` on CPU time (1.0: the step moves its bytes as fast as `a += 1`). Scale workloads
also report their trace supports, their memory per demon, and how far their predictions are from the
reference's on that subset.

Run: `horde bench [--quick] [--json PATH] [--only WORKLOAD ...]` or `python -m benchmarks ...`.
"""

from __future__ import annotations

import argparse
import gc
import json
import math
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import TextIO

import numpy as np

from benchmarks import bound, measure, thesis, workloads
from horde.core.reference import ReferenceHorde
from horde.core.simulation import Simulation
from horde.core.threads import cores

WORKLOADS = ("thesis", "nexting", "off_policy", "control")


@dataclass
class Row:
    """One line of the table (and one object of the JSON list)."""

    workload: str
    demons: int
    steps_per_second: float
    ms_per_step: float
    demon_updates_per_second: float
    reference_ratio: float
    bandwidth_fraction: float
    learner: str = ""
    dtype: str = "float64"
    cpu_ms_per_step: float = math.nan
    traffic_mb_per_step: float = math.nan
    trace_rows: float = math.nan  # mean support rows per block
    memory_per_demon_bytes: float = math.nan
    reference_error: float = math.nan  # max |prediction - reference| on the reference subset
    reference_demons: int = 0
    threads: int = 1
    bound_fraction: float = math.nan  # the in-place update's CPU time for the step's bytes over the step's
    single_thread_ms_per_step: float = math.nan  # the same steps on one thread, measured in the same run
    single_thread_cpu_ms_per_step: float = math.nan
    thread_speedup: float = math.nan  # wall ms per step on one thread / on `threads` threads
    # nexting learners other than TD: steps/s over TD's with as many demons, rounds of the two alternated
    # in this run (so that a change in a shared machine's load falls on both), on wall and CPU time
    td_ratio: float = math.nan
    td_ratio_cpu: float = math.nan
    notes: str = ""


@dataclass(frozen=True)
class Plan:
    """Which sizes to run and for how many steps."""

    thesis: tuple[int, ...]
    thesis_seconds: float  # timed seconds per thesis size
    scale: tuple[tuple[str, int, str], ...]  # (workload, demons, learner)
    warmup: int  # steps before timing (the traces' supports reach their steady size)
    timed: int
    reference_steps: int
    reference_demons: int
    bandwidth_mb: int


FULL = Plan(
    thesis=(2, 100, 1000),
    thesis_seconds=2.0,
    scale=(
        ("nexting", 100, "td"),
        ("nexting", 1000, "td"),
        ("nexting", 2000, "td"),
        ("nexting", 8000, "td"),
        ("nexting", 8000, "gtd"),
        ("nexting", 8000, "true_online_td"),  # the learners that need less tuning (README)
        ("nexting", 8000, "etd"),
        ("nexting", 8000, "true_online_gtd"),  # at Horde scale since its traces keep a support (docs/performance.md)
        ("nexting", 8000, "td+autostep"),
        ("nexting", 8000, "td+tidbd"),
        ("off_policy", 1000, "gtd"),
        ("off_policy", 8000, "gtd"),
        ("control", 100, "gq"),
        ("control", 1000, "gq"),
        ("control", 2000, "gq"),
    ),
    warmup=150,
    timed=100,
    reference_steps=150,
    reference_demons=20,
    bandwidth_mb=512,
)
QUICK = Plan(
    thesis=(2,),
    thesis_seconds=0.2,
    # nexting 600: a block past engine.layout.PARALLEL_MIN, split over the cores (the speed-up over one thread)
    scale=(
        ("nexting", 50, "td"),
        ("nexting", 50, "td+autostep"),
        ("nexting", 600, "td"),
        ("off_policy", 50, "gtd"),
        ("control", 10, "gq"),
    ),
    warmup=10,
    timed=10,
    reference_steps=5,
    reference_demons=3,
    bandwidth_mb=64,
)


@dataclass
class Report:
    rows: list[Row] = field(default_factory=list)
    bandwidth: measure.Bandwidth | None = None
    seconds: float = 0.0


# ----------------------------------------------------------------------------------------------


def run_thesis(demons: int, plan: Plan, bandwidth: measure.Bandwidth) -> Row:
    """The whole loop of Experiment 1 with `demons` demons, against ReferenceHorde."""
    sim = thesis.simulation(demons)
    sim.run(200)  # compile (cached) and warm up
    chunk = max(20, 20_000 // demons)
    began = time.perf_counter()
    sim.run(chunk)
    per_chunk = time.perf_counter() - began
    count = max(5, int(plan.thesis_seconds / max(per_chunk, 1e-6)))
    timing = measure.time_steps(lambda t: sim.run(chunk), 0, count, per_call=chunk)
    subset = min(demons, 12)
    reference = thesis.reference_seconds_per_step(subset, max(plan.reference_steps, 20))
    updates = demons / timing.wall
    traffic = _traffic(sim)
    return Row(
        workload="thesis",
        demons=demons,
        steps_per_second=1.0 / timing.wall,
        ms_per_step=1e3 * timing.wall,
        demon_updates_per_second=updates,
        reference_ratio=updates / (subset / reference),
        bandwidth_fraction=traffic / timing.wall / _rate(bandwidth, sim.threads),
        learner="gq+gtd",
        cpu_ms_per_step=1e3 * timing.cpu,
        traffic_mb_per_step=traffic / 1e6,
        reference_demons=subset,
        threads=sim.threads,
        bound_fraction=_bound(traffic, timing, bandwidth, sim.threads),
        notes=f"whole loop, {sim.horde.groups[0].coder.n} features, reference: ReferenceHorde of {subset} demons",
    )


def _traffic(sim: Simulation) -> int:
    """The bytes read plus bytes written of one more step (`bound.step_bytes`)."""
    return bound.next_step_bytes(sim)


def _rate(bandwidth: measure.Bandwidth, threads: int) -> float:
    """An in-place update's bytes read plus bytes written per second on `threads` threads."""
    return 2.0 * bandwidth.for_threads(threads)


def _bound(traffic: int, timing: measure.Timing, bandwidth: measure.Bandwidth, threads: int) -> float:
    """The CPU time that `threads` threads updating in place would take for `traffic` bytes (read plus written),
    over the step's CPU time: 1.0 means the step moves its bytes as fast as `a += 1`."""
    return threads * traffic / _rate(bandwidth, threads) / timing.cpu


def _replay(sim: Simulation, reference: ReferenceHorde, steps: int) -> float:
    """Step `sim` one transition at a time and feed each to `reference`; the reference's median seconds."""
    names = sim.world.sensor_names
    reference.observe(*sim.position, dict(zip(names, sim.start_sensors.tolist(), strict=True)))
    seconds = []
    for _ in range(steps):
        result = sim.step()
        sensors = sim.sensors
        began = time.perf_counter()
        reference.learn(result.action, sim.behaviour_probability, float(sensors[0]), float(sensors[1]),
                        dict(zip(names, sensors.tolist(), strict=True)), result.terminated)  # fmt: skip
        if result.done:
            reference.observe(*sim.position, dict(zip(names, sim.start_sensors.tolist(), strict=True)))
        seconds.append(time.perf_counter() - began)
    return float(np.median(seconds))


def run_scale(name: str, demons: int, learner: str, plan: Plan, bandwidth: measure.Bandwidth) -> Row:
    """A scale workload through `Simulation`, against ReferenceHorde on a subset of its demons."""
    spec = workloads.spec(name, demons, learner)
    rss_before = measure.rss_bytes()
    sim = Simulation(spec, np.random.default_rng(0))
    sim.with_metrics = False
    size = plan.reference_demons // (4 if name == "control" else 1)  # a plain GQ demon costs ~4 times more
    small, picked = workloads.subset(spec, max(size, 1))
    reference = ReferenceHorde(small)
    reference_seconds = _replay(sim, reference, plan.reference_steps)
    ours = sim.prediction_array()[picked]
    theirs = np.array([reference.demons[d.name].prediction for d in small.demons])
    sim.run(max(plan.warmup - plan.reference_steps, 0))
    chunk = 5
    threads = sim.threads  # the run's share of the cores (all of them: it runs alone)
    calls = max(1, plan.timed // chunk)
    if threads > 1:  # the same steps on one thread, rounds alternated: the speed-up measured in this run

        def use(count: int | None) -> Callable[[], None]:
            return lambda: setattr(sim, "threads", count)

        timing, single = measure.time_alternating(lambda t: sim.run(chunk), [use(None), use(1)], calls, chunk)
        sim.threads = None
    else:
        timing = single = measure.time_steps(lambda t: sim.run(chunk), 0, calls, per_call=chunk)
    rss = measure.rss_bytes() - rss_before
    memory = sim.learner.engine.nbytes()
    nnz = float(sim.learner.engine.t.wts.touched.mean())
    traffic = _traffic(sim)
    updates = demons / timing.wall
    return Row(
        workload=name,
        demons=demons,
        steps_per_second=1.0 / timing.wall,
        ms_per_step=1e3 * timing.wall,
        demon_updates_per_second=updates,
        reference_ratio=updates / (len(picked) / reference_seconds),
        bandwidth_fraction=traffic / timing.wall / _rate(bandwidth, threads),
        learner=learner,
        cpu_ms_per_step=1e3 * timing.cpu,
        traffic_mb_per_step=traffic / 1e6,
        trace_rows=nnz,
        memory_per_demon_bytes=(rss if rss > 0 else memory) / demons,
        reference_error=float(np.abs(ours - theirs).max()),
        reference_demons=len(picked),
        threads=threads,
        bound_fraction=_bound(traffic, timing, bandwidth, threads),
        single_thread_ms_per_step=1e3 * single.wall,
        single_thread_cpu_ms_per_step=1e3 * single.cpu,
        thread_speedup=single.wall / timing.wall,
        notes=f"{len(sim.horde.blocks)} blocks, {sim.horde.num_classes} trace classes, "
        f"buffers {memory / demons / 1024:.1f} KiB/demon (memory_per_demon_bytes: resident growth)",
    )


def td_ratio(td: Simulation, demons: int, learner: str, plan: Plan) -> tuple[float, float]:
    """The learner's steps per second over TD's (`td`, warmed) on the same nexting workload (wall, CPU): the
    learner's run built and warmed, then the two timed in alternated rounds, as the speed-up over one thread
    is. Measured one after the other, minutes apart, the ratio moved from 0.26 to 0.41 with a shared
    machine's load (sixth session)."""
    sim = Simulation(workloads.spec("nexting", demons, learner), np.random.default_rng(0))
    sim.with_metrics = False
    sim.run(plan.warmup)
    sims = [td, sim]
    current: list[Simulation] = []

    def use(sim: Simulation) -> Callable[[], None]:
        def choose() -> None:
            current[:] = [sim]

        return choose

    chunk = 5
    base, other = measure.time_alternating(lambda t: current[0].run(chunk), [use(s) for s in sims],
                                           max(2, plan.timed // chunk), chunk)  # fmt: skip
    return base.wall / other.wall, base.cpu / other.cpu


# ----------------------------------------------------------------------------------------------


def run(plan: Plan, only: Sequence[str] = WORKLOADS, stream: TextIO | None = None) -> Report:
    """Every workload of the plan (those named in `only`), with progress lines on `stream` (stderr)."""
    began = time.perf_counter()
    report = Report()
    report.bandwidth = measure.bandwidth(plan.bandwidth_mb, threads=cores())
    in_place = ", ".join(f"{2 * b / 1e9:.1f}" for b in report.bandwidth.in_place)

    def say(text: str) -> None:
        print(text, file=stream or sys.stderr, flush=True)

    say(
        f"memory bandwidth: in-place update {in_place} GB/s on 1, 2, ... threads (bytes read plus written); numpy "
        f"copy {report.bandwidth.copy / 1e9:.1f}, update {report.bandwidth.update / 1e9:.1f}, read "
        f"{report.bandwidth.read / 1e9:.1f} GB/s (bytes read plus bytes written)"
    )
    if "thesis" in only:
        for demons in plan.thesis:
            say(f"thesis {demons} ...")
            report.rows.append(run_thesis(demons, plan, report.bandwidth))
    for name, demons, learner in plan.scale:
        if name in only:
            say(f"{name} {demons} {learner} ...")
            report.rows.append(run_scale(name, demons, learner, plan, report.bandwidth))
            gc.collect()
    tds: dict[int, Simulation] = {}  # one warmed TD run per size, timed against each other learner
    for i, row in enumerate(report.rows):
        if row.workload == "nexting" and row.learner != "td" and ("nexting", row.demons, "td") in plan.scale:
            say(f"nexting {row.demons} {row.learner} against td, alternated ...")
            if row.demons not in tds:
                td = tds[row.demons] = Simulation(workloads.spec("nexting", row.demons, "td"), np.random.default_rng(0))
                td.with_metrics = False
                td.run(plan.warmup)
            wall, cpu = td_ratio(tds[row.demons], row.demons, row.learner, plan)
            report.rows[i] = replace(row, td_ratio=wall, td_ratio_cpu=cpu)
            gc.collect()
    tds.clear()
    report.seconds = time.perf_counter() - began
    return report


def _fmt(value: float, digits: int = 1) -> str:
    if not math.isfinite(value):
        return "-"
    if abs(value) >= 1e5:
        return f"{value:.3g}"
    return f"{value:,.{digits}f}"


def format_table(report: Report) -> str:
    header = (
        "workload",
        "demons",
        "learner",
        "thr",
        "x 1 thr",
        "steps/s",
        "ms/step",
        "cpu ms",
        "updates/s",
        "x ref",
        "bw frac",
        "bound",
        "MB/step",
        "rows",
        "KiB/demon",
        "ref err",
        "x td",
    )
    rows = [
        (
            r.workload,
            str(r.demons),
            r.learner,
            str(r.threads),
            _fmt(r.thread_speedup, 2),
            _fmt(r.steps_per_second),
            _fmt(r.ms_per_step, 3),
            _fmt(r.cpu_ms_per_step, 3),
            _fmt(r.demon_updates_per_second, 0),
            _fmt(r.reference_ratio, 0),
            _fmt(r.bandwidth_fraction, 2),
            _fmt(r.bound_fraction, 2),
            _fmt(r.traffic_mb_per_step),
            _fmt(r.trace_rows, 0),
            _fmt(r.memory_per_demon_bytes / 1024),
            "-" if not math.isfinite(r.reference_error) else f"{r.reference_error:.1e}",
            _fmt(r.td_ratio, 2),
        )
        for r in report.rows
    ]
    widths = [max(len(row[i]) for row in [header, *rows]) for i in range(len(header))]
    lines = [
        "  ".join(c.rjust(w) if i > 4 else c.ljust(w) for i, (c, w) in enumerate(zip(row, widths, strict=True)))
        for row in [header, *rows]
    ]
    lines.insert(1, "  ".join("-" * w for w in widths))
    if report.bandwidth is not None:
        in_place = ", ".join(f"{2 * b / 1e9:.1f}" for b in report.bandwidth.in_place)
        lines.append("")
        lines.append(
            f"convention: bytes read plus bytes written on both sides. bw frac: a step's bytes of weights and "
            f"traces (support rows read and written, x_t+1's other rows read) per wall second over an in-place "
            f"update's rate on as many threads ({in_place} GB/s on 1, 2, ... threads, {report.bandwidth.megabytes}"
            f" MB, measured in this run); bound: that update's CPU time for the step's bytes over the step's CPU "
            f"time; "
            f"thr: threads; x 1 thr: speed-up over one thread (wall, rounds alternated in this run); x td: "
            f"steps/s over TD's with as many demons (wall, rounds of the two alternated in this run); "
            f"total {report.seconds:.0f} s. The machine may be shared: compare CPU ms with wall ms."
        )
    return "\n".join(lines)


def to_json(report: Report) -> list[dict[str, object]]:
    """The rows as plain objects (NaN becomes null)."""
    out = []
    for row in report.rows:
        item = asdict(row)
        out.append({k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in item.items()})
    return out


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="horde bench", description=__doc__.splitlines()[0])
    add_arguments(parser)
    return bench(parser.parse_args(argv))


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--quick", action="store_true", help="a tiny run (a few seconds), for smoke tests")
    parser.add_argument("--json", metavar="PATH", help="also write the figures as JSON")
    parser.add_argument("--only", action="append", choices=WORKLOADS, help="run only this workload (repeatable)")
    parser.add_argument("--workload", metavar="NAME-LEARNER",
                        help="instead of the table: one workload (nexting-td, nexting-gtd, nexting-td+autostep, "
                        "off_policy-gtd, control-gq, ...) against the memory bound (benchmarks/bound.py)")  # fmt: skip
    parser.add_argument("--demons", type=int, default=8000, help="with --workload: its demons (default 8000)")
    parser.add_argument("--threads", default="1,2", help="with --workload: thread counts, comma-separated")
    parser.add_argument("--dtype", default="float64,float32", help="with --workload: dtypes, comma-separated")


def bench(args: argparse.Namespace) -> int:
    if getattr(args, "workload", None):
        try:  # a workload the benchmarks do not have, or a learner the specs do not know: said, not raised
            bound.spec(args.workload, args.demons, args.dtype[0])
        except ValueError as exc:  # (pydantic's ValidationError is one)
            errors = getattr(exc, "errors", None)
            reason = errors()[0]["msg"] if callable(errors) else str(exc)
            raise SystemExit(f"error: --workload {args.workload!r} (NAME-LEARNER: nexting, off_policy or control, "
                             f"then a learner such as td, gtd or td+autostep): {reason}") from None  # fmt: skip
        rows, rates = bound.run(args.workload, args.demons, args.threads, args.dtype)
        print(bound.table(rows, rates))
        if args.json:
            Path(args.json).write_text(json.dumps([asdict(r) for r in rows], indent=2) + "\n")
        return 0
    report = run(QUICK if args.quick else FULL, tuple(args.only or WORKLOADS))
    print(format_table(report))
    if args.json:
        Path(args.json).write_text(json.dumps(to_json(report), indent=2) + "\n")
    return 0
