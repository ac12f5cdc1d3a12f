"""Studies on Ray: on this machine, and across a real two-node cluster on loopback, equal to in-process.

The cluster test starts a head node (`ray start --head`) and a worker node (`ray start --address`), each
with one CPU, so the study's tasks must spread over both; it runs `horde study --address` against it and
compares every measurement with the same study run in this process. Ray 2.59+ requires token
authentication: every node and the client share one RAY_AUTH_TOKEN. Both nodes run with `--block`, so
stopping them is terminating those two processes (bounded); `ray stop` would also stop any other Ray on
the machine (a study a user is running beside the tests).
"""

from __future__ import annotations

import json
import os
import secrets
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest

from horde.runs.store import Store
from horde.studies.files import parse_study
from horde.studies.runner import InProcess, create_study, run_study

from .helpers import alpha_by_learner

pytestmark = pytest.mark.slow

STUDY = alpha_by_learner(runs=2, episodes=150, checkpoints=3, learners=("td", "gq"))
RAY = str(Path(sys.executable).with_name("ray"))


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


def free_port() -> int:
    """A free TCP port outside Ray's worker range (10002-19999)."""
    for _ in range(100):
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            port = int(s.getsockname()[1])
        if not 10002 <= port <= 19999:
            return port
    raise RuntimeError("no free port outside 10002-19999")


def test_a_study_on_local_ray_equals_the_in_process_run(tmp_path: Path) -> None:
    path = tmp_path / "small.toml"
    path.write_text(STUDY)
    data = tmp_path / "ray"
    command = [sys.executable, "-m", "horde.cli", "study", str(path), "--workers", "2", "--quiet", "--data", str(data)]
    done = subprocess.run(command, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert_equal_results(stored_tasks(data), in_process(tmp_path))


def start_node(args: list[str], env: dict[str, str], log: Path) -> subprocess.Popen[bytes]:
    with log.open("wb") as out:
        return subprocess.Popen(
            [RAY, "start", "--block", "--node-ip-address=127.0.0.1", "--num-cpus=1", "--disable-usage-stats", *args],
            env=env, stdout=out, stderr=subprocess.STDOUT, start_new_session=True,
        )  # fmt: skip


def stop_node(node: subprocess.Popen[bytes]) -> None:
    if node.poll() is None:
        node.send_signal(signal.SIGTERM)  # ray start --block drains its node and stops its processes
        try:
            node.wait(timeout=60)
        except subprocess.TimeoutExpired:
            os.killpg(node.pid, signal.SIGKILL)
            node.wait(timeout=10)


def wait_for_nodes(address: str, env: dict[str, str], count: int, timeout: float) -> None:
    probe = (
        "import ray, sys; ray.init(address=sys.argv[1], log_to_driver=False); "
        "print(sum(1 for n in ray.nodes() if n['Alive']))"
    )
    deadline = time.monotonic() + timeout
    alive = "0"
    while time.monotonic() < deadline:
        done = subprocess.run(
            [sys.executable, "-c", probe, address], env=env, capture_output=True, text=True, timeout=60
        )
        alive = done.stdout.strip().splitlines()[-1] if done.stdout.strip() else "0"
        if done.returncode == 0 and int(alive) >= count:
            return
        time.sleep(1)
    pytest.fail(f"the Ray cluster at {address} had {alive} of {count} nodes alive after {timeout} s")


def test_a_study_across_a_two_node_cluster_equals_the_in_process_run(tmp_path: Path) -> None:
    port = free_port()
    address = f"127.0.0.1:{port}"
    env = {
        # Without the single-machine switch that a local study's Ray sets in this process (studies/runner.py):
        # with it, a second node cannot join.
        **{k: v for k, v in os.environ.items() if k != "RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER"},
        "RAY_AUTH_MODE": "token",
        "RAY_AUTH_TOKEN": secrets.token_hex(16),
        "RAY_NODE_IP_ADDRESS": "127.0.0.1",
    }
    head = start_node(
        ["--head", f"--port={port}", "--include-dashboard=false", f"--dashboard-agent-listen-port={free_port()}"],
        env, tmp_path / "head.log",
    )  # fmt: skip
    worker = None
    try:
        wait_for_nodes(address, env, 1, timeout=90)
        worker = start_node(
            [f"--address={address}", f"--dashboard-agent-listen-port={free_port()}"], env, tmp_path / "worker.log"
        )
        wait_for_nodes(address, env, 2, timeout=90)
        path = tmp_path / "small.toml"
        path.write_text(STUDY)
        data = tmp_path / "cluster"
        command = [
            sys.executable,
            "-m",
            "horde.cli",
            "study",
            str(path),
            "--address",
            address,
            "--quiet",
            "--data",
            str(data),
        ]
        done = subprocess.run(command, env=env, capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, done.stderr
        tasks = stored_tasks(data)
        assert len({t["node"] for t in tasks.values()}) == 2  # both nodes ran tasks
        assert_equal_results(tasks, in_process(tmp_path))
    finally:
        for node in (worker, head):
            if node is not None:
                stop_node(node)
    assert head.returncode is not None and worker is not None and worker.returncode is not None
