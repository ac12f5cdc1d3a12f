"""The Lab tab in a real browser (issue 25): the list of the textbook experiments, each with what the class
should see; a figure run with a smaller set-up (2 runs) fills in as a study and draws its learning curves with
their 95 % bootstrap bands under its caption; a set-up past its bound shows the 422 at its field.

The server runs studies in process here (HORDE_STUDY_EXECUTOR=local), as test_studies_e2e.py does.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import TYPE_CHECKING

import pytest

from horde.server import Settings

from .conftest import ON_DASHBOARD, PAGE_CATCHES_UP_MS, SHOTS, RunningServer, collect_errors, serve_in_thread

if TYPE_CHECKING:
    from playwright.sync_api import Browser


pytestmark = ON_DASHBOARD


@pytest.fixture(scope="module")
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[RunningServer]:
    settings = Settings(
        data=tmp_path_factory.mktemp("horde-data"), token=None, snapshot_every=3600.0, study_executor="local"
    )
    with serve_in_thread(settings) as running:
        yield running


def test_the_lab_runs_a_figure_and_draws_its_curves_with_bands(browser: Browser, server: RunningServer) -> None:
    from playwright.sync_api import expect

    context = browser.new_context(viewport={"width": 1440, "height": 1000})
    page = context.new_page()
    page.set_default_timeout(PAGE_CATCHES_UP_MS)
    errors = collect_errors(page)
    try:
        page.goto(server.url)
        page.get_by_role("heading", name="Horde Lab").wait_for()
        page.get_by_role("tab", name="Lab").click()
        panel = page.locator(".lab-panel")
        expect(panel.locator(".lab-item")).to_have_count(10)
        boyan = panel.get_by_test_id("lab-boyan-learners")
        expect(boyan.locator(".lab-see")).to_contain_text("TD and TDRC fastest")
        # a set-up past its bound: the server's 422 at the field, nothing launched
        walk = panel.get_by_test_id("lab-walk-1000")
        walk.get_by_label("order").fill("40")
        walk.get_by_role("button", name="Run live").click()
        expect(walk.locator("#lab-walk-1000-order-problem")).to_contain_text("less than or equal to 32")
        # the figure with 2 runs a configuration: it fills in, curves and bands drawn under its caption
        boyan.get_by_label("runs").fill("2")
        boyan.get_by_role("button", name="Run the figure").click()
        figure = panel.locator(".lab-figure")
        expect(figure.locator(".lab-caption")).to_contain_text("Boyan's chain")
        expect(figure.get_by_test_id("lab-status")).to_have_text("finished", timeout=120_000)
        curves = figure.locator(".study-curves svg.study-chart")
        expect(curves.locator("path.line")).to_have_count(5)  # TD, GTD, GTD2, TDC, TDRC
        expect(curves.locator("path.band")).to_have_count(5)
        box = curves.locator("path.band").first.bounding_box()
        assert box is not None and box["height"] > 2 and box["width"] > 100  # two runs differ: a band, not a line
        SHOTS.mkdir(parents=True, exist_ok=True)
        page.screenshot(path=str(SHOTS / "lab.png"), full_page=True)
    finally:
        context.close()
    assert [e for e in errors if "422" not in e] == [], "errors in the browser console"
