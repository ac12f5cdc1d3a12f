"""The dashboard for a class, in a real browser: readable at 1024, 1440 and 1920 pixels with Large text,
a world drawn by hand and run, no serious accessibility problem on any tab (axe-core), and the help layer
(glossary, tooltips, keyboard shortcuts, the guided tour).

One server with the viser live view serves every test here; screenshots go to test-artifacts/screenshots.
"""

from __future__ import annotations

import contextlib
import math
import time
from collections.abc import Iterator
from typing import TYPE_CHECKING, Any
from urllib.parse import unquote, urlparse

import pytest
from playwright.sync_api import Error as PlaywrightError
from playwright.sync_api import expect

from horde.server import Settings

from .conftest import (
    ON_DASHBOARD,
    PAGE_CATCHES_UP_MS,
    ROOT,
    SHOTS,
    RunningServer,
    collect_errors,
    free_port,
    serve_in_thread,
    viser_view,
)

if TYPE_CHECKING:
    from playwright.sync_api import Browser, BrowserContext, Page, Route

AXE = ROOT / "frontend" / "node_modules" / "axe-core" / "axe.min.js"
SIZES = [(1024, 768), (1440, 900), (1920, 1080)]
WATCH_SECONDS = 30
# The tour and Large text are remembered in the browser; these set them before the page loads.
TOUR_DONE = "localStorage.setItem('horde-lab-tour-done', '1')"
LARGE_TEXT = "localStorage.setItem('horde-lab-large-text', '1')"

pytestmark = ON_DASHBOARD
PAGE_TIMEOUT_MS = 60_000


@pytest.fixture(scope="module")
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[RunningServer]:
    settings = Settings(
        data=tmp_path_factory.mktemp("classroom-data"), token=None, viser_port=free_port(), snapshot_every=3600.0
    )
    with serve_in_thread(settings) as running:
        yield running


# The browser contexts the running test opened: closed after it whatever its outcome, so that a failed test
# leaves no page drawing the live view (software WebGL) to slow the next tests' pages down.
OPENED: list[BrowserContext] = []


@pytest.fixture(autouse=True)
def nothing_left_running(server: RunningServer) -> Iterator[None]:
    """After each test: its pages closed and every run it left running paused (runs are launched at 30 steps
    a second and share the module's server)."""
    yield
    while OPENED:
        with contextlib.suppress(PlaywrightError):
            OPENED.pop().close()
    for run in server.client.get("/api/runs").json():
        if run["status"] == "running":
            server.client.post(f"/api/runs/{run['id']}/pause")


def new_page(browser: Browser, width: int, height: int, *scripts: str) -> tuple[Page, list[str]]:
    """A page whose dashboard errors are collected (the embedded viser client's own are its business: it
    logs stale updates to charts it has just replaced when the run shown changes)."""
    context = browser.new_context(viewport={"width": width, "height": height})
    OPENED.append(context)
    for script in scripts:
        context.add_init_script(script)
    page = context.new_page()
    # A wide page shows the live view at once: its software WebGL then holds the page's frames (and so
    # Playwright's "stable" check) up for tens of seconds on a loaded two-core machine.
    page.set_default_timeout(PAGE_TIMEOUT_MS)

    def from_the_dashboard(message: Any) -> bool:
        host = urlparse(page.main_frame.url).netloc
        return not host or host in message.location.get("url", "")

    return page, collect_errors(page, from_the_dashboard)


def launch(server: RunningServer, **template: Any) -> str:
    body = {"scenario": "classroom-offpolicy", "seed": 3, **template}
    response = server.client.post("/api/runs", params={"hz": 30, "start": True}, json=body)
    assert response.status_code == 201, response.text
    return str(response.json()["id"])


def select(page: Page, server: RunningServer, run_id: str) -> None:
    page.goto(server.url)
    page.locator(f'li.run-item[data-run="{run_id}"] button.run-select').click()
    page.locator(f'li.run-item.selected[data-run="{run_id}"]').wait_for()


