"""What every browser test shares: Debian's chromium and its flags, free ports, the real server in a thread."""

from __future__ import annotations

import socket
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import httpx
import pytest
import uvicorn

from horde.server import Settings, create_app
from horde.spec import WorldSpec
from horde.view.scene import agent_point, to_scene

if TYPE_CHECKING:
    from playwright.sync_api import Browser

CHROMIUM = Path("/usr/bin/chromium")
# Playwright cannot download browsers here; these flags run Debian's chromium headless, with no network
# chatter of its own and software WebGL for the viser client.
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
]
ROOT = Path(__file__).resolve().parents[2]
# Screenshots go to a build folder (git-ignored); `make screenshots` copies the ones the docs show.
SHOTS = ROOT / "test-artifacts" / "screenshots"
# True once the viser client's agent node (its THREE.Object3D, from the client's own test hook
# window.__viserMutable.nodeRefFromName) stands at scene position [x, y].
AGENT_AT = """([x, y]) => {
    const node = window.__viserMutable?.nodeRefFromName?.["/agent"];
    return !!node && Math.abs(node.position.x - x) < 1e-4 && Math.abs(node.position.y - y) < 1e-4;
}"""


def drawn_at(world: WorldSpec, x: float, y: float) -> list[float]:
    """Where the live view draws an agent standing at world (x, y): [scene x, scene y]."""
    return list(to_scene(world, *agent_point(world, x, y))[:2])


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


@dataclass
class RunningServer:
    url: str
    client: httpx.Client


@contextmanager
def serve_in_thread(settings: Settings) -> Iterator[RunningServer]:
    """The real app (lifespan and all), served by uvicorn in a background thread on a free loopback port."""
    app = create_app(settings)
    port = free_port()
    server = uvicorn.Server(uvicorn.Config(app, host="127.0.0.1", port=port, log_level="warning"))
    thread = threading.Thread(target=server.run, name="uvicorn-e2e", daemon=True)
    thread.start()
    deadline = time.monotonic() + 30
    while not server.started:
        assert time.monotonic() < deadline, "the server did not start"
        assert thread.is_alive(), "the server thread died"
        time.sleep(0.02)
    url = f"http://127.0.0.1:{port}"
    try:
        with httpx.Client(base_url=url, timeout=30) as client:
            yield RunningServer(url, client)
    finally:
        server.should_exit = True
        thread.join(timeout=20)


@pytest.fixture(scope="session", autouse=True)
def docs_pictures_untouched() -> Iterator[None]:
    """The browser tests write screenshots to SHOTS only: the tracked pictures in docs/ stay as they are
    (`make screenshots` refreshes them on purpose, after the tests)."""
    docs = ROOT / "docs"

    def pictures() -> dict[str, tuple[int, int]]:
        return {p.name: (p.stat().st_mtime_ns, p.stat().st_size) for p in sorted(docs.rglob("*.png"))}

    before = pictures()
    yield
    after = pictures()
    assert after == before, f"a browser test wrote into docs/: {sorted(set(after.items()) ^ set(before.items()))}"


@pytest.fixture(scope="module")
def browser() -> Iterator[Browser]:
    """One headless chromium per test module (Debian's, with CHROMIUM_ARGS)."""
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
        yield browser
        browser.close()
