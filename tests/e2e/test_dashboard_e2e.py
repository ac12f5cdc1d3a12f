"""The dashboard in a real browser: headless Chromium (Debian's) driven by Playwright, against the real
server (uvicorn in a background thread, a temporary HORDE_DATA) serving the built frontend/dist.

Each test starts from a fresh page and fails on any error in the browser's console. The screenshots
of the main screens land in docs/ (dashboard.png, demon-editor.png, world-editor.png).
"""

from __future__ import annotations

import re
import socket
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import httpx
import pytest
import uvicorn

from horde.server import Settings, create_app
from horde.server.frontend import mount_frontend

CHROMIUM = Path("/usr/bin/chromium")
ROOT = Path(__file__).resolve().parents[2]
DIST = ROOT / "frontend" / "dist"
DOCS = ROOT / "docs"
ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
]
VIEWPORT = {"width": 1280, "height": 800}
TIMEOUT_MS = 15_000
NUMBER = re.compile(r"^-?\d+(\.\d+)?(e[+-]\d+)?$")

pytestmark = [
    pytest.mark.e2e,
    pytest.mark.skipif(not CHROMIUM.exists(), reason="needs Debian's chromium at /usr/bin/chromium"),
    pytest.mark.skipif(not (DIST / "index.html").exists(), reason="frontend/dist is not built: run `make frontend`"),
]

if TYPE_CHECKING:  # Playwright itself is imported in the browser fixture
    from playwright.sync_api import Browser, Page


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


@dataclass
class Server:
    url: str
    client: httpx.Client

    def create_run(self, scenario: str = "experiment1", hz: float = 30.0, episodes: int = 2000) -> str:
        """A running run made through the REST API (the launcher's own test makes one through the page)."""
        response = self.client.post(
            "/api/runs",
            params={"hz": hz, "start": True},
            json={"scenario": scenario, "seed": 7, "protocol": {"episodes": episodes}},
        )
        assert response.status_code == 201, response.text
        return str(response.json()["id"])


@pytest.fixture(scope="module")
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    settings = Settings(data=tmp_path_factory.mktemp("horde-data"), token=None, snapshot_every=3600.0, history=2000)
    app = create_app(settings)
    mount_frontend(app, DIST)
    port = free_port()
    uv = uvicorn.Server(uvicorn.Config(app, host="127.0.0.1", port=port, log_level="warning"))
    thread = threading.Thread(target=uv.run, name="uvicorn-e2e", daemon=True)
    thread.start()
    deadline = time.monotonic() + 20
    while not uv.started:
        assert time.monotonic() < deadline, "the server did not start"
        assert thread.is_alive(), "the server thread died"
        time.sleep(0.02)
    url = f"http://127.0.0.1:{port}"
    with httpx.Client(base_url=url, timeout=30) as client:
        yield Server(url, client)
    uv.should_exit = True
    thread.join(timeout=20)


@pytest.fixture(scope="module")
def browser() -> Iterator[Browser]:
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=str(CHROMIUM), args=ARGS)
        yield browser
        browser.close()


@dataclass
class Console:
    """Errors the page reported: console.error calls, uncaught exceptions, failed loads."""

    errors: list[str] = field(default_factory=list)
    expected: list[re.Pattern[str]] = field(default_factory=list)

    def expect(self, pattern: str) -> None:
        """Allow errors matching `pattern` from now on (the request a test makes fail on purpose)."""
        self.expected.append(re.compile(pattern))

    def unexpected(self) -> list[str]:
        return [e for e in self.errors if not any(p.search(e) for p in self.expected)]


@pytest.fixture
def console() -> Console:
    return Console()


@pytest.fixture
def page(browser: Browser, server: Server, console: Console) -> Iterator[Page]:
    context = browser.new_context(viewport=VIEWPORT)
    page = context.new_page()
    page.set_default_timeout(TIMEOUT_MS)

    def on_console(message: Any) -> None:
        if message.type == "error":
            console.errors.append(f"{message.text} ({message.location.get('url', '')})")

    page.on("console", on_console)
    page.on("pageerror", lambda error: console.errors.append(f"uncaught: {error}"))
    page.goto(server.url)
    page.get_by_role("heading", name="Horde Lab").wait_for()
    yield page
    context.close()
    assert console.unexpected() == [], "errors in the browser console"


def select_run(page: Page, run_id: str) -> None:
    """Click the run's name in the run list (it appears within a second, at the list's next refresh)."""
    page.locator(f'li.run-item[data-run="{run_id}"] button.run-select').click()
    page.locator(f'li.run-item.selected[data-run="{run_id}"]').wait_for()