def without_the_view(page: Page, server: RunningServer) -> None:
    """The live view's frame as a stand-in page: a test about the dashboard's own panels need not wait for
    the viser client, whose software WebGL holds a busy machine's page up for tens of seconds."""
    view_url = server.client.get("/api/view").json()["url"].rstrip("/")
    page.route(f"{view_url}/**", lambda route: route.fulfill(content_type="text/html", body="<p>viser</p>"))
    page.route(view_url, lambda route: route.fulfill(content_type="text/html", body="<p>viser</p>"))


AGENT_NODE = """() => !!window.__viserMutable?.nodeRefFromName?.["/agent"]"""
# Widths that must not grow: the page's, and the widest chart's.
WIDTHS = """() => ({
    page: document.documentElement.scrollWidth,
    charts: Math.max(0, ...[...document.querySelectorAll('.chart canvas')].map(c => c.getBoundingClientRect().width)),
    count: document.querySelectorAll('.chart canvas').length,
})"""

# What lies on top at points spread over the live view's frame: the frame itself, or what covers it.
COVERING = """() => {
    const frame = document.querySelector('iframe.viser-frame');
    frame.scrollIntoView({block: 'center'});
    const box = frame.getBoundingClientRect();
    const hits = [];
    for (const fx of [0.1, 0.5, 0.9]) for (const fy of [0.1, 0.5, 0.9]) {
        const x = box.left + fx * box.width, y = box.top + fy * box.height;
        if (y < 0 || y > innerHeight) continue;
        const top = document.elementFromPoint(x, y);
        if (top !== frame) hits.push(`${top?.tagName}.${top?.className} at ${fx},${fy}`);
    }
    return hits;
}"""


def picture_and_close(page: Page, errors: list[str], name: str) -> None:
    """The whole page from its top into SHOTS as `name`, no console errors, then the page's context closed."""
    page.evaluate("window.scrollTo(0, 0)")
    SHOTS.mkdir(parents=True, exist_ok=True)
    page.screenshot(path=str(SHOTS / name), full_page=True)
    assert errors == [], f"{name}: errors in the browser console"
    page.context.close()


def classroom_mode(page: Page, server: RunningServer, run_id: str) -> None:
    """`run_id` selected and Classroom mode on, its charts (one per demon, six or more) drawn."""
    select(page, server, run_id)
    page.get_by_role("button", name="Classroom mode").click()
    page.wait_for_function("() => document.querySelectorAll('.chart canvas').length >= 6")


def test_three_screens_at_once_with_large_text_grow_nothing_sideways(browser: Browser, server: RunningServer) -> None:
    """A running run watched in Classroom mode on three screens at once: neither the page nor a chart grows as
    the readings come in. (The live view's frame is a stand-in here: three software-WebGL views at once would
    leave each page a frame or two a second; the next test looks at the real view, one screen at a time.)"""
    run_id = launch(server, name="sizes")
    pages = []
    for width, height in SIZES:
        page, errors = new_page(browser, width, height, TOUR_DONE, LARGE_TEXT)
        without_the_view(page, server)
        classroom_mode(page, server, run_id)
        assert page.evaluate("document.documentElement.classList.contains('large')")
        pages.append((width, page, errors))
    first = {width: page.evaluate(WIDTHS) for width, page, _ in pages}
    began = time.monotonic()
    while time.monotonic() - began < WATCH_SECONDS:
        time.sleep(5)
        for width, page, _ in pages:
            now = page.evaluate(WIDTHS)
            assert now["page"] <= width, f"{width} px: the page grew sideways to {now['page']} px"
            assert now["charts"] <= first[width]["charts"] + 1, f"{width} px: a chart grew: {first[width]} -> {now}"
    assert {width: errors for width, _, errors in pages} == {width: [] for width, _ in SIZES}


