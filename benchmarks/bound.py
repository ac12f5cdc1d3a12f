"""`horde bench --workload nexting-td --threads 1,2 --dtype float64,float32`: one workload against this machine's
memory bound, per thread count and dtype, in alternated rounds.

**The convention (issue 27): bytes read plus bytes written, on both sides.** A step's bytes: on each block's
trace support, every per-weight vector the learner keeps (`Kernel.vectors`: theta; GTD's w; Autostep's three
more) read and written, so counted twice, and the trace's rows too; x_{t+1}'s rows outside the support read
once (theta only); at the dtype's size. GQ's update also moves theta on every action's rows at s_t (its
correction at the last step's s_{t+1}, each action weighted by the target policy), where only the action taken
holds a trace: those of them outside the support are read (once, with x_{t+1}'s) and written
(`Kernel.corrects_every_action`). The machine's rate: an in-place update `a += 1` over 512 MB of float64
(compiled, on as many threads), counting its bytes read plus its bytes written. The bound is the time the
in-place update would take for the step's bytes; `bound` is that time over the step's wall time, `bound (cpu)`
threads times that time over the step's CPU time (1.0: the step moves its bytes as fast as `a += 1`).
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass

import numba
import numpy as np

from benchmarks import measure, workloads
from horde.core.simulation import Simulation
from horde.spec import RunSpec


@dataclass(frozen=True)
class BoundRow:
    workload: str
    demons: int
    learner: str
    dtype: str
    threads: int
    steps_per_second: float
    ms_per_step: float
    cpu_ms_per_step: float
    mb_per_step: float  # bytes read plus bytes written, the convention above
    bound_ms: float  # the in-place update's time for those bytes on as many threads
    bound: float  # bound_ms / ms_per_step
    bound_cpu: float  # threads * bound_ms / cpu_ms_per_step


def step_bytes(sim: Simulation, x_t: list[np.ndarray] | None = None) -> int:
    """Bytes read plus bytes written by the last step (the convention of the module); `x_t`: each group's active
    features before that step (`Engine.active_features`), needed where a learner corrects every action's rows."""
    engine = sim.learner.engine
    t = engine.t
    size = t.wts.theta.itemsize
    total = 0
    for g, group in enumerate(engine.horde.groups):
        n_s = int(t.grp.n_s[g])
        actions = engine.horde.num_actions if group.action_values else 1

        def rows(features: np.ndarray, n_s: int = n_s, actions: int = actions) -> np.ndarray:
            return np.unique(np.concatenate([a * n_s + features for a in range(actions)]))

        x_next = rows(t.coded.features[g, : t.coded.counts[g]])
        for b in group.blocks:
            block = engine.horde.blocks[b]
            support = t.wts.support[int(t.lay.toff[b]) :][: int(t.wts.nnz[b])]
            total += 2 * support.size * block.num_classes * size  # the trace's rows
            if block.kernel.corrects_every_action:
                if x_t is None:
                    raise ValueError(f"{block.kernel.learner}'s bytes need the features before the step (x_t)")
                corrected = np.setdiff1d(rows(x_t[g]), support)  # read and written
                read = np.setdiff1d(np.union1d(x_next, corrected), support)  # each read once
                total += block.size * size * (2 * support.size * block.kernel.vectors + read.size + corrected.size)
            else:
                outside = np.setdiff1d(x_next, support).size
                total += block.size * size * (2 * support.size * block.kernel.vectors + outside)
    return total


def next_step_bytes(sim: Simulation) -> int:
    """One more step, and its bytes read plus bytes written (`step_bytes`)."""
    engine = sim.learner.engine
    x_t = [engine.active_features(g) for g in range(len(engine.horde.groups))]
    sim.run(1)
    return step_bytes(sim, x_t)


def spec(workload: str, demons: int, dtype: str) -> RunSpec:
    """`nexting-td`, `nexting-gtd`, `nexting-td+autostep`, `off_policy-gtd`, `control-gq` ... at `dtype`."""
    name, _, learner = workload.partition("-")
    data = workloads.spec(name, demons, learner).model_dump(by_alias=True)
    data["learning"]["dtype"] = dtype
    return RunSpec.model_validate(data)


def run(workload: str, demons: int, threads: list[int], dtypes: list[str], rounds: int = 4,
        steps: int = 40) -> tuple[list[BoundRow], list[float]]:  # fmt: skip
    """Every (dtype, threads) of the workload, timed in `rounds` alternated rounds of `steps` steps; the rows and
    the in-place update's rate (bytes read plus written per second) on 1, 2, ... threads."""
    bandwidth = measure.bandwidth(512, threads=max(threads))
    rates = [2.0 * b for b in bandwidth.in_place]  # read plus written
    sims = {}
    for dtype in dtypes:
        sim = Simulation(spec(workload, demons, dtype), np.random.default_rng(0))
        sim.with_metrics = False
        sim.run(150)  # compiled, and the traces' supports at their steady size
        sims[dtype] = sim
    times: dict[tuple[str, int], list[tuple[float, float]]] = {}
    for _ in range(rounds):
        for dtype in dtypes:
            for count in threads:
                sim = sims[dtype]
                sim.threads = count
                sim.run(5)
                w0, c0 = time.perf_counter(), time.process_time()
                sim.run(steps)
                times.setdefault((dtype, count), []).append(
                    ((time.perf_counter() - w0) / steps, (time.process_time() - c0) / steps)
                )
    rows = []
    for (dtype, count), samples in times.items():
        sim = sims[dtype]
        sim.threads = count
        nbytes = next_step_bytes(sim)
        wall, cpu = (float(np.median([s[i] for s in samples])) for i in (0, 1))
        bound_s = nbytes / rates[min(count, len(rates)) - 1]
        learner = workload.partition("-")[2]
        rows.append(BoundRow(workload, demons, learner, dtype, count, 1.0 / wall, 1e3 * wall, 1e3 * cpu,
                             nbytes / 1e6, 1e3 * bound_s, bound_s / wall, count * bound_s / cpu))  # fmt: skip
    return rows, rates


def table(rows: list[BoundRow], rates: list[float]) -> str:
    head = "workload            demons  dtype   thr   steps/s   ms/step   cpu ms   MB/step  bound ms  bound  bound(cpu)"
    lines = [head, "-" * len(head)]
    for r in rows:
        lines.append(f"{r.workload:<18}  {r.demons:>6}  {r.dtype:<7}  {r.threads:>3}  {r.steps_per_second:>8.1f}  "
                     f"{r.ms_per_step:>8.2f}  {r.cpu_ms_per_step:>7.2f}  {r.mb_per_step:>8.2f}  {r.bound_ms:>8.2f}  "
                     f"{r.bound:>5.2f}  {r.bound_cpu:>10.2f}")  # fmt: skip
    lines.append("")
    lines.append(
        "convention: bytes read plus bytes written on both sides. MB/step: per-weight vectors and trace rows on the "
        "support read and written (twice), x_{t+1}'s other rows read (once; GQ: and every action's rows at s_t "
        "outside the support read and written, its correction), at the dtype's size; the machine's "
        "rate: a += 1 over 512 MB float64, read plus written: "
        + ", ".join(f"{r / 1e9:.1f}" for r in rates)
        + " GB/s on 1, 2, ... threads (measured in this run). bound: that rate's time for the step's bytes over "
        "the step's wall time; bound(cpu): threads times it over the step's CPU time. Rounds alternated; "
        f"load average {os.getloadavg()[0]:.1f}; numba threads {numba.config.NUMBA_NUM_THREADS}."
    )
    return "\n".join(lines)
