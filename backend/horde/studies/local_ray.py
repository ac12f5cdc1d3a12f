"""A Ray cluster of one node on this machine, for the studies of a server (or of `horde study`) that is given no
cluster: `ray start --head --block` as a child process, every Ray process on loopback with token authentication.

Why a child process and not `ray.init()` here: a process that is Ray's driver dies with Ray (Ray's core worker
exits the process when its GCS has been gone for `RAY_gcs_rpc_server_reconnect_timeout_s`), and the server must
outlive Ray. So the server starts the head here, never imports Ray itself, and each study's driver is a worker
process of its own (`studies/driver.py`) that joins this head by its address. When Ray dies (its GCS killed, say),
`ray start --block` notices, stops the rest of its processes and exits; the next study starts a new head.

Every port the head opens is chosen free here (the GCS port outside Ray's worker range 10002-19999, which its
workers take from), so that several servers and test runs on one machine never collide; the node address is
127.0.0.1 (`--node-ip-address` and RAY_NODE_IP_ADDRESS), so every Ray process listens on loopback only; and
RAY_AUTH_MODE=token with a token of its own, shared with the drivers through `env()`, keeps other users of this
machine (loopback reaches them too) out.
"""

from __future__ import annotations

import contextlib
import logging
import os
import secrets
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

log = logging.getLogger(__name__)

LOOPBACK = "127.0.0.1"
RAY_WORKER_PORTS = range(10002, 20000)  # Ray's default min/max worker ports: its workers listen there
START_TIMEOUT = 120.0  # seconds for the head to accept a driver
GCS_RECONNECT_SECONDS = 10  # a driver of this Ray gives its GCS up after this long (Ray's default: 60)


def free_ports(count: int) -> list[int]:
    """`count` distinct free TCP ports on loopback, outside Ray's worker range. Every socket stays bound until all
    are chosen: ports taken one at a time can repeat (the system handed a just-closed port to the next bind, and
    Ray's head refused to start with its GCS and runtime-env agent on one port)."""
    ports: list[int] = []
    with contextlib.ExitStack() as bound:
        for _ in range(200 + count):
            s = bound.enter_context(socket.socket())
            s.bind((LOOPBACK, 0))
            port = int(s.getsockname()[1])
            if port not in RAY_WORKER_PORTS:
                ports.append(port)
            if len(ports) == count:
                return ports
    raise RuntimeError("no free port outside 10002-19999")


def free_port() -> int:
    """A free TCP port on loopback, outside Ray's worker range."""
    return free_ports(1)[0]


def ray_command() -> str:
    """The `ray` command of this interpreter's environment."""
    return str(Path(sys.executable).with_name("ray"))


class LocalRay:
    """The head of a one-node Ray on this machine, started on first use and again after it died.

    Args:
        cpus: CPUs Ray may use (default: every core).
        log_dir: where the head's output goes (default: discarded).
    """

    def __init__(self, cpus: int | None = None, log_dir: Path | None = None) -> None:
        self.cpus = cpus or os.cpu_count() or 1
        self.log_dir = log_dir
        self.token = secrets.token_hex(32)
        self._process: subprocess.Popen[bytes] | None = None
        self._address: str | None = None
        self._lock = threading.Lock()

    def env(self) -> dict[str, str]:
        """The environment every process of this Ray (the head, its drivers) runs with."""
        return {
            "RAY_AUTH_MODE": "token",
            "RAY_AUTH_TOKEN": self.token,
            "RAY_NODE_IP_ADDRESS": LOOPBACK,
            # Ray resolves 127.0.0.1 to the machine's outward address (its servers then listen on every interface)
            # unless this switch of single-machine Ray (macOS's and Windows's default) is off.
            "RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER": "0",
            "RAY_gcs_rpc_server_reconnect_timeout_s": str(GCS_RECONNECT_SECONDS),
            "RAY_USAGE_STATS_ENABLED": "0",
        }

    @property
    def pid(self) -> int | None:
        return self._process.pid if self._process is not None else None

    def alive(self) -> bool:
        return self._process is not None and self._process.poll() is None

    def address(self) -> str:
        """The head's address (host:port), starting it first if it is not running (or has died).

        Raises:
            RuntimeError: the head did not start, saying why.
        """
        with self._lock:
            if not self.alive():
                self._reap()
                self._start()
            assert self._address is not None
            return self._address

    def _start(self) -> None:
        flags = ("--port", "--node-manager-port", "--object-manager-port", "--dashboard-agent-listen-port",
                 "--dashboard-agent-grpc-port", "--metrics-export-port", "--runtime-env-agent-port")  # fmt: skip
        ports = dict(zip(flags, free_ports(len(flags)), strict=True))
        port = ports["--port"]
        command = [ray_command(), "start", "--head", "--block", f"--node-ip-address={LOOPBACK}",
                   f"--num-cpus={self.cpus}", "--include-dashboard=false", "--disable-usage-stats",
                   *(f"{flag}={value}" for flag, value in ports.items())]  # fmt: skip
        env = {**{k: v for k, v in os.environ.items() if not k.startswith("RAY_")}, **self.env()}
        output = subprocess.DEVNULL
        if self.log_dir is not None:
            self.log_dir.mkdir(parents=True, exist_ok=True)
            output = (self.log_dir / "ray-head.log").open("ab")  # type: ignore[assignment]
        self._process = subprocess.Popen(command, env=env, stdout=output, stderr=subprocess.STDOUT,
                                         stdin=subprocess.DEVNULL, start_new_session=True)  # fmt: skip
        self._address = f"{LOOPBACK}:{port}"
        self._wait_listening(port)

    def _wait_listening(self, port: int) -> None:
        deadline = time.monotonic() + START_TIMEOUT
        while time.monotonic() < deadline:
            if self._process is None or self._process.poll() is not None:
                code = self._process.returncode if self._process is not None else None
                raise RuntimeError(f"Ray's head exited with code {code} while it started")
            with socket.socket() as s:
                if s.connect_ex((LOOPBACK, port)) == 0:
                    return
            time.sleep(0.2)
        self.stop()
        raise RuntimeError(f"Ray's head did not listen within {START_TIMEOUT:g} s")

    def _reap(self) -> None:
        if self._process is not None:
            with contextlib.suppress(subprocess.TimeoutExpired):
                self._process.wait(1.0)
            self._process = None

    def stop(self, timeout: float = 60.0) -> None:
        """Stop the head (`ray start --block` stops every process of its node) and wait for it."""
        with self._lock:
            process, self._process = self._process, None
        if process is None or process.poll() is not None:
            return
        process.send_signal(signal.SIGTERM)
        try:
            process.wait(timeout)
        except subprocess.TimeoutExpired:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(process.pid, signal.SIGKILL)
            process.wait(10)