@pytest.mark.parametrize(("width", "height"), SIZES, ids=[f"{w}x{h}" for w, h in SIZES])
def test_at_each_size_with_large_text_nothing_covers_the_live_view(
    browser: Browser, server: RunningServer, width: int, height: int
) -> None:
    """Classroom mode with Large text: no part of the dashboard lies over the live view's world, which is
    drawn with its panel folded away; at 1440 px the truths are evaluated for the picture."""
    run_id = launch(server, name=f"size-{width}")
    page, errors = new_page(browser, width, height, TOUR_DONE, LARGE_TEXT)
    classroom_mode(page, server, run_id)
    assert page.evaluate(COVERING) == [], f"{width} px: something covers the live view's world"
    frame = viser_view(page, server.client.get("/api/view").json()["url"])
    frame.wait_for_function(AGENT_NODE, timeout=30_000)
    # Inside the frame: wide enough for the viser client's desktop layout (its phone layout lays the panel
    # over the world), and its panel minimized to a bar.
    assert frame.evaluate("innerWidth") > 576, f"{width} px: the embedded view gets its phone layout"
    assert frame.get_by_role("button", name="Expand panel").count() == 1, f"{width} px: the view's panel is open"
    # The "software WebGL" notice of a GPU-less browser, closed for the picture where it lets itself be.
    for close in page.frame_locator("iframe.viser-frame").locator(".mantine-Notification-root button").all():
        with contextlib.suppress(PlaywrightError):
            close.click(timeout=2000)
    if width == 1440:
        page.get_by_role("button", name="Evaluate all").click()
        page.locator(".chart figcaption", has_text="from the start at step").nth(5).wait_for(timeout=60_000)
    picture_and_close(page, errors, f"classroom-{width}.png")


# Every chart's tick labels as drawn (plots.ts puts them on the plot as data-x-ticks / data-y-ticks), measured
# in the axes' font: x labels closer than their half-widths (plus a gap), y labels repeated, the labels
# themselves, y labels wider than the room left of the plot, and demon names broken inside a piece (a piece
# between two <wbr> laid over two lines).
AXES = """() => {
    const ctx = document.createElement('canvas').getContext('2d');
    const rem = parseFloat(getComputedStyle(document.documentElement).fontSize);
    ctx.font = `${Math.round(0.8 * rem)}px system-ui`;
    const crowded = [], repeated = [], labels = [], broken = [], cut = [];
    for (const plot of document.querySelectorAll('.chart .uplot')) {
        const xs = JSON.parse(plot.dataset.xTicks || '[]').filter(([label]) => label).sort((a, b) => a[1] - b[1]);
        labels.push(...xs.map(([label]) => label));
        xs.slice(1).forEach(([label, at], i) => {
            const [before, was] = xs[i];
            const room = (ctx.measureText(before).width + ctx.measureText(label).width) / 2 + 4;
            if (at - was < room) crowded.push(`${before}|${label}`);
        });
        const ys = JSON.parse(plot.dataset.yTicks || '[]').map(([label]) => label).filter(Boolean);
        if (new Set(ys).size < ys.length) repeated.push(ys.join(','));
        // The y labels end left of the plotting area, less uPlot's ticks (10 px) and gap (5 px): they must
        // fit between the chart's edge and there.
        const room = plot.querySelector('.u-over').offsetLeft - 15;
        for (const label of ys) if (ctx.measureText(label).width + 4 > room) cut.push(label);
    }
    for (const piece of document.querySelectorAll('.chart-name, .demon-table .demon-name')) {
        for (const node of piece.childNodes) {
            if (node.nodeType !== Node.TEXT_NODE || !node.textContent.trim()) continue;
            const range = document.createRange();
            range.selectNodeContents(node);
            const lines = new Set([...range.getClientRects()].map(r => Math.round(r.top)));
            if (lines.size > 1) broken.push(node.textContent);
        }
    }
    return {crowded, repeated, labels, broken, cut};
}"""


# Six charts or more whose x axis is labelled in thousands (k) or millions (M).
COMPACT_CHARTS = (
    "() => [...document.querySelectorAll('.chart .uplot')].filter(p => /\\d[kM]/.test(p.dataset.xTicks)).length >= 6"
)


def long_history(route: Route) -> None:
    """A demon's history as a long run has it: 1.25 million steps; predictions of a few ten-thousandths for
    the goal demons (whose y ticks then need four decimals), of a few steps for the others."""
    demon = unquote(route.request.url.split("/demons/")[1].split("/")[0])
    rows = 500
    size = 0.0006 if demon.startswith("goal") else 4.0
    steps = [round(i * 1_250_000 / (rows - 1)) for i in range(rows)]
    prediction = [size * (0.5 + 0.5 * math.sin(i / 25)) for i in range(rows)]
    zeros = [0.0] * rows
    route.fulfill(
        json={
            "demon": demon,
            "capacity": rows,
            "every": 1,
            "step": steps,
            "prediction": prediction,
            "rupee": zeros,
            "ude": zeros,
            "delta": zeros,
            "cumulant": zeros,
        }
    )


