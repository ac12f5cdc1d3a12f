"""The live view in a real browser: headless Chromium (Debian's) driven by Playwright.

The test reads the agent's position from the viser client's own test hook: the client exposes its
mutable viewer state as `window.__viserMutable`, whose `nodeRefFromName[name]` is the THREE.Object3D
of a scene node; `.position` is the node's position in its parent frame (here the world frame).
"""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from playwright.sync_api import Browser

from horde.runs.manager import RunManager
from horde.scenarios import load_scenario
from horde.view import LiveView, ManagerSource
from horde.view.scene import agent_radius
from polling import wait_until

from .conftest import AGENT_AT, IN_BROWSER, PAGE_CATCHES_UP_MS, ROOT, SHOTS, browser_page, drawn_at, free_port

AGENT_POSITION = """() => {
    const node = window.__viserMutable?.nodeRefFromName?.["/agent"];
    return node ? [node.position.x, node.position.y, node.position.z] : null;
}"""

pytestmark = IN_BROWSER


@pytest.fixture
def live() -> Iterator[tuple[LiveView, ManagerSource]]:
    """The live view over the server's run manager (no store), holding one created run of experiment1."""
    manager = RunManager()
    manager.create(load_scenario(ROOT / "scenarios" / "experiment1.toml"), hz=10.0)
    source = ManagerSource(manager)
    view = LiveView(source, host="127.0.0.1", port=free_port())
    view.start()
    yield view, source
    view.stop()
    manager.stop()


def test_the_agent_moves_in_the_browser_when_the_run_steps(
    browser: Browser, live: tuple[LiveView, ManagerSource]
) -> None:
    view, source = live
    run = source.list_runs()[0][0]
    spec = source.snapshot(run).spec
    world = spec.world

    with browser_page(browser, 1280, 800) as (page, errors):
        page.goto(view.url)
        # The node can be read before its pose is applied (a fresh clone once read the origin here): wait for the
        # agent drawn at experiment1's start, (0, 0), then read its height.
        page.wait_for_function(AGENT_AT, arg=drawn_at(world, 0.0, 0.0), timeout=30_000)
        _, _, z = page.evaluate(AGENT_POSITION)
        assert z == pytest.approx(agent_radius(spec.world))

        # The panel starts minimized (embedded, it would cover the world): one click opens it.
        step = page.get_by_role("button", name="Step", exact=True)
        assert not step.is_visible()
        page.get_by_role("button", name="Expand panel").click()
        # Step with the GUI's button until the agent has left its start (a bump leaves it there).
        for _ in range(30):
            before = source.snapshot(run).total_steps
            step.click()
            wait_until(lambda b=before: source.snapshot(run).total_steps > b, "the Step button to step the run", 30.0)
            snap = source.snapshot(run)
            if (snap.x, snap.y) != (0.0, 0.0):
                break
        assert (snap.x, snap.y) != (0.0, 0.0)
        page.wait_for_function(AGENT_AT, arg=drawn_at(world, snap.x, snap.y), timeout=PAGE_CATCHES_UP_MS)

        # Learn a while, so that the picture shows a value map worth seeing.
        source.step(run, 2000)
        snap = source.snapshot(run)
        page.wait_for_function(AGENT_AT, arg=drawn_at(world, snap.x, snap.y), timeout=PAGE_CATCHES_UP_MS)
        page.wait_for_timeout(1500)  # a value map refresh and a chart refresh
        for close in page.locator(".mantine-Notification-root button").all():
            close.click()  # the "software WebGL" notice of a GPU-less browser
        page.wait_for_timeout(300)
        SHOTS.mkdir(parents=True, exist_ok=True)
        page.screenshot(path=str(SHOTS / "view.png"))
    assert errors == []
