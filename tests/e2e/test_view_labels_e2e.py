"""Large text in the live view, in a real browser at 1024 x 768 and at 1920 x 1080 (issue 28, item 5).

The dashboard's Large text reaches its embedded view: the view's labels are drawn 1.5 times larger and its panel
(once opened) in a root font 1.5 times the browser's, and the predictions' label, under the world, covers no
region's name. Labels are drawn on the GPU (no DOM to measure), so each label is found by what it paints: the
view's frame is captured as the labels are hidden one group after another (their handles in this page's own
scene, on the server), and the pixels that change at each are that group's box. Its height, per line, is the
label's size on screen.

The figures (pixels per line of the predictions' label and of a region's name, normal and large; measured: 12
and 16 px normal, 18 (17 at 1920 x 1080) and 24 px large; the panel's root font 24 px) are written to
test-artifacts/view-labels.json and the pictures to test-artifacts/screenshots/view-labels-*.png.
"""

from __future__ import annotations

import io
import itertools
import json
import time
from collections.abc import Iterator
from typing import TYPE_CHECKING, Any

import numpy as np
import pytest
from PIL import Image

from horde.server import Settings

from .conftest import ON_DASHBOARD, ROOT, SHOTS, RunningServer, free_port, page_viewer, serve_in_thread, viser_view

if TYPE_CHECKING:
    from playwright.sync_api import Browser, Page

    from horde.view.viewer import Viewer

pytestmark = ON_DASHBOARD

SIZES = [(1024, 768), (1920, 1080)]
REGIONS = ("goal", "pit", "wall")  # experiment1's regions: goal and pit at the world's right edge, wall inside
LINES = 1  # the predictions' label: "at the agent:" and the two demons, on one line
TOUR_DONE = "localStorage.setItem('horde-lab-tour-done', '1')"
FIGURES = ROOT / "test-artifacts" / "view-labels.json"


@pytest.fixture(scope="module")
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[RunningServer]:
    data = tmp_path_factory.mktemp("labels")
    with serve_in_thread(Settings(data=data, token=None, viser_port=free_port(), snapshot_every=3600.0)) as running:
        yield running


def capture(page: Page) -> np.ndarray:
    """[H, W, 3] the view's frame as the page shows it."""
    png = page.locator("iframe.viser-frame").screenshot(animations="disabled")
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(np.int16)


Box = tuple[int, int, int, int]  # (x0, y0, x1, y1) on the view's frame


def painted_boxes(page: Page, groups: list[list[Any]], timeout: float = 30.0) -> list[Box]:
    """The box of the pixels each group of handles paints: the groups hidden one after another (each box where the
    frame changed as its group was hidden), then all shown again; a pixel counts only where the frame shown again
    equals the first (so that a change elsewhere meanwhile, say a notice fading, does not count). Tried again, a
    few times, when something else changed in the same moment."""
    boxes: list[Box] = []
    for _ in range(4):
        frames = [capture(page)]
        for group in groups:
            for handle in group:
                handle.visible = False
            frames.append(wait_for_change(page, frames[-1], timeout))
        for group in groups:
            for handle in group:
                handle.visible = True
        back = np.abs(frames[0] - wait_for_change(page, frames[-1], timeout)).max(axis=2) <= 40  # [H, W]
        boxes = []
        for shown, hidden in itertools.pairwise(frames):
            ys, xs = np.nonzero((np.abs(shown - hidden).max(axis=2) > 40) & back)
            if xs.size == 0:
                break
            box = int(xs.min()), int(ys.min()), int(xs.max()) + 1, int(ys.max()) + 1
            if (box[2] - box[0]) * (box[3] - box[1]) >= 0.1 * back.size:  # a redrawn view, not a label
                break
            boxes.append(box)
        if len(boxes) == len(groups):
            return boxes
    raise AssertionError(f"the labels' pixels could not be told from other changes: boxes found {boxes}")


def wait_for_change(page: Page, frame: np.ndarray, timeout: float) -> np.ndarray:
    """The next capture that differs from `frame` in more than a few pixels (then one more frame, drawn whole)."""
    deadline = time.monotonic() + timeout
    while True:
        now = capture(page)
        if (np.abs(now - frame).max(axis=2) > 40).sum() > 20:
            time.sleep(0.5)  # the software renderer may draw a frame in parts
            return capture(page)
        assert time.monotonic() < deadline, "showing or hiding a label changed nothing on the screen"
        time.sleep(0.2)


def quiet(page: Page) -> None:
    """Close viser's notices (software WebGL) over the view, so that only the labels change on the screen."""
    frame = page.frame_locator("iframe.viser-frame")
    closers = frame.locator(".mantine-Notification-closeButton")
    for k in range(closers.count()):
        closers.nth(k).click()
    time.sleep(1.0)