@pytest.mark.timeout(120)
def test_chart_axes_stay_readable_at_1024_and_with_large_text_at_1920(browser: Browser, server: RunningServer) -> None:
    """A million steps and tiny predictions (the histories of a long run, stubbed) on the small multiples of
    a classroom run: compact x labels that do not run together, y labels that do not repeat, demon names
    broken only between words."""
    run_id = launch(server, name="axes")
    for width, height, scripts in ((1024, 768, [TOUR_DONE]), (1920, 1080, [TOUR_DONE, LARGE_TEXT])):
        page, errors = new_page(browser, width, height, *scripts)
        page.route("**/demons/*/history", long_history)
        without_the_view(page, server)
        select(page, server, run_id)
        page.get_by_role("button", name="Classroom mode").click()
        page.wait_for_function(COMPACT_CHARTS)
        found = page.evaluate(AXES)
        assert found["crowded"] == [], f"{width} px: x labels run together: {found['crowded']}"
        assert found["repeated"] == [], f"{width} px: y labels repeat: {found['repeated']}"
        assert found["cut"] == [], f"{width} px: y labels cut off at the left: {found['cut']}"
        assert found["broken"] == [], f"{width} px: names broken inside a word: {found['broken']}"
        assert "1M" in found["labels"] and not any("," in label for label in found["labels"]), found["labels"]
        picture_and_close(page, errors, f"axes-{width}.png")
    server.client.post(f"/api/runs/{run_id}/pause")


def drag(page: Page, world: dict[str, float], start: tuple[float, float], end: tuple[float, float]) -> None:
    """Drag on the world drawing from one world point to another (world units, y up)."""
    svg = page.locator("svg.world-svg")
    box = svg.bounding_box()
    assert box is not None
    # The drawing keeps the world's aspect and a margin of 1/20 of its smaller side all round.
    margin = min(world["width"], world["height"]) / 20
    span_x, span_y = world["width"] + 2 * margin, world["height"] + 2 * margin
    scale = min(box["width"] / span_x, box["height"] / span_y)
    left = box["x"] + (box["width"] - scale * span_x) / 2
    top = box["y"] + (box["height"] - scale * span_y) / 2

    def at(x: float, y: float) -> tuple[float, float]:
        return left + scale * (x + margin), top + scale * (world["height"] - y + margin)

    page.mouse.move(*at(*start))
    page.mouse.down()
    for k in range(1, 6):
        f = k / 5
        page.mouse.move(*at(start[0] + f * (end[0] - start[0]), start[1] + f * (end[1] - start[1])))
    page.mouse.up()


