"""A Gymnasium world in the browser: scenarios/mountaincar-nexting.toml launched from the dashboard's launcher,
watched in the demon table (predictions moving) and in the embedded live view (a phase plane of position and
velocity), then run at full speed with both pages open. Prints the run's steps per second, wall and the
server process's CPU; asserts only that it learns (speed is measured, not asserted: README)."""

from __future__ import annotations

import re
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from playwright.sync_api import expect

from horde.server import Settings

from .conftest import CHROMIUM, CHROMIUM_ARGS, ROOT, RunningServer, free_port, serve_in_thread, viser_view
from .test_dashboard_live_e2e import viser_race

DIST = ROOT / "frontend" / "dist"
PHASE_MAP = """() => !!window.__viserMutable?.nodeRefFromName?.["/phase/map"]"""
PHASE_AGENT = """() => !!window.__viserMutable?.nodeRefFromName?.["/phase/agent"]"""
NUMBER = re.compile(r"^-?\d+(\.\d+)?(e[+-]\d+)?$")
SECONDS = 8.0  # full speed measured over this long, with both pages streaming

pytestmark = [
    pytest.mark.e2e,
    pytest.mark.slow,
    pytest.mark.skipif(not CHROMIUM.exists(), reason="needs Debian's chromium at /usr/bin/chromium"),
    pytest.mark.skipif(not (DIST / "index.html").exists(), reason="frontend/dist is not built: run `make frontend`"),
]


def see_the_prediction_move(page: Any, demon: str) -> None:
    """The demon table lists the demon, and its prediction takes three different values as the car drives."""
    row = page.locator(f'table.demon-table tr[data-demon="{demon}"]')
    row.wait_for()
    now = row.locator("td").first
    expect(now, f"{demon} has a prediction").to_have_text(NUMBER)
    seen = {now.inner_text().strip()}
    for _ in range(2):
        pattern = re.compile("^(" + "|".join(re.escape(t) for t in sorted(seen | {"–"})) + ")$")
        expect(now, f"the prediction moves on from {seen}").not_to_have_text(pattern)
        seen.add(now.inner_text().strip())
    assert len(seen) == 3 and all(NUMBER.match(v) for v in seen), seen


@pytest.fixture
def server(tmp_path: Path) -> Iterator[RunningServer]:
    settings = Settings(data=tmp_path / "data", token=None, viser_port=free_port(), snapshot_every=3600.0)
    with serve_in_thread(settings) as running:
        yield running


def test_mountaincar_launched_from_the_dashboard_shows_its_demons_and_phase_plane(server: RunningServer) -> None:
    from playwright.sync_api import sync_playwright

    api = server.client
    errors: list[str] = []
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
        try:
            page = browser.new_page(viewport={"width": 1280, "height": 1000})
            page.set_default_timeout(60_000)
            page.on(
                "console", lambda m: errors.append(m.text) if m.type == "error" and not viser_race(m.text) else None
            )
            page.on("pageerror", lambda e: errors.append(str(e)))
            page.goto(server.url)
            launcher = page.locator("section.launcher")
            launcher.get_by_label("Scenario").select_option("mountaincar-nexting")
            expect(launcher.locator(".scenario-description")).to_contain_text("Gymnasium MountainCar-v0")
            launcher.get_by_label("Steps/s").fill("50")
            launcher.get_by_role("button", name="Launch").click()
            selected = page.locator("li.run-item.selected")
            selected.wait_for()
            run = selected.get_attribute("data-run")
            assert run, "the launched run is selected"
            assert api.get(f"/api/runs/{run}").json()["status"] == "running"

            see_the_prediction_move(page, "position_g0.9_on")
            demons = api.get(f"/api/runs/{run}/demons").json()
            assert len(demons) == 131 and all(d["metrics"]["rupee"] is not None for d in demons)

            # The embedded live view draws the run's phase plane: a value map with the car (its trail ends there) on it.
            view_url = api.get("/api/view").json()["url"]
            view = viser_view(page, view_url)
            view.wait_for_function(PHASE_MAP, timeout=120_000)
            view.wait_for_function(PHASE_AGENT, timeout=60_000)

            # Full speed with both pages streaming: steps per second, wall and the server process's CPU.
            api.patch(f"/api/runs/{run}", json={"hz": None})
            first, began, cpu = api.get(f"/api/runs/{run}").json(), time.monotonic(), time.process_time()
            time.sleep(SECONDS)
            last = api.get(f"/api/runs/{run}").json()
            seconds, cpu_seconds = time.monotonic() - began, time.process_time() - cpu
        finally:
            browser.close()

    rate = (last["step"] - first["step"]) / seconds
    print(
        f"\nmountaincar-nexting live (131 demons) with the dashboard and the viser view open: {rate:.0f} steps/s "
        f"over {seconds:.1f} s wall, {cpu_seconds:.1f} s CPU of the server process (learner, server, view)"
    )
    assert last["step"] > first["step"], "the run learned at full speed"
    assert errors == [], errors