def overlap(a: Box, b: Box) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def this_pages_viewer(server: RunningServer, page: Page, large: bool) -> Viewer:
    """The page's own view on the server, once it has drawn the predictions at the size asked for."""
    view = server.app.state.live_view
    key = page_viewer(page)
    deadline = time.monotonic() + 60
    while True:
        viewers = view.viewers(key)
        if viewers and viewers[0].applier.label_scale == (1.5 if large else 1.0):
            drawn = viewers[0].applier.drawn
            if "/predictions" in drawn and all(f"/region_labels/{r}" in drawn for r in REGIONS):
                return viewers[0]
        assert time.monotonic() < deadline, "the page's view did not draw its labels"
        time.sleep(0.2)


def measure(server: RunningServer, page: Page, large: bool) -> dict[str, Any]:
    viewer = this_pages_viewer(server, page, large)
    quiet(page)
    time.sleep(2.0)  # the browser draws what the view sent
    drawn = viewer.applier.drawn
    others = [drawn[f"/region_labels/{name}"][1] for name in REGIONS if name != "wall"]
    predictions, some, wall = painted_boxes(
        page, [[drawn["/predictions"][1]], others, [drawn["/region_labels/wall"][1]]]
    )
    names = min(some[0], wall[0]), min(some[1], wall[1]), max(some[2], wall[2]), max(some[3], wall[3])  # all three
    assert not overlap(names, predictions), f"the predictions' label {predictions} covers region names in {names}"
    return {
        "predictions_box": predictions,
        "predictions_px_per_line": (predictions[3] - predictions[1]) / LINES,
        "region_names_box": names,
        "region_name_px": wall[3] - wall[1],
    }


@pytest.mark.timeout(420)
def test_large_text_scales_the_views_labels_and_panel_and_the_predictions_cover_no_region_name(
    browser: Browser, server: RunningServer
) -> None:
    api = server.client
    run = api.post("/api/runs", json={"scenario": "experiment1", "seed": 3, "protocol": {"episodes": 0}}).json()["id"]
    assert api.post(f"/api/runs/{run}/step", json={"steps": 250}).status_code == 200  # paused: a still frame
    figures: dict[str, Any] = {}
    SHOTS.mkdir(parents=True, exist_ok=True)
    for width, height in SIZES:
        context = browser.new_context(viewport={"width": width, "height": height})
        context.add_init_script(TOUR_DONE)
        page = context.new_page()
        page.set_default_timeout(60_000)  # software WebGL on a loaded machine
        try:
            page.goto(f"{server.url}/?run={run}&tab=live")
            page.locator("iframe.viser-frame").wait_for()
            frame = viser_view(page, api.get("/api/view").json()["url"])
            frame.wait_for_function("() => !!window.__viserMutable?.nodeRefFromName?.['/agent']")
            normal = measure(server, page, large=False)
            page.locator("iframe.viser-frame").screenshot(path=str(SHOTS / f"view-labels-{width}.png"))
            page.get_by_role("button", name="Large text").click()
            frame = viser_view(page, api.get("/api/view").json()["url"])  # the page's layout moved: in sight again
            large = measure(server, page, large=True)
            page.locator("iframe.viser-frame").screenshot(path=str(SHOTS / f"view-labels-{width}-large.png"))
            ratio = large["predictions_px_per_line"] / normal["predictions_px_per_line"]
            assert 1.3 < ratio < 1.7, f"labels {ratio:.2f} times larger with Large text at {width} x {height}"
            region_ratio = large["region_name_px"] / normal["region_name_px"]
            assert 1.3 < region_ratio < 1.7, f"region names {region_ratio:.2f} times larger"
            # The panel, once opened, is drawn in a root font 1.5 times the browser's (it is minimized at first).
            frame.get_by_role("button", name="Expand panel").click()
            frame.get_by_role("button", name="Tilt to 3-D").wait_for()
            panel_px = float(frame.evaluate("parseFloat(getComputedStyle(document.documentElement).fontSize)"))
            assert panel_px == pytest.approx(24.0), "the panel's root font with Large text"
            page.locator("iframe.viser-frame").screenshot(path=str(SHOTS / f"view-labels-{width}-large-panel.png"))
            figures[f"{width}x{height}"] = {"normal": normal, "large": large, "panel_root_px_large": panel_px}
        finally:
            context.close()
    FIGURES.parent.mkdir(parents=True, exist_ok=True)
    FIGURES.write_text(json.dumps(figures, indent=2))
