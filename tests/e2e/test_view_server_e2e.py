"""The live view inside the real server, in headless Chromium: a run stepped through the REST API moves
the agent in the browser.

The agent's position is read from the viser client's test hook, `window.__viserMutable.nodeRefFromName`,
whose entry "/agent" is the agent node's THREE.Object3D (position in scene units: world units x scale).
"""

from __future__ import annotations

from playwright.sync_api import Browser

from horde.scenarios import find_scenario

from .conftest import (
    AGENT_AT,
    IN_BROWSER,
    PAGE_CATCHES_UP_MS,
    ROOT,
    RunningServer,
    browser_page,
    drawn_at,
)

pytestmark = IN_BROWSER


def test_a_run_stepped_over_rest_moves_the_agent_in_the_browser(browser: Browser, server: RunningServer) -> None:
    api = server.client
    run = api.post("/api/runs", json={"scenario": "experiment1", "seed": 3}).json()["id"]
    view = api.post("/api/view", json={"viewer": "rest-stepping-page", "run": run}).json()  # a tab's own view
    world = find_scenario("experiment1").world

    with browser_page(browser, 1280, 800) as (page, errors):
        page.goto(view["url"])
        page.wait_for_function(AGENT_AT, arg=drawn_at(world, 0.0, 0.0), timeout=30_000)  # experiment1 starts at (0, 0)

        # Step over REST until the agent has left its start (a bump into the wall leaves it there).
        agent = {"x": 0.0, "y": 0.0}
        for _ in range(50):
            agent = api.post(f"/api/runs/{run}/step", json={"steps": 1}).json()["agent"]
            if (agent["x"], agent["y"]) != (0.0, 0.0):
                break
        assert (agent["x"], agent["y"]) != (0.0, 0.0)
        page.wait_for_function(AGENT_AT, arg=drawn_at(world, agent["x"], agent["y"]), timeout=PAGE_CATCHES_UP_MS)

        # A few hundred more steps: the agent follows again, and the picture has a value map.
        agent = api.post(f"/api/runs/{run}/step", json={"steps": 300}).json()["agent"]
        page.wait_for_function(AGENT_AT, arg=drawn_at(world, agent["x"], agent["y"]), timeout=PAGE_CATCHES_UP_MS)
        page.wait_for_timeout(1000)
        artifacts = ROOT / "test-artifacts"
        artifacts.mkdir(exist_ok=True)
        page.screenshot(path=str(artifacts / "view-server.png"))
    assert errors == []