def test_draw_a_world_by_dragging_save_it_run_it_and_see_its_value_map(browser: Browser, server: RunningServer) -> None:
    """Why 70 lines: one user's path (draw the regions, name them, save, launch a run on the drawn world, see
    its value map), each step on the page the previous one left."""
    page, errors = new_page(browser, 1440, 1000, TOUR_DONE)
    page.goto(server.url)
    page.get_by_role("tab", name="World editor").click()
    editor = page.locator("form.world-form")
    editor.get_by_role("group", name="World").get_by_label("Name").fill("drawn")
    world = {"width": 500.0, "height": 500.0}
    regions = editor.locator("fieldset.region")
    assert regions.count() == 1  # the new world's goal

    # A wall by dragging: snapped to the grid of 100.
    page.get_by_label("Draw new regions as").select_option("obstacle")
    drag(page, world, (110, 190), (190, 290))
    assert regions.count() == 2
    wall = regions.nth(1)
    assert wall.get_by_label("Name").input_value() == "obstacle1"
    assert wall.get_by_label("Rectangle").input_value() == "100, 200, 200, 300"
    # Moved one step right, then resized from its top-right corner, then the resize taken back.
    drag(page, world, (150, 250), (250, 250))
    assert wall.get_by_label("Rectangle").input_value() == "200, 200, 300, 300"
    drag(page, world, (300, 300), (400, 400))
    assert wall.get_by_label("Rectangle").input_value() == "200, 200, 400, 400"
    page.get_by_role("button", name="Undo").click()
    assert regions.nth(1).get_by_label("Rectangle").input_value() == "200, 200, 300, 300"

    # A second terminal, renamed pit with reward -1 in the form: the drawing follows the form too.
    page.get_by_label("Draw new regions as").select_option("terminal")
    drag(page, world, (410, 110), (490, 190))
    pit = regions.nth(2)
    assert pit.get_by_label("Rectangle").input_value() == "400, 100, 500, 200"
    pit.get_by_label("Name").fill("pit")
    pit.get_by_label("Reward").fill("-1")
    page.locator('svg.world-svg g[data-region="pit"]').wait_for()
    # A click sets the start on the nearest lattice point.
    drag(page, world, (95, 105), (95, 105))
    assert editor.get_by_label("Start", exact=True).input_value() == "100, 100"
    SHOTS.mkdir(parents=True, exist_ok=True)
    page.screenshot(path=str(SHOTS / "world-drawn.png"), full_page=True)
    editor.get_by_role("button", name="Save to library").click()
    page.get_by_role("status").filter(has_text="world 'drawn'").wait_for()
    saved = server.client.get("/api/worlds/drawn").json()["world"]
    assert saved["start"] == [100, 100]
    assert [(r["name"], r["kind"], r["rect"]) for r in saved["regions"]] == [
        ("goal", "terminal", [400, 400, 500, 500]),
        ("obstacle1", "obstacle", [200, 200, 300, 300]),
        ("pit", "terminal", [400, 100, 500, 200]),
    ]

    # Experiment 1's demons on the drawn world, launched from the page; the live view shows a value map.
    launcher = page.locator("section.launcher")
    launcher.get_by_label("Scenario").select_option("experiment1")
    launcher.get_by_label("World").select_option("drawn")
    launcher.get_by_label("Name", exact=True).fill("on-drawn")
    launcher.get_by_label("Steps/s").fill("50")
    launcher.get_by_role("button", name="Launch").click()
    page.locator("li.run-item.selected", has_text="on-drawn").wait_for()
    view_url = server.client.get("/api/view").json()["url"]
    frame = viser_view(page, view_url)
    frame.wait_for_function(
        """() => Object.keys(window.__viserMutable?.nodeRefFromName ?? {}).some(n => n.startsWith("/value_map/"))""",
        timeout=30_000,
    )
    run = next(r for r in server.client.get("/api/runs").json() if r["name"] == "on-drawn")
    assert server.client.get(f"/api/runs/{run['id']}").json()["spec"]["world"]["start"] == [100, 100]
    server.client.post(f"/api/runs/{run['id']}/pause")

    # Or straight from the editor: an empty run on the drawn world, selected and running on the Live tab.
    page.get_by_role("tab", name="World editor").click()
    editor.get_by_role("button", name="Launch on this world").click()
    page.locator("li.run-item.selected", has_text="empty-on-drawn").wait_for()
    expect(page.get_by_role("tab", name="Live")).to_have_attribute("aria-selected", "true")
    empty = next(r for r in server.client.get("/api/runs").json() if r["name"] == "empty-on-drawn")
    assert empty["demons"] == [] and empty["status"] == "running", empty
    assert server.client.get(f"/api/runs/{empty['id']}").json()["spec"]["world"]["regions"] == saved["regions"]
    server.client.post(f"/api/runs/{empty['id']}/pause")
    assert errors == []
    page.context.close()


def axe_violations(page: Page) -> list[str]:
    """axe-core's serious and critical violations on the page as it stands (the viser frame aside)."""
    if not page.evaluate("!!window.axe"):
        page.add_script_tag(path=str(AXE))
    found = page.evaluate(
        """async () => {
            const result = await axe.run(document, {iframes: false, resultTypes: ["violations"]});
            return result.violations
                .filter(v => v.impact === "serious" || v.impact === "critical")
                .map(v => `${v.impact} ${v.id}: ${v.nodes.slice(0, 3).map(n => n.target.join(" ")).join(" | ")}`);
        }"""
    )
    return list(found)


