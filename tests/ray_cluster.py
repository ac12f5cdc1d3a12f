"""A real Ray cluster of two nodes on loopback, for the tests that run studies or runs across nodes.

The head (`ray start --head`) has no CPUs of its own unless asked, so that the work must go to the worker
node (`ray start --address`); every process of both nodes listens on 127.0.0.1 only and every node and
client shares one RAY_AUTH_TOKEN (Ray 2.59+ requires token authentication).

Why the worker node starts through a shim: Ray replaces a node address of 127.0.0.1 by the machine's outward
one (and then listens on every interface) unless its single-machine switch RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER=0
is set, and with that switch `ray start --address` refuses to start a second node. The head runs with the
switch; the worker node's `ray start` runs without it, with the localhost rewrite turned off (`SHIM`). Both
nodes run with `--block`, so ending them is terminating those two processes by pid (bounded); `ray stop`
would also stop any other Ray on the machine (another test run's).
"""

from __future__ import annotations

import json
import os
import secrets
import signal
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

from horde.studies.local_ray import free_port, free_ports, ray_command

SHIM = (
    "import sys, ray._private.services as services; services.resolve_ip_for_localhost = lambda host: host; "
    "from ray.scripts.scripts import main; sys.argv[0] = 'ray'; main()"
)
PROBE = (
    "import json, ray, sys; ray.init(address=sys.argv[1], log_to_driver=False); "
    "print(json.dumps([{'id': n['NodeID'], 'cpus': n['Resources'].get('CPU', 0)} for n in ray.nodes() if n['Alive']]))"
)


@dataclass
class Cluster:
    address: str
    env: dict[str, str]  # what every client of the cluster runs with
    head: subprocess.Popen[bytes]
    worker: subprocess.Popen[bytes]
    worker_node: str  # the worker node's id

    def stop(self) -> None:
        for node in (self.worker, self.head):
            stop_node(node)


def _ports() -> list[str]:
    """A node's component ports, distinct (`free_ports`)."""
    flags = ("--node-manager-port", "--object-manager-port", "--dashboard-agent-listen-port",
             "--dashboard-agent-grpc-port", "--metrics-export-port", "--runtime-env-agent-port")  # fmt: skip
    return [f"{flag}={port}" for flag, port in zip(flags, free_ports(len(flags)), strict=True)]


def _start(command: list[str], env: dict[str, str], log: Path) -> subprocess.Popen[bytes]:
    with log.open("wb") as out:
        return subprocess.Popen(command, env=env, stdout=out, stderr=subprocess.STDOUT, start_new_session=True)


def stop_node(node: subprocess.Popen[bytes]) -> None:
    if node.poll() is None:
        node.send_signal(signal.SIGTERM)  # ray start --block drains its node and stops its processes
        try:
            node.wait(timeout=60)
        except subprocess.TimeoutExpired:
            os.killpg(node.pid, signal.SIGKILL)
            node.wait(timeout=10)


def nodes(address: str, env: dict[str, str]) -> list[dict[str, object]]:
    done = subprocess.run([sys.executable, "-c", PROBE, address], env=env, capture_output=True, text=True, timeout=90)
    lines = done.stdout.strip().splitlines()
    return list(json.loads(lines[-1])) if done.returncode == 0 and lines else []


def wait_for_nodes(address: str, env: dict[str, str], count: int, timeout: float) -> list[dict[str, object]]:
    deadline = time.monotonic() + timeout
    alive: list[dict[str, object]] = []
    while time.monotonic() < deadline:
        alive = nodes(address, env)
        if len(alive) >= count:
            return alive
        time.sleep(1)
    raise AssertionError(f"the Ray cluster at {address} had {len(alive)} of {count} nodes alive after {timeout} s")


def start_cluster(folder: Path, head_cpus: int = 0, worker_cpus: int = 2) -> Cluster:
    """A head and a worker node on loopback; the caller stops them (`Cluster.stop`)."""
    port = free_port()
    address = f"127.0.0.1:{port}"
    base = {k: v for k, v in os.environ.items() if not k.startswith("RAY_")}
    shared = {"RAY_AUTH_MODE": "token", "RAY_AUTH_TOKEN": secrets.token_hex(16), "RAY_NODE_IP_ADDRESS": "127.0.0.1",
              "RAY_USAGE_STATS_ENABLED": "0"}  # fmt: skip
    env = {**base, **shared, "RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER": "0"}
    common = ["--block", "--node-ip-address=127.0.0.1", "--disable-usage-stats"]
    head = _start([ray_command(), "start", "--head", *common, f"--port={port}", f"--num-cpus={head_cpus}",
                   "--include-dashboard=false", *_ports()], env, folder / "head.log")  # fmt: skip
    worker = None
    try:
        (first,) = wait_for_nodes(address, env, 1, timeout=90)
        command = [sys.executable, "-c", SHIM, "start", *common, f"--address={address}", f"--num-cpus={worker_cpus}"]
        worker = _start([*command, *_ports()], {**base, **shared}, folder / "worker.log")
        alive = wait_for_nodes(address, env, 2, timeout=90)
    except BaseException:
        for node in (worker, head):
            if node is not None:
                stop_node(node)
        raise
    (worker_node,) = [str(n["id"]) for n in alive if n["id"] != first["id"]]
    return Cluster(address, {**shared, "RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER": "0"}, head, worker, worker_node)
