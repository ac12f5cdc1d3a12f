"""The whole picture in a real browser: the dashboard with the real viser live view embedded beside
the demon table, following a learning run. It takes the README's main screenshot (dashboard-live.png).
"""

from __future__ import annotations

from playwright.sync_api import Browser

from polling import wait_until

from .conftest import (
    ON_DASHBOARD,
    SHOTS,
    RunningServer,
    browser_page,
    page_viewer,
    viser_view,
)

AGENT_NODE = """() => !!window.__viserMutable?.nodeRefFromName?.["/agent"]"""

pytestmark = ON_DASHBOARD


def viser_race(text: str) -> bool:
    """viser's own client logs this when an update reaches a GUI component that the panel has just removed
    (the run's demon folder is rebuilt when the view switches runs): a race inside viser, harmless."""
    return text.startswith("Tried to update non-existent component")


def test_the_dashboard_embeds_the_live_view_of_the_selected_run(browser: Browser, server: RunningServer) -> None:
    api = server.client
    run = api.post("/api/runs", params={"hz": 30, "start": True}, json={"scenario": "experiment1", "seed": 5}).json()[
        "id"
    ]
    with browser_page(browser, 1280, 1000, ignore=viser_race) as (page, errors):
        page.goto(server.url)
        page.locator(f'li.run-item[data-run="{run}"] button.run-select').click()
        page.locator(f'li.run-item.selected[data-run="{run}"]').wait_for()
        viewer = page_viewer(page)  # the page tells the server its choice after the selection shows: poll
        wait_until(lambda: api.get("/api/view", params={"viewer": viewer}).json()["run"] == run,
                   "selecting a run shows it in the live view", 15)  # fmt: skip

        frame = page.frame_locator("iframe.viser-frame")
        view = viser_view(page, api.get("/api/view").json()["url"])
        view.wait_for_function(AGENT_NODE, timeout=30_000)
        assert frame.get_by_text(f"Showing experiment1 [{run}]").is_visible(), "the view's bar names its run"

        page.get_by_label("Rollouts per evaluation").fill("200")
        page.get_by_role("button", name="Evaluate steps_to_end").click()
        page.wait_for_timeout(4000)  # a few seconds of learning at 30 steps a second
        for close in frame.locator(".mantine-Notification-root button").all():
            close.click()  # the "software WebGL" notice of a GPU-less browser
        page.evaluate("window.scrollTo(0, 0)")
        SHOTS.mkdir(parents=True, exist_ok=True)
        page.screenshot(path=str(SHOTS / "dashboard-live.png"), full_page=True)
    assert errors == []