def test_no_serious_accessibility_violation_on_any_tab(browser: Browser, server: RunningServer) -> None:
    run_id = launch(server, name="axe")
    page, errors = new_page(browser, 1440, 900, TOUR_DONE)
    without_the_view(page, server)  # axe leaves the frame aside
    select(page, server, run_id)
    page.locator(".chart canvas").first.wait_for()
    found: dict[str, list[str]] = {}
    for tab in ("Live", "Protocol", "World editor", "Demon editor"):
        page.get_by_role("tab", name=tab).click()
        found[tab] = axe_violations(page)
    page.get_by_role("button", name="Help (?)").click()
    found["Help"] = axe_violations(page)
    assert found == {tab: [] for tab in found}
    server.client.post(f"/api/runs/{run_id}/pause")
    assert errors == []
    page.context.close()


# The tour's dialog and the part it points at: whether the dialog lies over the part's upper half (where the
# live view draws the value map's legend) and whether the part shows anything.
TOUR_PLACE = """() => {
    const dialog = document.querySelector('.tour').getBoundingClientRect();
    const target = document.querySelector('.tour-target');
    const box = target.getBoundingClientRect();
    const upper = {top: box.top, bottom: box.top + box.height / 2, left: box.left, right: box.right};
    const covers = dialog.left < upper.right && dialog.right > upper.left
        && dialog.top < upper.bottom && dialog.bottom > upper.top;
    const empty = !target.querySelector('iframe, .chart, tr[data-demon], li.run-item');
    const edges = b => [b.left, b.top, b.right, b.bottom].map(Math.round);
    return {covers, empty, dialog: edges(dialog), part: edges(box), window: [innerWidth, innerHeight]};
}"""
NEXT_FRAME = "() => new Promise(resolve => requestAnimationFrame(() => requestAnimationFrame(resolve)))"


def test_the_tour_waits_for_a_run_comes_once_and_covers_nothing(browser: Browser, server: RunningServer) -> None:
    run_id = launch(server)  # named after the classroom scenario: the tour is for it
    page, errors = new_page(browser, 1440, 900)
    without_the_view(page, server)
    page.goto(server.url)
    page.locator(f'li.run-item[data-run="{run_id}"]').wait_for()
    # Classroom mode with no run selected: nothing to show yet, so no tour.
    page.get_by_role("button", name="Classroom mode").click()
    page.evaluate(NEXT_FRAME)
    assert page.locator(".tour").is_hidden(), "the tour waits for a run"
    page.locator(f'li.run-item[data-run="{run_id}"] button.run-select').click()

    # A classroom run offers the tour the first time, and only then: a reload without closing it
    # does not bring it back.
    page.get_by_role("dialog", name="The world").wait_for()
    page.reload()
    select(page, server, run_id)
    page.locator("table.demon-table tr[data-demon]").first.wait_for()
    page.evaluate(NEXT_FRAME)
    assert page.locator(".tour").is_hidden(), "the tour, once offered, does not come back"

    # Taken on demand: four stops, each at a part with something in it, the dialog never over its top.
    page.locator(".chart").first.wait_for()
    page.get_by_role("button", name="Take the tour").click()
    SHOTS.mkdir(parents=True, exist_ok=True)
    titles = []
    for _ in range(4):
        dialog = page.locator(".tour")
        titles.append(dialog.locator("h2").inner_text())
        assert page.locator(".tour-target").count() == 1
        place = page.evaluate(TOUR_PLACE)
        page.screenshot(path=str(SHOTS / f"tour-{len(titles)}.png"))
        assert (place["covers"], place["empty"]) == (False, False), f"{titles[-1]}: {place}"
        if titles[-1] == "One chart per demon":
            assert "ring" in dialog.inner_text(), "the tour says what the charts draw"
        dialog.get_by_role("button", name="Next").or_(dialog.get_by_role("button", name="Done")).click()
    assert titles == ["The world", "One chart per demon", "The demons", "Speed and control"]
    assert page.locator(".tour").is_hidden()
    server.client.post(f"/api/runs/{run_id}/pause")
    assert errors == []
    page.context.close()