def cell(page: Page, demon: str, column: int) -> str:
    """The text of a demon table cell; column 1 is the prediction now, 2-4 the evaluation."""
    return page.locator(f'table.demon-table tr[data-demon="{demon}"] td').nth(column - 1).inner_text().strip()


def wait_until(predicate: Any, timeout: float = TIMEOUT_MS / 1000, what: str = "condition") -> None:
    deadline = time.monotonic() + timeout
    while not predicate():
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        time.sleep(0.05)


def field_error(page: Page, label: str) -> str:
    """The error message shown in the field labelled `label`."""
    return page.locator(".field", has=page.get_by_label(label, exact=True)).locator(".field-error").inner_text()


def test_launch_experiment1_and_watch_it_learn(page: Page, server: Server) -> None:
    launcher = page.locator("section.launcher")
    launcher.get_by_label("Scenario").select_option("experiment1")
    launcher.get_by_label("Seed").fill("5")
    launcher.get_by_label("Episodes").fill("500")
    launcher.get_by_label("Steps/s").fill("40")
    launcher.get_by_role("button", name="Launch").click()

    # The new run is selected; its step counter in the top bar moves.
    page.locator("li.run-item.selected").wait_for()
    step = page.get_by_test_id("step")
    first = step.inner_text()
    wait_until(lambda: step.inner_text() != first, what="the step counter to move")
    assert re.fullmatch(r"step [\d,]+", step.inner_text())
    runs = server.client.get("/api/runs").json()
    assert [(r["name"], r["status"]) for r in runs] == [("experiment1", "running")]
    assert page.locator("li.run-item.selected .badge").inner_text() == "running"

    # The prediction of steps_to_end at the agent's state changes as the agent moves and learns.
    page.locator('table.demon-table tr[data-demon="steps_to_end"]').wait_for()
    seen: set[str] = set()

    def prediction_changed() -> bool:
        seen.add(cell(page, "steps_to_end", 1))
        return len(seen - {"–"}) >= 3

    wait_until(prediction_changed, what="the prediction of steps_to_end to change")
    assert all(NUMBER.match(v) for v in seen - {"–"}), seen
    assert cell(page, "steps_to_end", 5) == "30.700"  # the thesis's number beside ours

    # Charts draw once the histories arrive; the viser note stands where the server offers no view.
    page.locator("figure.chart canvas").first.wait_for()
    page.get_by_test_id("viser-note").or_(page.locator("iframe.viser-frame")).first.wait_for()

    # Pause and step from the run list.
    run_id = runs[0]["id"]
    row = page.locator(f'li.run-item[data-run="{run_id}"]')
    row.get_by_role("button", name=re.compile("^Pause run")).click()
    row.locator(".badge", has_text="paused").wait_for()
    before = server.client.get(f"/api/runs/{run_id}").json()["step"]
    row.get_by_role("button", name=re.compile("^Step run")).click()
    wait_until(lambda: server.client.get(f"/api/runs/{run_id}").json()["step"] == before + 1, what="one step")


def test_add_a_demon_to_a_live_run_and_see_a_422_at_its_field(page: Page, server: Server, console: Console) -> None:
    run_id = server.create_run()
    select_run(page, run_id)
    page.get_by_role("tab", name="Demon editor").click()
    form = page.locator("form.demon-form")
    form.get_by_label("Name", exact=True).fill("reach_goal")
    # Will the agent reach the goal, following the base demon? Outcome 1 in the goal, 0 elsewhere.
    form.get_by_label("Target policy").select_option("of")
    form.get_by_label("Follows").select_option("base")
    form.get_by_label("Cumulant", exact=True).select_option("constant")
    form.get_by_label("Cumulant: constant").fill("0")
    form.get_by_label("Outcome", exact=True).select_option("inside")
    form.get_by_label("Outcome: region").select_option("goal")
    form.get_by_label("Continuation", exact=True).select_option("constant")
    form.get_by_label("Continuation: constant").fill("1")

    # A lambda above 1: the server's 422 appears at the lambda field, which takes the focus.
    console.expect(r"status of 422")
    form.get_by_label("λ (lambda)").fill("2")
    form.get_by_role("button", name="Add to run").click()
    message = form.locator(".field", has=page.get_by_label("λ (lambda)")).locator(".field-error")
    message.wait_for()
    assert "less than or equal to 1" in message.inner_text()
    assert form.get_by_label("λ (lambda)").get_attribute("aria-invalid") == "true"
    page.evaluate("window.scrollTo(0, 0)")
    DOCS.mkdir(exist_ok=True)
    page.screenshot(path=str(DOCS / "demon-editor.png"))

    form.get_by_label("λ (lambda)").fill("0.9")
    form.get_by_role("button", name="Add to run").click()
    page.get_by_role("status").filter(has_text="Added demon 'reach_goal'").wait_for()
    assert message.is_hidden()
    demons = server.client.get(f"/api/runs/{run_id}/demons").json()
    added = next(d for d in demons if d["name"] == "reach_goal")
    assert added["spec"]["outcome"] == {"sensor": "in:goal"}
    assert added["spec"]["lambda"] == 0.9

    # The live run goes on with the new demon in the table.
    page.get_by_role("tab", name="Live").click()
    page.locator('table.demon-table tr[data-demon="reach_goal"]').wait_for()
    wait_until(lambda: NUMBER.match(cell(page, "reach_goal", 1)) is not None, what="a prediction of reach_goal")


