"""`python -m benchmarks.bench_load --smoke`: the load benchmark runs end to end against a real server (a few
runs, clients and pollers, a 500-demon run made meanwhile) and reports what it measured. Speed is the
benchmark's to measure, not this test's: it checks the report's shape and that every part of the load ran."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.serial  # a benchmark: alone

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
@pytest.mark.timeout(300)
def test_the_load_benchmark_runs_and_reports(tmp_path: Path) -> None:
    out = tmp_path / "load.json"
    done = subprocess.run([sys.executable, "-m", "benchmarks.bench_load", "--smoke", "--json", str(out)], cwd=ROOT,
                          capture_output=True, text=True, timeout=280)  # fmt: skip
    assert done.returncode == 0, done.stderr[-3000:]
    assert "all rounds: health median" in done.stdout
    (round_,) = json.loads(out.read_text())
    health = round_["health_ms"]
    assert health["checks"] > 50 and 0 < health["median"] <= health["p99"] <= health["max"], health
    assert round_["poller_answers_per_s"]["min"] > 0 and round_["poller_failures"] == 0, round_
    assert round_["stream_messages_per_s"] > 0 and round_["streams_dropped"] == 0, round_
    assert round_["steps_per_s"] > 0, "the runs learned"
    assert round_["big_run"]["status"] == 201 and round_["big_run"]["seconds"] > 0, round_["big_run"]
