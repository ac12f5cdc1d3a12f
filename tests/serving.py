"""The real server for the tests that need one on a socket: a free loopback port, the app in a uvicorn thread."""

from __future__ import annotations

import socket
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

import httpx
import uvicorn

from horde.server import Settings, create_app
from horde.server.cli_serve import UVICORN_OPTIONS
from polling import wait_until


def free_port() -> int:
    """A TCP port that nothing listens on now (the OS's choice)."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


@dataclass
class RunningServer:
    url: str
    client: httpx.Client
    app: Any = None  # the FastAPI app served (its `state`: the live view, the runs), for tests that look inside


@contextmanager
def serve_in_thread(settings: Settings, **config: Any) -> Iterator[RunningServer]:
    """The real app (lifespan and all), served by uvicorn as `horde serve` serves it (and with `config`, e.g.
    ws_max_size) in a background thread on a free loopback port; stopped on the way out."""
    port = free_port()
    app = create_app(settings)
    options = UVICORN_OPTIONS | config
    server = uvicorn.Server(uvicorn.Config(app, host="127.0.0.1", port=port, log_level="warning", **options))
    thread = threading.Thread(target=server.run, name="uvicorn-test", daemon=True)
    thread.start()

    def started() -> bool:
        assert thread.is_alive(), "the server thread died"
        return server.started

    wait_until(started, "the server to start")
    url = f"http://127.0.0.1:{port}"
    try:
        with httpx.Client(base_url=url, timeout=30) as client:
            yield RunningServer(url, client, app)
    finally:
        server.should_exit = True
        thread.join(timeout=20)


def health_is_quick(server: RunningServer) -> None:
    """/api/health answers within 100 ms: a bound on time, so a test that asks it is marked `serial`."""
    started = time.perf_counter()
    assert server.client.get("/api/health").status_code == 200
    assert time.perf_counter() - started < 0.1
