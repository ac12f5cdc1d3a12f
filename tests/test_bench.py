"""`horde bench --quick --json PATH`: the smoke run of the throughput benchmarks, and its JSON shape.

Every workload runs through `Simulation` (the product path) and is checked against reference.py.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numba
import numpy as np
import pytest
from benchmarks import measure, workloads

from horde.cli import main
from horde.core import threads
from horde.core.engine.layout import PARALLEL_MIN
from horde.core.simulation import Simulation

REQUIRED = {
    "workload": str,
    "demons": int,
    "steps_per_second": float,
    "ms_per_step": float,
    "demon_updates_per_second": float,
    "reference_ratio": float,
    "bandwidth_fraction": float,
    "cpu_ms_per_step": float,
    "bound_fraction": float,
    "threads": int,
}


@pytest.mark.slow
def test_quick_bench_writes_every_workload(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "bench.json"
    assert main(["bench", "--quick", "--json", str(out)]) == 0
    table = capsys.readouterr().out
    assert "updates/s" in table and "bw frac:" in table and "in-place update" in table
    rows = json.loads(out.read_text())
    assert isinstance(rows, list)
    assert {r["workload"] for r in rows} == {"thesis", "nexting", "off_policy", "control"}
    for row in rows:
        for key, kind in REQUIRED.items():
            assert isinstance(row[key], kind), f"{key} of {row['workload']}: {row[key]!r}"
            if kind is float:
                assert math.isfinite(row[key]) and row[key] > 0, f"{key} of {row['workload']}"
        assert row["demons"] > 0
        assert row["ms_per_step"] == pytest.approx(1e3 / row["steps_per_second"])
        assert row["demon_updates_per_second"] == pytest.approx(row["demons"] * row["steps_per_second"])
    # a learner's speed over TD's, the two timed in alternated rounds in the same run (TD's own row has none)
    ratios = {r["learner"]: r["td_ratio"] for r in rows if r["workload"] == "nexting" and r["demons"] == 50}
    assert ratios["td"] is None and 0 < ratios["td+autostep"] < 10, ratios
    scale_rows = [r for r in rows if r["workload"] != "thesis"]
    assert all(r["reference_error"] < 1e-6 for r in scale_rows), "the product path agrees with reference.py"
    assert all(r["threads"] >= 1 for r in rows)
    # a block past the threshold learns on every core of an idle process, and the speed-up over one
    # thread is measured beside it (its size is not asserted: the machine may be shared)
    wide = [r for r in scale_rows if r["demons"] >= PARALLEL_MIN]
    assert wide, "the quick plan has a workload past the threshold"
    for row in wide:
        assert row["threads"] == threads.budget()
        assert math.isfinite(row["thread_speedup"]) and row["thread_speedup"] > 0
        assert row["single_thread_ms_per_step"] == pytest.approx(row["thread_speedup"] * row["ms_per_step"])


def test_bench_can_run_one_workload(tmp_path: Path) -> None:
    out = tmp_path / "bench.json"
    assert main(["bench", "--quick", "--only", "nexting", "--json", str(out)]) == 0
    assert {r["workload"] for r in json.loads(out.read_text())} == {"nexting"}


@pytest.mark.parametrize("learner", ["td", "gtd"])
def test_unique_bytes_counts_each_touched_number_once(learner: str) -> None:
    """`Engine.unique_bytes` against a plain count over the rows of the last step: theta on the support
    and at x_{t+1}, for GTD w on the support and at x_t, the trace's rows, each row once."""
    sim = Simulation(workloads.spec("nexting", 200, learner), np.random.default_rng(3))
    sim.run(30)
    loop = sim.learner.engine
    before = tuple(loop.active_features(g) for g in range(len(loop.horde.groups)))
    sim.run(1)
    (block,) = loop.horde.blocks
    assert len(loop.horde.groups) == 1
    support = set(loop.t.wts.support[: int(loop.t.wts.nnz[0])].tolist())
    x_next, x_prev = set(loop.active_features(0).tolist()), set(before[0].tolist())
    expected = len(support) * block.num_classes * loop.t.wts.trace.itemsize
    for row in support | x_next | x_prev:
        expected += 8 * block.size * (row in support or row in x_next)  # theta
        expected += 8 * block.size * (learner == "gtd" and (row in support or row in x_prev))  # w
    assert loop.unique_bytes(before) == expected
    assert block.num_classes > 1 and len(x_next - support) < len(x_next), "x_{t+1}'s rows mostly in the support"


def test_bandwidth_in_place_on_each_thread_count() -> None:
    bw = measure.bandwidth(megabytes=16, repeats=2, threads=2)
    assert len(bw.in_place) == min(2, numba.config.NUMBA_NUM_THREADS)
    assert all(b > 0 for b in bw.in_place)
    assert bw.for_threads(1) == bw.in_place[0] and bw.for_threads(64) == bw.in_place[-1]
