"""Studies on Ray: on this machine, and across a real two-node cluster on loopback, equal to in-process.

The cluster test starts a head node and a worker node on loopback (`ray_cluster.start_cluster`: token
authentication, every process on 127.0.0.1), each with one CPU, so the study's tasks must spread over both;
it runs `horde study --address` against it and compares every measurement with the same study run in this
process.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from horde.runs.store import Store
from horde.studies.files import parse_study
from horde.studies.runner import InProcess, create_study, run_study
from ray_cluster import start_cluster

from .helpers import alpha_by_learner

pytestmark = pytest.mark.slow

STUDY = alpha_by_learner(runs=2, episodes=150, checkpoints=3, learners=("td", "gq"))


def in_process(tmp_path: Path) -> dict[tuple[int, int], dict[str, Any]]:
    study, base, _ = parse_study(STUDY)
    store = Store(tmp_path / "reference")
    record, _ = create_study(store, study, base)
    run_study(store, record.id, InProcess())
    tasks = {(t.config, t.run): json.loads(t.data) for t in store.study_tasks(record.id)}
    store.close()
    return tasks


def stored_tasks(data: Path) -> dict[tuple[int, int], dict[str, Any]]:
    store = Store(data)
    (record,) = store.list_studies()
    assert record.status == "finished"
    tasks = {(t.config, t.run): json.loads(t.data) for t in store.study_tasks(record.id)}
    store.close()
    return tasks


def measurements(task: dict[str, Any]) -> dict[str, Any]:
    return {k: v for k, v in task.items() if k not in ("seconds", "cpu_seconds", "node")}


def assert_equal_results(
    got: dict[tuple[int, int], dict[str, Any]], want: dict[tuple[int, int], dict[str, Any]]
) -> None:
    assert sorted(got) == sorted(want) and len(want) == 8
    for key in want:
        # the same seeds give the same numbers, wherever the task ran (nan == nan in JSON text)
        assert json.dumps(measurements(got[key])) == json.dumps(measurements(want[key])), key


def test_a_study_on_local_ray_equals_the_in_process_run(tmp_path: Path) -> None:
    path = tmp_path / "small.toml"
    path.write_text(STUDY)
    data = tmp_path / "ray"
    command = [sys.executable, "-m", "horde.cli", "study", str(path), "--workers", "2", "--quiet", "--data", str(data)]
    done = subprocess.run(command, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert_equal_results(stored_tasks(data), in_process(tmp_path))


def test_a_study_across_a_two_node_cluster_equals_the_in_process_run(tmp_path: Path) -> None:
    cluster = start_cluster(tmp_path, head_cpus=1, worker_cpus=1)  # one CPU each: the tasks must spread
    try:
        path = tmp_path / "small.toml"
        path.write_text(STUDY)
        data = tmp_path / "cluster"
        command = [sys.executable, "-m", "horde.cli", "study", str(path), "--address", cluster.address, "--quiet",
                   "--data", str(data)]  # fmt: skip
        env = {**{k: v for k, v in os.environ.items() if not k.startswith("RAY_")}, **cluster.env}
        done = subprocess.run(command, env=env, capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, done.stderr
        tasks = stored_tasks(data)
        assert len({t["node"] for t in tasks.values()}) == 2  # both nodes ran tasks
        assert_equal_results(tasks, in_process(tmp_path))
    finally:
        cluster.stop()
    assert cluster.head.returncode is not None and cluster.worker.returncode is not None
