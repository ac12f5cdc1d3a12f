"""A view per viewer, in a real browser (issue 28, item 1): two dashboards on different runs, each embedded live
view naming its own page's run (the panel's title, as text) for a minute while both learn, and a switch on one
page leaving the other's view alone.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from typing import TYPE_CHECKING

import pytest

from horde.server import Settings

from .conftest import ON_DASHBOARD, RunningServer, free_port, serve_in_thread, viser_view

if TYPE_CHECKING:
    from playwright.sync_api import Browser, Frame, Page

pytestmark = ON_DASHBOARD

WATCH_SECONDS = 60  # both runs learning, both views watched: the minute
CHECK_EVERY = 5  # seconds between looks at both views
TOUR_DONE = "localStorage.setItem('horde-lab-tour-done', '1')"


@pytest.fixture
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[RunningServer]:
    settings = Settings(
        data=tmp_path_factory.mktemp("viewers-data"), token=None, viser_port=free_port(), snapshot_every=3600.0
    )
    with serve_in_thread(settings) as running:
        yield running


def launch(server: RunningServer, name: str) -> str:
    body = {"scenario": "experiment1", "seed": 3, "name": name, "protocol": {"episodes": 0}}
    response = server.client.post("/api/runs", params={"hz": 20, "start": True}, json=body)
    assert response.status_code == 201, response.text
    return str(response.json()["id"])


def open_dashboard(browser: Browser, server: RunningServer) -> Page:
    context = browser.new_context(viewport={"width": 1024, "height": 768})
    context.add_init_script(TOUR_DONE)
    page = context.new_page()
    page.set_default_timeout(60_000)  # two software-WebGL views on a loaded machine
    page.goto(server.url)
    return page


def select(page: Page, run_id: str, view_url: str) -> Frame:
    """Select the run in the page's list; its embedded view, scrolled back into sight (Chromium runs no
    cross-origin frame outside the viewport, and the page's layout moves when the selection changes)."""
    page.locator(f'li.run-item[data-run="{run_id}"] button.run-select').click()
    page.locator(f'li.run-item.selected[data-run="{run_id}"]').wait_for()
    return viser_view(page, view_url)


def shown_by(frame: Frame, label: str) -> None:
    """Wait (bounded) until the view's panel names the run `label` as the one it shows (in its title, which
    its bar shows while minimized, as it starts)."""
    frame.get_by_text(f"Showing {label}", exact=True).wait_for(timeout=60_000)


def title(frame: Frame) -> str:
    return str(frame.get_by_text("Showing ").first.inner_text())


@pytest.mark.timeout(360)
def test_two_pages_each_see_their_own_run_and_a_switch_on_one_leaves_the_other(
    browser: Browser, server: RunningServer
) -> None:
    alpha, beta = launch(server, "alpha"), launch(server, "beta")
    labels = {alpha: f"alpha [{alpha}]", beta: f"beta [{beta}]"}
    view_url = server.client.get("/api/view").json()["url"]
    pages = [open_dashboard(browser, server), open_dashboard(browser, server)]
    frames = []
    for page, run_id in zip(pages, (alpha, beta), strict=True):
        frame = select(page, run_id, view_url)
        shown_by(frame, labels[run_id])
        frames.append(frame)

    began = time.monotonic()
    while time.monotonic() - began < WATCH_SECONDS:
        for frame, own in zip(frames, (alpha, beta), strict=True):
            assert title(frame) == f"Showing {labels[own]}"
        time.sleep(CHECK_EVERY)
    steps = {run: server.client.get(f"/api/runs/{run}").json()["step"] for run in (alpha, beta)}
    assert min(steps.values()) > 100, f"both runs learned while watched: {steps}"

    # The first page switches to beta: its view follows. Then the second to alpha: its view follows, and
    # the first page's (in sight, so drawing) stays on beta.
    shown_by(select(pages[0], beta, view_url), labels[beta])
    shown_by(select(pages[1], alpha, view_url), labels[alpha])
    assert title(frames[0]) == f"Showing {labels[beta]}"
    for page in pages:
        page.context.close()
