"""The live view with HORDE_TOKEN set: a browser without the token cannot change a run (but may choose what
it sees); with it, it can. And the live view's port refuses WebSocket upgrades from pages of other sites.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from pathlib import Path

import pytest
import viser
from playwright.sync_api import Browser
from websockets.exceptions import ConnectionClosed, InvalidStatus
from websockets.sync.client import connect

from horde.server import Settings
from polling import wait_until

from .conftest import CHROMIUM, PAGE_CATCHES_UP_MS, RunningServer, browser_page, free_port, serve_in_thread

TOKEN = "s3cret-token"
AUTH = {"Authorization": f"Bearer {TOKEN}"}


@pytest.fixture
def server(tmp_path: Path) -> Iterator[RunningServer]:
    settings = Settings(data=tmp_path / "data", token=TOKEN, viser_port=free_port(), snapshot_every=3600.0)
    with serve_in_thread(settings) as running:
        yield running


def view_port(server: RunningServer) -> int:
    return int(server.client.get("/api/view").json()["url"].rstrip("/").rsplit(":", 1)[1])


@pytest.mark.slow
def test_the_live_view_disconnects_other_sites(server: RunningServer) -> None:
    url = f"ws://127.0.0.1:{view_port(server)}"
    protocol = [f"viser-v{viser.__version__}"]
    with connect(url, origin=f"http://127.0.0.1:{view_port(server)}", subprotocols=protocol) as own:  # type: ignore[arg-type]
        assert own.recv(timeout=10), "the view's own page gets the scene"
    with connect(url, origin="http://evil.example", subprotocols=protocol) as other:  # type: ignore[arg-type]
        deadline = time.monotonic() + 10
        with pytest.raises((ConnectionClosed, InvalidStatus)):
            while time.monotonic() < deadline:
                other.recv(timeout=1)
        assert other.close_code == 1008, other.close_code


@pytest.mark.e2e
@pytest.mark.skipif(not CHROMIUM.exists(), reason="needs Debian's chromium at /usr/bin/chromium")
def test_without_the_token_the_panel_changes_no_run(browser: Browser, server: RunningServer) -> None:
    from playwright.sync_api import expect

    api = server.client
    body = {"scenario": "experiment1", "seed": 3, "protocol": {"episodes": 0}}  # runs until paused
    run = api.post("/api/runs", json=body, headers=AUTH).json()["id"]
    url = api.get("/api/view").json()["url"]

    with browser_page(browser, 960, 600) as (page, errors):  # small: software WebGL draws it sooner
        page.goto(url)
        page.get_by_role("button", name="Expand panel").click(timeout=60_000)  # minimized at first; software WebGL
        tilt = page.get_by_role("button", name="Tilt to 3-D")
        expect(tilt).to_be_visible(timeout=60_000)
        for name in ("Play", "Pause", "Step", "Reset"):  # the commands are absent
            expect(page.get_by_role("button", name=name, exact=True)).to_have_count(0)
        expect(page.get_by_text("Full speed")).to_have_count(0)

        tilt.click()  # what this browser sees is its own choice: no token needed
        expect(page.get_by_role("button", name="Top-down 2-D")).to_be_visible(timeout=PAGE_CATCHES_UP_MS)

        token = page.get_by_role("textbox").first  # the browser's own Token field
        token.fill("wrong")
        token.press("Enter")
        expect(page.get_by_text("this token is not one of this server's").first).to_be_visible(
            timeout=PAGE_CATCHES_UP_MS
        )
        expect(page.get_by_role("button", name="Play", exact=True)).to_have_count(0)
        assert api.get(f"/api/runs/{run}").json()["status"] == "created"

        token.fill(TOKEN)
        token.press("Enter")
        play = page.get_by_role("button", name="Play", exact=True)
        expect(play).to_be_visible(timeout=PAGE_CATCHES_UP_MS)
        play.click()
        wait_until(lambda: api.get(f"/api/runs/{run}").json()["status"] == "running", "Play to start the run", 60)

        # A second browser, without the token, still sees no commands.
        other = browser.new_page(viewport={"width": 960, "height": 600})
        other.goto(url)
        other.get_by_role("button", name="Expand panel").click(timeout=60_000)  # a second software-WebGL page
        expect(other.get_by_role("button", name="Tilt to 3-D")).to_be_visible(timeout=30_000)
        expect(other.get_by_role("button", name="Pause", exact=True)).to_have_count(0)
    assert errors == [], errors
    assert api.get(f"/api/runs/{run}").json()["status"] == "running"
