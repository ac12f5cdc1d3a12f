"""Baird's counterexample in the browser, as a class sees it: scenarios/baird.toml launched from the dashboard's
launcher at full speed; near step 10,000 (seconds on a quiet machine, a minute or more beside the other tests) the
demon table marks `td` diverged (and only it), its chart, ticked in the table, is drawn on a log scale that its caption
names (GTD's is not), and the embedded live view draws the star. The page is saved as
test-artifacts/screenshots/baird.png (`make screenshots` copies it to docs/)."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from playwright.sync_api import Browser, expect

from horde.server import Settings

from .conftest import CHROMIUM, ROOT, SHOTS, RunningServer, browser_page, free_port, serve_in_thread, viser_view
from .test_dashboard_live_e2e import viser_race

DIST = ROOT / "frontend" / "dist"
STAR = """() => !!window.__viserMutable?.nodeRefFromName?.["/star/agent"]"""

pytestmark = [
    pytest.mark.e2e,
    pytest.mark.slow,
    pytest.mark.skipif(not CHROMIUM.exists(), reason="needs Debian's chromium at /usr/bin/chromium"),
    pytest.mark.skipif(not (DIST / "index.html").exists(), reason="frontend/dist is not built: run `make frontend`"),
]


@pytest.fixture
def server(tmp_path: Path) -> Iterator[RunningServer]:
    settings = Settings(data=tmp_path / "data", token=None, viser_port=free_port(), snapshot_every=3600.0)
    with serve_in_thread(settings) as running:
        yield running


def test_baird_launched_from_the_dashboard_marks_td_diverged_and_charts_it_on_a_log_scale(
    browser: Browser, server: RunningServer
) -> None:
    with browser_page(browser, 1280, 2400, ignore=viser_race) as (page, errors):  # the whole page: the view too
        page.set_default_timeout(60_000)
        page.goto(server.url)
        launcher = page.locator("section.launcher")
        launcher.get_by_label("Scenario").select_option("baird")
        expect(launcher.locator(".scenario-description")).to_contain_text("Baird's counterexample")
        launcher.get_by_label("Steps/s").fill("")
        launcher.get_by_role("button", name="Launch").click()
        page.locator("li.run-item.selected").wait_for()

        rows = {name: page.locator(f'table.demon-table tr[data-demon="{name}"]') for name in ("td", "gtd")}
        rows["td"].get_by_label("Chart td").check()
        rows["gtd"].get_by_label("Chart gtd").check()
        # The run's own pace: its worker is niced below the API and the other tests, so on a busy machine the
        # 10,000 steps take minutes; the run's 12 episodes (about 12,000 steps) end after TD has diverged.
        expect(rows["td"].locator(".tag.diverged"), "TD diverges near step 10,000").to_be_visible(timeout=300_000)
        expect(rows["gtd"].locator(".tag.diverged")).to_be_hidden()
        expect(page.locator('figure.chart[data-demon="td"] figcaption')).to_contain_text("log scale")
        expect(page.locator('figure.chart[data-demon="gtd"] figcaption')).not_to_contain_text("log scale")
        view_url = server.client.get("/api/view").json()["url"]
        view = viser_view(page, view_url)
        view.wait_for_function(STAR, timeout=60_000)
        page.wait_for_timeout(2000)  # a few frames of the view, for the picture
        view.locator(".mantine-Notification-root button").first.click()  # "software WebGL" note
        SHOTS.mkdir(parents=True, exist_ok=True)
        page.screenshot(path=str(SHOTS / "baird.png"), full_page=True)
    assert errors == [], errors
