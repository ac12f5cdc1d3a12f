"""Roles in the dashboard, in a real browser (issue 28, item 3): a page shows only the controls its token may use.

A viewer opens the teacher's invitation link: on every tab, no control that changes anything is shown, and
pressing every button it does show (twice, for those that ask to be pressed again) draws no 401 or 403 from
the server. A student's page shows the commands of the student's own run, not of the teacher's, and names
each run's owner. The teacher's Class tab issues a token, whose invitation link it shows once.
"""

from __future__ import annotations

import contextlib
import re
from collections.abc import Iterator
from typing import TYPE_CHECKING, Any

import pytest
from playwright.sync_api import TimeoutError as PlaywrightTimeout
from playwright.sync_api import expect

from horde.server import Settings

from .conftest import ON_DASHBOARD, RunningServer, collect_errors, serve_in_thread

if TYPE_CHECKING:
    from playwright.sync_api import Browser, Page

pytestmark = ON_DASHBOARD

TEACHER = {"Authorization": "Bearer s3cret"}
TABS = ("Live", "Class", "Protocol", "World editor", "Demon editor", "Studies")
# What a control that changes something on the server is called, by its accessible name (a viewer must see none):
# a demon's Remove is "Remove <demon>"; a region's or a study axis's Remove only edits a form on the page.
CHANGES = re.compile(
    r"^(Launch|Start|Pause|Step|Reset|Delete|Evaluate|Add to run|Save to library|Run|Cancel|Resume|"
    r"Issue a token|Revoke|Full speed|Really .*|Remove (?!region |axis ).*)( .*)?$"
)
# Buttons that change only this page (its tabs, help, large text, the tour, a filter...): pressed in the sweep.
NOT_PRESSED = re.compile(r"^(Present|Take the tour|Help.*|Exit present mode.*)$")


@pytest.fixture(scope="module")
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[RunningServer]:
    settings = Settings(data=tmp_path_factory.mktemp("roles"), token="s3cret", snapshot_every=3600.0)
    with serve_in_thread(settings) as running:
        yield running


def launch(server: RunningServer, headers: dict[str, str], name: str) -> str:
    body = {"scenario": "experiment1", "seed": 3, "name": name, "protocol": {"episodes": 0}}
    response = server.client.post("/api/runs", params={"hz": 10, "start": True}, json=body, headers=headers)
    assert response.status_code == 201, response.text
    return str(response.json()["id"])


def open_link(browser: Browser, link: str) -> tuple[Page, list[str], list[str]]:
    """A page at `link`; the console errors, and every answer of the server refused as 401 or 403."""
    context = browser.new_context(viewport={"width": 1440, "height": 900})
    context.add_init_script("localStorage.setItem('horde-lab-tour-done', '1')")
    page = context.new_page()
    page.set_default_timeout(30_000)
    refused: list[str] = []

    def on_response(response: Any) -> None:
        if response.status in (401, 403):
            refused.append(f"{response.status} {response.request.method} {response.url}")

    page.on("response", on_response)
    return page, collect_errors(page, lambda message: "403" not in message.text), refused


def visible_buttons(page: Page) -> list[Any]:
    return [b for b in page.get_by_role("button").all() if b.is_visible()]


def issue_viewer_link(browser: Browser, server: RunningServer) -> str:
    """The teacher's page issues a viewer's token on the Class tab; its invitation link, shown once."""
    page, _, _ = open_link(browser, "about:blank")
    try:
        page.goto(f"{server.url}/?token=s3cret&tab=class")
        expect(page).to_have_url(re.compile(r"\?tab=class$"))  # the token is taken, and gone from the address
        form = page.get_by_role("form", name="Issue a token")
        form.get_by_label("Name").fill("vic")
        form.get_by_label("Role").select_option("viewer")
        form.get_by_role("button", name="Issue a token").click()
        link = page.get_by_label(re.compile("Invitation for vic")).input_value()
        assert re.fullmatch(rf"{re.escape(server.url)}/\?token=hl_[\w-]+", link), link
        expect(page.get_by_role("row", name=re.compile("vic viewer"))).to_be_visible()
        return link
    finally:
        page.context.close()


