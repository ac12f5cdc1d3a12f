"""What every browser test shares: Debian's chromium and its flags, free ports, the real server in a thread."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any
from urllib.parse import parse_qs, urlsplit

import pytest

from horde.server import Settings
from horde.spec import WorldSpec
from horde.view.scene import agent_point, to_scene
from serving import RunningServer, free_port, serve_in_thread

if TYPE_CHECKING:
    from playwright.sync_api import Browser, Frame, Locator, Page

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
# How long a page may take to show what the server already did (a step drawn, a button after a click): the CI
# machine runs the browser beside two test processes and the fuzzer on two cores, and there a drawn step has
# taken over 10 s. A wait ends as soon as its condition holds, so the bound costs nothing when the page is quick.
PAGE_CATCHES_UP_MS = 60_000
ROOT = Path(__file__).resolve().parents[2]
DIST = ROOT / "frontend" / "dist"
# A browser test module says `pytestmark = IN_BROWSER` (it opens pages of its own: viser, the API docs) or
# `pytestmark = ON_DASHBOARD` (it opens the built dashboard, so frontend/dist must exist).
IN_BROWSER = [
    pytest.mark.e2e,
    pytest.mark.skipif(not CHROMIUM.exists(), reason="needs Debian's chromium at /usr/bin/chromium"),
]
ON_DASHBOARD = [
    *IN_BROWSER,
    pytest.mark.skipif(not (DIST / "index.html").exists(), reason="frontend/dist is not built: run `make frontend`"),
]
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


def quiet_settings(data: Path, **changes: Any) -> Settings:
    """A test server's settings: data under `data`, no token, a free viser port, no periodic snapshots."""
    fields: dict[str, Any] = {"data": data, "token": None, "viser_port": free_port(), "snapshot_every": 3600.0}
    return Settings(**(fields | changes))


@pytest.fixture
def server(tmp_path: Path) -> Iterator[RunningServer]:
    """A fresh server for one test (`quiet_settings`); a module that shares one defines its own."""
    with serve_in_thread(quiet_settings(tmp_path / "data")) as running:
        yield running


def collect_errors(page: Page, keep: Callable[[Any], bool] = lambda message: True) -> list[str]:
    """The list that `page`'s console errors (those `keep` keeps, with the URL they came from) and its
    uncaught exceptions are appended to from now on."""
    errors: list[str] = []

    def on_console(message: Any) -> None:
        if message.type == "error" and keep(message):
            errors.append(f"{message.text} ({message.location.get('url', '')})")

    page.on("console", on_console)
    page.on("pageerror", lambda error: errors.append(f"uncaught: {error}"))
    return errors


@contextmanager
def browser_page(
    browser: Browser, width: int, height: int, ignore: Callable[[str], bool] = lambda text: False
) -> Iterator[tuple[Page, list[str]]]:
    """A fresh page of `width` x `height` and its errors (`collect_errors`, less those whose text `ignore`
    names); closed on the way out."""
    context = browser.new_context(viewport={"width": width, "height": height})
    page = context.new_page()
    try:
        yield page, collect_errors(page, lambda message: not ignore(message.text))
    finally:
        context.close()


def viser_view(page: Page, view_url: str, timeout: float = 60.0) -> Frame:
    """The frame of the embedded viser live view at `view_url`, its iframe scrolled into sight first (waited for
    until `timeout` seconds: the iframe's element comes before its frame has loaded the view).

    The view is served on another port, so its iframe is cross-origin, and Chromium runs no frames of a
    cross-origin iframe outside the viewport: below the fold the viser client neither starts nor draws, and a
    wait for its nodes times out (about one run in five of the stream test, as the page's layout settled).

    Scrolled by the page's own scrollIntoView, not Playwright's, which first waits for the frame to stand still
    over two animation frames: once the view draws (software WebGL), a page gets a few frames a second, the
    charts above the frame grow as readings arrive, and that wait ran out on a loaded machine. The scroll too is
    bounded by `timeout`, not the page's default: the view's frame shares the page's main thread, which the viser
    client's start-up (its shaders compiled in software) held for more than 20 s in a loaded CI run."""
    deadline = time.monotonic() + timeout
    scroll = "frame => frame.scrollIntoView({block: 'center'})"
    page.locator("iframe.viser-frame").evaluate(scroll, timeout=timeout * 1000)
    while (frame := next((f for f in page.frames if f.url.startswith(view_url.rstrip("/"))), None)) is None:
        assert time.monotonic() < deadline, f"no frame of the page shows the live view at {view_url}"
        page.wait_for_timeout(100)  # (Playwright's events, a frame's navigation among them, arrive while it waits)
    return frame


def page_viewer(page: Page) -> str:
    """The page's own live view key: the `viewer` of the WebSocket address in its embedded view's address."""
    src = page.locator("iframe.viser-frame").get_attribute("src") or ""
    socket = parse_qs(urlsplit(src).query)["websocket"][0]
    return parse_qs(urlsplit(socket).query)["viewer"][0]


def fill_and_press(form: Locator, fields: dict[str, str], button: str) -> None:
    """Type each value into the field labelled by its key, then press the button named `button`."""
    for label, value in fields.items():
        form.get_by_label(label).fill(value)
    form.get_by_role("button", name=button).click()


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
