"""A stream run in a real browser: listed in the dashboard, its strip chart (predictions beside realised
returns) drawn from records pushed over REST, and its phase plane in the same embedded live view."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from polling import wait_until
from stream_specs import LIGHT_WHEEL, nexting, robot, tiled

from .conftest import ON_DASHBOARD, PAGE_CATCHES_UP_MS, SHOTS, RunningServer, page_viewer, viser_view

if TYPE_CHECKING:
    from playwright.sync_api import Browser

# Pixels of a colour on a uPlot canvas (the prediction's blue, the return's near-black), for "is it drawn".
PIXELS_OF = """([selector, rgb]) => {
    const canvas = document.querySelector(selector);
    if (!canvas) return 0;
    const data = canvas.getContext("2d").getImageData(0, 0, canvas.width, canvas.height).data;
    let n = 0;
    for (let i = 0; i < data.length; i += 4) {
        if (Math.abs(data[i] - rgb[0]) < 40 && Math.abs(data[i + 1] - rgb[1]) < 40
            && Math.abs(data[i + 2] - rgb[2]) < 40 && data[i + 3] > 200) n++;
    }
    return n;
}"""
PHASE_MAP = """() => !!window.__viserMutable?.nodeRefFromName?.["/phase/map"]"""

pytestmark = ON_DASHBOARD


def spec() -> dict[str, Any]:
    return robot(tiled(LIGHT_WHEEL, tilings=4, tiles=6, size=256), nexting("light", 0.8), nexting("wheel", 0.5))


def records(start: int, n: int) -> list[dict[str, Any]]:
    return [{"observation": [0.5 + 0.4 * math.sin(k / 20), math.cos(k / 7)], "action": k % 2}
            for k in range(start, start + n)]  # fmt: skip


def test_pushed_records_draw_the_strip_chart_and_the_phase_plane(server: RunningServer, browser: Browser) -> None:
    api = server.client
    stream = api.post("/api/streams", json=spec()).json()["id"]
    assert api.post(f"/api/streams/{stream}/records", json={"records": records(0, 300)}).status_code == 200
    errors: list[str] = []
    page = browser.new_page(viewport={"width": 1280, "height": 1100})
    try:
        page.on("pageerror", lambda e: errors.append(str(e)))
        page.goto(server.url)
        row = page.locator(f'li.run-item[data-stream="{stream}"]')
        row.wait_for(timeout=PAGE_CATCHES_UP_MS)
        assert "300 records learned of 300 received" in row.inner_text()
        row.locator("button").click()
        strip = page.locator('[data-testid="stream-strip"]')
        strip.wait_for(state="visible", timeout=PAGE_CATCHES_UP_MS)
        assert "predictions beside realised returns" in strip.locator("h2").inner_text()
        assert "Dashed black: the discounted return that actually followed" in strip.inner_text()
        canvas = 'figure[data-demon="light_g0.8"] canvas'
        page.locator(canvas).wait_for(timeout=PAGE_CATCHES_UP_MS)
        page.wait_for_function(f"() => ({PIXELS_OF})([{canvas!r}, [0, 114, 178]]) > 50", timeout=PAGE_CATCHES_UP_MS)
        assert page.evaluate(PIXELS_OF, [canvas, [17, 24, 39]]) > 50, "the realised return is drawn beside it"
        sensor_canvas = 'figure[data-sensor="light"] canvas'
        page.locator(sensor_canvas).wait_for(timeout=PAGE_CATCHES_UP_MS)
        caption = page.locator('figure[data-demon="light_g0.8"] figcaption')
        caption.filter(has_text="mean |prediction − return|").wait_for(timeout=PAGE_CATCHES_UP_MS)
        # The stream's demon table: each demon's prediction at the last record, as the REST table says.
        table = page.locator('[data-testid="stream-demons"]')
        table.locator('tr[data-demon="light_g0.8"]').wait_for(timeout=PAGE_CATCHES_UP_MS)
        rest = {d["name"]: d for d in api.get(f"/api/streams/{stream}/demons").json()}
        shown = table.locator('tr[data-demon="light_g0.8"] td').nth(1).inner_text()
        assert abs(float(shown) - rest["light_g0.8"]["prediction"]) < 1e-3, (shown, rest["light_g0.8"])
        link = page.get_by_test_id("stream-snapshot").get_attribute("href")
        assert link == f"/api/streams/{stream}/snapshot"
        assert api.get(link).json()["learned"] == 300
        # More records arrive: the list and the chart follow.
        assert api.post(f"/api/streams/{stream}/records", json={"records": records(300, 200)}).status_code == 200
        page.locator('[data-testid="stream-strip"] p.hint', has_text="500 records learned").wait_for(
            timeout=PAGE_CATCHES_UP_MS
        )
        # The same embedded live view now draws the stream run's phase plane.
        viewer = page_viewer(page)  # the page tells the server its choice after the selection shows: poll
        wait_until(lambda: api.get("/api/view", params={"viewer": viewer}).json()["run"] == stream,
                   "selecting a stream run shows it in the live view", 15)  # fmt: skip
        frame = page.frame_locator("iframe.viser-frame")
        frame.locator("body").wait_for(timeout=PAGE_CATCHES_UP_MS)
        viser = viser_view(page, api.get("/api/view").json()["url"])
        viser.wait_for_function(PHASE_MAP, timeout=60_000)  # a GPU-less client on a busy machine is slow
        SHOTS.mkdir(parents=True, exist_ok=True)
        page.screenshot(path=str(SHOTS / "stream-strip.png"), full_page=True)
        strip.screenshot(path=str(SHOTS / "stream-strip-chart.png"))
        assert errors == []
    finally:
        page.close()