def test_evaluate_a_demon_and_see_truth_beside_prediction(page: Page, server: Server) -> None:
    run_id = server.create_run(hz=200.0)
    select_run(page, run_id)
    page.get_by_label("Rollouts per evaluation").fill("30")
    page.get_by_role("button", name="Evaluate steps_to_end").click()
    wait_until(lambda: cell(page, "steps_to_end", 3) != "–", timeout=30, what="the Monte-Carlo truth")
    prediction, truth, error = (cell(page, "steps_to_end", c) for c in (2, 3, 4))
    assert NUMBER.match(prediction), prediction
    assert re.fullmatch(r"-?[\d.e+-]+ ± [\d.e+-]+", truth), truth
    assert "%" in error
    assert page.get_by_role("button", name="Evaluate steps_to_end").is_enabled()

    page.get_by_role("button", name="Evaluate base").click()
    wait_until(lambda: cell(page, "base", 3) != "–", timeout=30, what="the Monte-Carlo truth of base")
    page.locator("figure.chart canvas").first.wait_for()
    page.wait_for_timeout(1200)  # one more chart refresh, so that the lines show some history
    page.evaluate("window.scrollTo(0, 0)")
    DOCS.mkdir(exist_ok=True)
    page.screenshot(path=str(DOCS / "dashboard.png"))


def test_world_editor_draws_validates_and_saves(page: Page, server: Server, console: Console) -> None:
    page.get_by_role("tab", name="World editor").click()
    editor = page.locator("form.world-form")
    editor.get_by_label("Start from").select_option("scenario:experiment2-small")
    editor.get_by_role("button", name="Load").click()
    drawing = page.locator("svg.world-svg")
    drawing.locator('[data-region="critical"]').wait_for()
    assert drawing.locator("g.region").count() == 4

    # A new zone is drawn as it is typed.
    editor.get_by_role("button", name="Add region").click()
    region = editor.locator("fieldset.region").last
    region.get_by_label("Name").fill("lake")
    region.get_by_label("Rectangle").fill("200, 0, 300, 100")
    drawing.locator('[data-region="lake"]').wait_for()

    # A negative width: the 422 appears at the width field.
    console.expect(r"status of 422")
    editor.get_by_label("Name", exact=True).first.fill("classroom")
    editor.get_by_label("Width").fill("-5")
    editor.get_by_role("button", name="Save to library").click()
    page.locator(".field", has=page.get_by_label("Width")).locator(".field-error").wait_for()
    assert "greater than 0" in field_error(page, "Width")

    editor.get_by_label("Width").fill("500")
    editor.get_by_role("button", name="Save to library").click()
    page.get_by_role("status").filter(has_text="world 'classroom'").wait_for()
    stored = server.client.get("/api/worlds/classroom").json()["world"]
    assert [r["name"] for r in stored["regions"]][-1] == "lake"
    page.evaluate("window.scrollTo(0, 0)")
    DOCS.mkdir(exist_ok=True)
    page.screenshot(path=str(DOCS / "world-editor.png"))

    # The stored world is offered by the launcher.
    page.locator("section.launcher").get_by_label("World").locator("option", has_text="library: classroom").wait_for(
        state="attached"
    )


def test_the_viser_view_is_embedded_where_the_server_offers_it(page: Page, server: Server) -> None:
    # This server has no GET /api/view yet: the page says so instead of showing a broken frame.
    assert "no GET /api/view" in page.get_by_test_id("viser-note").inner_text()

    # A server that lists the route and answers it: the view appears in a frame (stand-ins via routing).
    view_url = f"{server.url}/viser-stand-in"
    page.route("**/openapi.json", lambda route: route.fulfill(json={"paths": {"/api/view": {}}}))
    page.route("**/api/view", lambda route: route.fulfill(json={"url": view_url}))
    page.route("**/viser-stand-in", lambda route: route.fulfill(content_type="text/html", body="<p>viser here</p>"))
    page.reload()
    frame = page.locator("iframe.viser-frame")
    frame.wait_for()
    assert frame.get_attribute("src") == view_url
    assert page.frame_locator("iframe.viser-frame").get_by_text("viser here").is_visible()
