"""`horde serve` keeps tokens out of its log: a `?token=` in an HTTP request or a WebSocket upgrade is
written as `token=***` (server/logs.py)."""

from __future__ import annotations

import logging
import os
import signal
import subprocess
import sys
from pathlib import Path

import httpx
import pytest
import websockets.sync.client as ws_client
from websockets.exceptions import ConnectionClosed

from horde.server.logs import HideTokens, hide_tokens
from polling import wait_until
from serving import free_port

TOKEN = "tok-4f9c2d71e8"


def test_hide_tokens() -> None:
    assert hide_tokens(f"GET /api/streams/a/records?token={TOKEN}&x=1 HTTP/1.1") == (
        "GET /api/streams/a/records?token=***&x=1 HTTP/1.1"
    )
    assert hide_tokens(f"/p?a=1&TOKEN={TOKEN}") == "/p?a=1&TOKEN=***"
    assert hide_tokens("/p?notatoken=1") == "/p?notatoken=1"
    args = ("127.0.0.1:5000", f"/s?token={TOKEN}")
    record = logging.LogRecord("uvicorn.error", logging.INFO, "", 0, '%s - "WebSocket %s" [accepted]', args, None)
    HideTokens().filter(record)
    assert TOKEN not in record.getMessage()


@pytest.mark.timeout(120)
def test_the_served_log_has_no_token(tmp_path: Path) -> None:
    port = free_port()
    log = tmp_path / "serve.log"
    env = {**os.environ, "HORDE_TOKEN": TOKEN}
    command = [sys.executable, "-m", "horde.cli", "serve", "--no-view", "--port", str(port), "--data", str(tmp_path)]
    with log.open("wb") as out:
        server = subprocess.Popen(command, env=env, stdout=out, stderr=subprocess.STDOUT)
    try:
        base = f"http://127.0.0.1:{port}"

        def up() -> bool:
            try:
                return httpx.get(f"{base}/api/health", timeout=2).status_code == 200
            except httpx.HTTPError:
                return False

        wait_until(up, "horde serve to answer", timeout=60)
        assert httpx.get(f"{base}/api/health", params={"token": TOKEN}, timeout=10).status_code == 200
        with (
            ws_client.connect(f"ws://127.0.0.1:{port}/api/streams/nope/records?token={TOKEN}", open_timeout=10) as ws,
            pytest.raises(ConnectionClosed),
        ):
            ws.recv(timeout=10)
        wait_until(lambda: "WebSocket /api/streams/nope/records" in log.read_text(), "the upgrade to be logged")
    finally:
        server.send_signal(signal.SIGINT)
        server.wait(timeout=30)
    written = log.read_text()
    assert "token=***" in written and TOKEN not in written, written
