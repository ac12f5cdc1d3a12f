"""The demon editor's learner and step-size choices, and the demon table's "α now" column, in a browser."""

from __future__ import annotations

from typing import TYPE_CHECKING

from playwright.sync_api import expect

from . import test_dashboard_e2e as dashboard
from .test_dashboard_e2e import NUMBER, Server, cell, cell_at, new_demon

console, page, server = dashboard.console, dashboard.page, dashboard.server  # the dashboard tests' fixtures

if TYPE_CHECKING:
    from playwright.sync_api import Page

STEP_SIZE_COLUMN = 8  # prediction now, 3 of evaluation, thesis, RUPEE, UDE, then the step size now


def test_an_autostep_demon_joins_and_shows_its_step_size(page: Page, server: Server) -> None:
    run_id, form = new_demon(page, server, "auto_steps")
    learners = form.get_by_label("Learner").locator("option")
    expect(learners.filter(has_text="tdrc: TDRC")).to_have_count(1)  # the registry's (GET /api/learners)
    expect(learners.filter(has_text="gtd2: GTD2")).to_have_count(1)
    expect(learners.filter(has_text="gtd1: GTD, the original")).to_have_count(1)
    form.get_by_label("Learner").select_option("td")
    options = form.get_by_label("Step size").locator("option").all_inner_texts()
    assert any(text.startswith("autostep (TD only):") for text in options), options  # one line of explanation
    form.get_by_label("Step size").select_option("autostep")
    form.get_by_role("button", name="Add to run").click()
    page.get_by_role("status").filter(has_text="Added demon 'auto_steps'").wait_for()
    added = next(d for d in server.client.get(f"/api/runs/{run_id}/demons").json() if d["name"] == "auto_steps")
    assert added["spec"]["learner"] == "td" and added["spec"]["step_size"] == "autostep"

    page.get_by_role("tab", name="Live").click()
    page.get_by_role("columnheader", name="α now").wait_for()
    page.locator('table.demon-table tr[data-demon="auto_steps"]').wait_for()
    expect(cell_at(page, "auto_steps", STEP_SIZE_COLUMN), "the autostep demon shows its step size").to_have_text(NUMBER)
    assert NUMBER.match(cell(page, "base", STEP_SIZE_COLUMN)) is not None  # constant demons show alpha
