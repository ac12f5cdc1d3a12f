"""The whole picture in a real browser: the dashboard with the real viser live view embedded beside
the demon table, following a learning run. It takes the README's main screenshot (dashboard-live.png).
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from horde.server import Settings

from .conftest import CHROMIUM, CHROMIUM_ARGS, ROOT, SHOTS, RunningServer, free_port, serve_in_thread

DIST = ROOT / "frontend" / "dist"
AGENT_NODE = """() => !!window.__viserMutable?.nodeRefFromName?.["/agent"]"""

pytestmark = [
    pytest.mark.e2e,
    pytest.mark.skipif(not CHROMIUM.exists(), reason="needs Debian's chromium at /usr/bin/chromium"),
    pytest.mark.skipif(not (DIST / "index.html").exists(), reason="frontend/dist is not built: run `make frontend`"),
]


@pytest.fixture
def server(tmp_path: Path) -> Iterator[RunningServer]:
    settings = Settings(data=tmp_path / "data", token=None, viser_port=free_port(), snapshot_every=3600.0)
    with serve_in_thread(settings) as running:
        yield running


def viser_race(text: str) -> bool:
    """viser's own client logs this when an update reaches a GUI component that the panel has just removed
    (the run's demon folder is rebuilt when the view switches runs): a race inside viser, harmless."""
    return text.startswith("Tried to update non-existent component")


def test_the_dashboard_embeds_the_live_view_of_the_selected_run(server: RunningServer) -> None:
    from playwright.sync_api import sync_playwright

    api = server.client
    run = api.post("/api/runs", params={"hz": 30, "start": True}, json={"scenario": "experiment1", "seed": 5}).json()[
        "id"
    ]
    errors: list[str] = []
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
        try:
            page = browser.new_page(viewport={"width": 1280, "height": 1000})
            page.on(
                "console", lambda m: errors.append(m.text) if m.type == "error" and not viser_race(m.text) else None
            )
            page.on("pageerror", lambda e: errors.append(str(e)))
            page.goto(server.url)
            page.locator(f'li.run-item[data-run="{run}"] button.run-select').click()
            page.locator(f'li.run-item.selected[data-run="{run}"]').wait_for()
            assert api.get("/api/view").json()["run"] == run, "selecting a run shows it in the live view"

            frame = page.frame_locator("iframe.viser-frame")
            view = next(f for f in page.frames if f.url.startswith(api.get("/api/view").json()["url"]))
            view.wait_for_function(AGENT_NODE, timeout=30_000)
            assert frame.get_by_text("Connected").first.is_visible()

            page.get_by_label("Rollouts per evaluation").fill("200")
            page.get_by_role("button", name="Evaluate steps_to_end").click()
            page.wait_for_timeout(4000)  # a few seconds of learning at 30 steps a second
            for close in frame.locator(".mantine-Notification-root button").all():
                close.click()  # the "software WebGL" notice of a GPU-less browser
            page.evaluate("window.scrollTo(0, 0)")
            SHOTS.mkdir(parents=True, exist_ok=True)
            page.screenshot(path=str(SHOTS / "dashboard-live.png"), full_page=True)
        finally:
            browser.close()
    assert errors == []
