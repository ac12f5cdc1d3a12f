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
from benchmarks import bound, measure

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


@pytest.mark.parametrize(
    ("options", "named"),
    [
        (["--demons", "32000"], "--demons"),
        (["--demons", "ten"], "--demons"),
        (["--threads", "x"], "--threads"),
        (["--threads", "1,0"], "--threads"),
        (["--dtype", "float16"], "--dtype"),
        (["--workload", "thesis-td"], "--workload"),
        (["--workload", "nexting-sarsa"], "--workload"),
    ],
)
def test_a_bad_bench_option_is_named_and_nothing_runs(options: list[str], named: str,
                                                      capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    """`horde bench --workload` with an option it cannot take: a message naming the option, no traceback, exit
    status not 0, before any workload is built or timed."""
    argv = ["bench", "--workload", "nexting-td", *options]
    with pytest.raises(SystemExit) as info:
        main(argv)
    printed = capsys.readouterr()
    said = printed.err + (info.value.code if isinstance(info.value.code, str) else "")
    assert info.value.code not in (0, None)
    assert named in said and "Traceback" not in said, said
    assert "bound ms" not in printed.out


def test_bench_can_run_one_workload(tmp_path: Path) -> None:
    out = tmp_path / "bench.json"
    assert main(["bench", "--quick", "--only", "nexting", "--json", str(out)]) == 0
    assert {r["workload"] for r in json.loads(out.read_text())} == {"nexting"}


@pytest.mark.parametrize("learner", ["td", "gtd"])
@pytest.mark.parametrize("dtype", ["float64", "float32"])
def test_step_bytes_count_bytes_read_plus_bytes_written(learner: str, dtype: str) -> None:
    """`bound.step_bytes` against a plain count over the rows of the last step: on the support, theta (and GTD's
    w) and the trace read and written; x_{t+1}'s other rows of theta read; at the dtype's size."""
    sim = Simulation(bound.spec(f"nexting-{learner}", 200, dtype), np.random.default_rng(3))
    loop = sim.learner.engine
    (block,) = loop.horde.blocks
    size = 4 if dtype == "float32" else 8
    for _ in range(300):  # a step with rows of x_{t+1} outside the support (a few dozen steps in)
        sim.run(1)
        support = set(loop.t.wts.support[: int(loop.t.wts.nnz[0])].tolist())
        x_next = set(loop.active_features(0).tolist())
        if sim.total_steps > 30 and x_next - support:
            break
    vectors = 2 if learner == "gtd" else 1
    expected = 2 * len(support) * block.num_classes * size + 2 * len(support) * block.size * size * vectors
    expected += len(x_next - support) * block.size * size
    assert bound.step_bytes(sim) == expected
    assert block.num_classes > 1 and 0 < len(x_next - support) < len(x_next), "x_{t+1}'s rows mostly in the support"


def test_step_bytes_count_gqs_correction_on_every_actions_rows() -> None:
    """GQ's correction moves theta on every action's rows at the state it leaves, only the action taken's in a
    trace: those outside the support read and written, x_{t+1}'s other rows read, each row read once."""
    sim = Simulation(bound.spec("control-gq", 20, "float64"), np.random.default_rng(3))
    loop = sim.learner.engine
    (block,) = loop.horde.blocks
    n_s = int(loop.t.grp.n_s[0])
    sim.run(40)
    x_t = loop.active_features(0)
    sim.run(1)
    with pytest.raises(ValueError, match="x_t"):
        bound.step_bytes(sim)
    support = set(loop.t.wts.support[: int(loop.t.wts.nnz[0])].tolist())
    every_action = {a * n_s + int(f) for a in range(4) for f in x_t}
    following = {a * n_s + int(f) for a in range(4) for f in loop.active_features(0)}
    taken = [a for a in range(4) if {a * n_s + int(f) for f in x_t} <= support]
    assert len(taken) >= 1 and every_action - support, "the action taken's rows hold a trace, not every action's"
    written = every_action - support
    read = (every_action | following) - support
    expected = 2 * len(support) * block.num_classes * 8 + 2 * len(support) * block.size * 8 * 2
    expected += (len(read) + len(written)) * block.size * 8
    assert bound.step_bytes(sim, [x_t]) == expected
    x_next = loop.active_features(0)
    assert bound.next_step_bytes(sim) == bound.step_bytes(sim, [x_next])  # the bench's count of one more step


@pytest.mark.parametrize("runs", [1, 2, 3])
def test_the_in_place_update_adds_one_to_every_number_once_in_contiguous_runs(runs: int) -> None:
    a = np.arange(1001, dtype=np.float64)
    measure._add_one(a, runs)
    np.testing.assert_array_equal(a, np.arange(1001) + 1.0)


def test_bandwidth_in_place_on_each_thread_count() -> None:
    bw = measure.bandwidth(megabytes=16, repeats=2, threads=2)
    assert len(bw.in_place) == min(2, numba.config.NUMBA_NUM_THREADS)
    assert all(b > 0 for b in bw.in_place)
    assert bw.for_threads(1) == bw.in_place[0] and bw.for_threads(64) == bw.in_place[-1]
