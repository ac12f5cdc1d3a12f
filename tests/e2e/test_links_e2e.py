"""Links to a run, in a real browser (issue 28, item 2): the address names the selected run and tab, so a reload,
the back button and a shared link restore them, with the run's kept evaluations; a link to an unknown run opens
the dashboard with a notice. And present mode on the run the link opened."""

from __future__ import annotations

import re
from collections.abc import Iterator
from typing import TYPE_CHECKING

import pytest
from playwright.sync_api import expect

from horde.server import Settings

from .conftest import ON_DASHBOARD, RunningServer, collect_errors, serve_in_thread

if TYPE_CHECKING:
    from playwright.sync_api import Browser, Page

pytestmark = ON_DASHBOARD


@pytest.fixture
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[RunningServer]:
    settings = Settings(data=tmp_path_factory.mktemp("links-data"), token=None, snapshot_every=3600.0)
    with serve_in_thread(settings) as running:
        yield running


def truth_cell(page: Page, demon: str) -> str:
    return page.locator(f'table.demon-table tr[data-demon="{demon}"] td').nth(2).inner_text().strip()


@pytest.mark.timeout(180)
def test_a_link_restores_the_run_its_tab_and_its_evaluations(browser: Browser, server: RunningServer) -> None:
    api = server.client
    run = api.post("/api/runs", json={"scenario": "experiment1", "seed": 7, "protocol": {"episodes": 0}}).json()["id"]
    api.post(f"/api/runs/{run}/step", json={"steps": 300})
    request = {"demon": "steps_to_end", "from": [0, 0], "episodes": 20}
    kept = api.post(f"/api/runs/{run}/evaluate", json=request).json()
    context = browser.new_context(viewport={"width": 1280, "height": 900})
    context.add_init_script("localStorage.setItem('horde-lab-tour-done', '1')")
    page = context.new_page()
    page.set_default_timeout(30_000)
    errors = collect_errors(page)

    page.goto(f"{server.url}/?run={run}&tab=live")  # a shared link
    page.locator(f'li.run-item.selected[data-run="{run}"]').wait_for()
    cell = page.locator('table.demon-table tr[data-demon="steps_to_end"] td').nth(2)
    expect(cell, "the kept evaluation's truth").not_to_have_text("–")
    assert float(truth_cell(page, "steps_to_end").split()[0]) == pytest.approx(kept["exact"], rel=1e-3)

    page.get_by_role("tab", name="World editor").click()
    expect(page).to_have_url(re.compile(rf"\?run={run}&tab=world$"))
    page.reload()
    expect(page.get_by_role("tab", name="World editor")).to_have_attribute("aria-selected", "true")
    page.locator(f'li.run-item.selected[data-run="{run}"]').wait_for()
    page.get_by_role("tab", name="Live").click()
    expect(cell, "shown again after the reload").not_to_have_text("–")

    page.go_back()  # to the World editor, then back again to where the link opened
    expect(page.get_by_role("tab", name="World editor")).to_have_attribute("aria-selected", "true")
    page.go_back()
    expect(page.get_by_role("tab", name="Live")).to_have_attribute("aria-selected", "true")
    expect(page).to_have_url(re.compile(rf"\?run={run}&tab=live$"))

    # Present mode, for the projector: the run's view and charts, the rest hidden; Escape brings it back.
    page.get_by_role("button", name="Present", exact=True).click()
    expect(page.locator("aside.sidebar")).to_be_hidden()
    expect(page.locator("table.demon-table")).to_be_hidden()
    expect(page.locator("section.charts-panel")).to_be_visible()
    expect(page.locator("section.viser-panel")).to_be_visible()
    page.keyboard.press("Escape")
    expect(page.locator("aside.sidebar")).to_be_visible()

    page.goto(f"{server.url}/?run=no-such-run&tab=live")
    expect(page.get_by_role("alert")).to_contain_text('No run "no-such-run" on this server')
    expect(page.get_by_role("heading", name="Horde Lab")).to_be_visible()
    assert page.locator("li.run-item.selected").count() == 0
    assert [e for e in errors if "404" not in e] == [], errors
    context.close()