def sweep(page: Page, tab: str) -> None:
    """On `tab`: no control that changes anything is shown; every other button is pressed, twice."""
    page.get_by_role("tab", name=tab).click()
    page.wait_for_timeout(300)  # the tab's readings arrive
    names = [b.get_attribute("aria-label") or b.inner_text().strip() for b in visible_buttons(page)]
    shown = [name for name in names if CHANGES.match(name)]
    assert shown == [], f"the {tab} tab shows a viewer controls it may not use: {shown}"
    for button in visible_buttons(page):  # the rest change only this page: pressed, twice, none refused
        page.get_by_role("tab", name=tab).click()  # back, if the last one moved the page (Open a run)
        if not button.is_visible() or not button.is_enabled() or button.get_attribute("role") == "tab":
            continue
        for _ in range(2):
            # A located button is the n-th on the page: after a press moved the page (Open switches to the Live
            # tab), the same locator may be another button, so its name is read again before each press.
            with contextlib.suppress(PlaywrightTimeout):
                if NOT_PRESSED.match(button.inner_text(timeout=2_000).strip()):
                    break
                button.click(timeout=2_000)
        if page.evaluate("document.documentElement.classList.contains('present')"):
            page.keyboard.press("Escape")  # a press raced onto Present after all: leave it, the tabs show again


@pytest.mark.timeout(300)
def test_a_viewers_dashboard_shows_no_control_that_would_be_refused(browser: Browser, server: RunningServer) -> None:
    api = server.client
    alice = api.post("/api/tokens", json={"role": "student", "name": "alice"}, headers=TEACHER).json()
    teachers = launch(server, TEACHER, "teachers")
    alices = launch(server, {"Authorization": f"Bearer {alice['token']}"}, "alices")
    link = issue_viewer_link(browser, server)
    page, errors, refused = open_link(browser, link)
    try:
        page.goto(f"{link}&run={alices}")
        page.locator(f'li.run-item.selected[data-run="{alices}"]').wait_for()
        expect(page.get_by_test_id("role")).to_have_text("vic (viewer)")
        expect(page.locator(f'li.run-item[data-run="{teachers}"] [data-testid="run-owner"]')).to_have_text("by teacher")
        for tab in TABS:
            sweep(page, tab)
        page.wait_for_timeout(500)
        assert refused == [], f"a control the viewer was shown was refused: {refused}"
        assert errors == [], errors
        page.context.close()

        # A student's page: the commands of the student's own run, none of the teacher's run.
        invitation = alice["link"].replace("http://testserver", server.url)
        page, errors, refused = open_link(browser, invitation)
        page.goto(f"{invitation}&run={teachers}")
        page.locator(f'li.run-item.selected[data-run="{teachers}"]').wait_for()
        own = page.locator(f'li.run-item[data-run="{alices}"]')
        other = page.locator(f'li.run-item[data-run="{teachers}"]')
        expect(own.get_by_role("button", name="Pause run alices")).to_be_visible()
        expect(other.get_by_role("button", name=re.compile("^(Pause|Start) run"))).to_be_hidden()
        expect(page.get_by_role("button", name="Evaluate steps_to_end")).to_be_hidden()  # the teacher's run
        expect(page.get_by_role("button", name="Launch")).to_be_visible()
        own.get_by_role("button", name="Pause run alices").click()
        expect(own.get_by_role("button", name="Start run alices")).to_be_visible()
        assert api.get(f"/api/runs/{alices}").json()["status"] == "paused"
        assert refused == [], refused
        assert errors == [], errors
    finally:
        page.context.close()
        for run in (teachers, alices):
            api.post(f"/api/runs/{run}/pause", headers=TEACHER)