def test_help_tooltips_and_shortcuts(browser: Browser, server: RunningServer) -> None:
    run_id = launch(server)
    page, errors = new_page(browser, 1440, 900, TOUR_DONE)
    without_the_view(page, server)
    select(page, server, run_id)

    # Every column head of the demon table explains its word.
    heads = page.locator("table.demon-table thead th[title]")
    titles = heads.evaluate_all("hs => hs.map(h => h.title)")
    assert any(t.startswith("RUPEE: Root of the Unbiased Projected Error Estimate") for t in titles)
    assert any(t.startswith("UDE: ") for t in titles)

    # ? opens the help with the glossary; Escape closes it.
    page.keyboard.press("?")  # the focus is on the run's button: keys other than Space and Enter still work
    help_dialog = page.get_by_role("dialog", name="Help: words and keys")
    help_dialog.wait_for()
    words = ("Cumulant", "Continuation (γ)", "Importance ratio (ρ)", "RUPEE", "UDE", "GVF (general value function)")
    for word in words:
        assert help_dialog.locator("dt", has_text=word).count() == 1, word
    page.keyboard.press("Escape")
    help_dialog.wait_for(state="hidden")

    # Space pauses the selected run, s steps it, Space starts it again.
    page.evaluate("document.activeElement.blur()")
    page.keyboard.press(" ")
    page.locator(f'li.run-item[data-run="{run_id}"] .badge', has_text="paused").wait_for()
    before = server.client.get(f"/api/runs/{run_id}").json()["step"]
    counters = page.locator(f'li.run-item[data-run="{run_id}"]').get_by_test_id("run-counters")
    expect(counters, "the paused run's card caught up").to_contain_text(f"step {before:,} ·")
    page.keyboard.press("s")
    expect(counters, "s steps the selected run").not_to_contain_text(f"step {before:,} ·", timeout=PAGE_CATCHES_UP_MS)
    assert server.client.get(f"/api/runs/{run_id}").json()["step"] > before
    page.keyboard.press(" ")
    page.locator(f'li.run-item[data-run="{run_id}"] .badge', has_text="running").wait_for()
    server.client.post(f"/api/runs/{run_id}/pause")
    assert errors == []
    page.context.close()


def test_a_horde_of_800_demons_keeps_the_table_small_searchable_and_summarised(
    browser: Browser, server: RunningServer
) -> None:
    count = 800
    demons = [
        {"name": f"d{i:03d}", "policy": "uniform", "cumulant": 1, "learner": "td", "discount": 0.9}
        for i in range(count)
    ]
    body = {"scenario": "experiment1", "seed": 1, "name": "horde", "behaviour": "uniform", "demons": demons}
    response = server.client.post("/api/runs", params={"hz": 20, "start": True}, json=body)
    assert response.status_code == 201, response.text
    run_id = response.json()["id"]
    page, errors = new_page(browser, 1440, 900, TOUR_DONE)
    without_the_view(page, server)
    select(page, server, run_id)
    summary = page.get_by_test_id("demon-summary")
    summary.filter(has_text=f"{count} demons · {count} learning · 0 diverged").wait_for()
    rows = page.locator("table.demon-table tbody tr[data-demon]")
    assert 0 < rows.count() < 60, "only the rows in sight (and a few more) exist"
    # Scrolled to the end, the last demons are there (and the first are gone).
    page.locator(".table-scroll.virtual").evaluate("box => box.scrollTo(0, box.scrollHeight)")
    page.locator('table.demon-table tr[data-demon="d799"]').wait_for()
    assert page.locator('table.demon-table tr[data-demon="d000"]').count() == 0
    # The search finds one demon among 800.
    page.get_by_label("Find demons").fill("d417")
    page.locator('table.demon-table tr[data-demon="d417"]').wait_for()
    assert rows.count() == 1
    # The overview shows every prediction; the charts only the chosen ones (12 by default).
    assert page.locator("section.overview canvas").is_visible()
    assert page.locator(".chart").count() == 12
    server.client.post(f"/api/runs/{run_id}/pause")
    assert errors == []
    page.context.close()
