"""Horde scale in the browser: scenarios/nexting.toml launched from the dashboard, at full speed, with the
dashboard and the embedded viser live view open and streaming. Prints the run's steps per second and
the page's responsiveness (the longest gap between animation frames, the time for a click to take
effect); asserts only that the run learns and the page stays responsive, within generous bounds (the
machine may be shared, and speed is measured, not asserted: README and docs/performance.md)."""

from __future__ import annotations

import re
import time

import pytest
from playwright.sync_api import Browser, expect

from .conftest import (
    ON_DASHBOARD,
    RunningServer,
    browser_page,
    viser_view,
)
from .test_dashboard_live_e2e import AGENT_NODE, viser_race

SECONDS = 10.0  # measured while both pages stream
MAX_FRAME_GAP_MS = 3000.0  # generous: a frame gap this long is a page that froze
MAX_CLICK_S = 15.0

pytestmark = [*ON_DASHBOARD, pytest.mark.serial]  # a pause within a bound while nexting learns: alone

FRAME_GAPS = """() => {
  window.__gaps = [];
  let last = performance.now();
  const tick = (t) => { window.__gaps.push(t - last); last = t; requestAnimationFrame(tick); };
  requestAnimationFrame(tick);
}"""


def test_nexting_launched_from_the_dashboard_learns_and_the_page_stays_responsive(
    browser: Browser, server: RunningServer
) -> None:
    api = server.client
    with browser_page(browser, 1280, 1000, ignore=viser_race) as (page, errors):
        page.set_default_timeout(60_000)
        page.goto(server.url)
        launcher = page.locator("section.launcher")
        launcher.get_by_label("Scenario").select_option("nexting")
        launcher.get_by_label("Steps/s").fill("")  # full speed
        launcher.get_by_role("button", name="Launch").click()
        selected = page.locator("li.run-item.selected")
        selected.wait_for()
        run = selected.get_attribute("data-run")
        assert run, "the launched run is selected"

        # The live view follows the selected run and draws its agent.
        view_url = api.get("/api/view").json()["url"]
        frame = page.frame_locator("iframe.viser-frame")
        view = viser_view(page, view_url)
        view.wait_for_function(AGENT_NODE, timeout=120_000)
        assert frame.get_by_text(re.compile(rf"^Showing .*{run}")).is_visible(), "the view's bar names its run"

        # Steps per second of the run, and the gaps between the page's animation frames, meanwhile.
        page.evaluate(FRAME_GAPS)
        first = api.get(f"/api/runs/{run}").json()
        began = time.monotonic()
        time.sleep(SECONDS)
        last = api.get(f"/api/runs/{run}").json()
        seconds = time.monotonic() - began
        gaps = page.evaluate("window.__gaps")
        rate = (last["step"] - first["step"]) / seconds

        # A click takes effect: pause the run from the run list, until its badge says so.
        clicked = time.monotonic()
        page.locator(f'li.run-item[data-run="{run}"]').get_by_role("button", name=re.compile("^Pause run")).click()
        badge = page.locator(f'li.run-item[data-run="{run}"] .badge')
        expect(badge, "the run's badge within 60 s of the click").to_have_text("paused", timeout=60_000)
        click_s = time.monotonic() - clicked
        demons = len(last["demons"])

    frames = sorted(gaps)
    longest = frames[-1] if frames else float("inf")
    median = frames[len(frames) // 2] if frames else float("inf")
    print(
        f"\nnexting live ({demons} demons) with the dashboard and the viser view open: {rate:.1f} steps/s over "
        f"{seconds:.1f} s; animation frames: {len(frames)}, median gap {median:.0f} ms, longest {longest:.0f} ms; "
        f"a click (pause) took effect in {click_s:.2f} s"
    )
    assert last["step"] > first["step"], "the run learned while the pages streamed"
    assert errors == [], errors
    assert frames, "the page drew animation frames"
    assert longest < MAX_FRAME_GAP_MS, f"the page froze for {longest:.0f} ms (bound {MAX_FRAME_GAP_MS:.0f})"
    assert click_s < MAX_CLICK_S, f"a click took {click_s:.1f} s to take effect (bound {MAX_CLICK_S:.0f})"
