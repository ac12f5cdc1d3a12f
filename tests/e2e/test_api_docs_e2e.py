"""`/docs` (Swagger UI) and `/redoc` render the API's operations in a browser that may reach nothing
but the server itself: every request to another host is aborted and recorded."""

from __future__ import annotations

from collections.abc import Iterator
from urllib.parse import urlparse

import pytest
from playwright.sync_api import Browser

from horde.server import Settings

from .conftest import IN_BROWSER, RunningServer, browser_page, serve_in_thread

pytestmark = IN_BROWSER

LOOPBACK = {"127.0.0.1", "localhost", "[::1]", "::1"}


@pytest.fixture(scope="module")
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[RunningServer]:
    with serve_in_thread(Settings(data=tmp_path_factory.mktemp("docs-data"), token=None)) as running:
        yield running


@pytest.mark.parametrize(
    ("path", "operation"),
    [
        ("/docs", "#operations-runs-create_run_api_runs_post"),
        ("/redoc", "[id='operation/create_run_api_runs_post'] h2"),
    ],
)
def test_the_api_docs_render_with_the_network_cut_off(
    browser: Browser, server: RunningServer, path: str, operation: str
) -> None:
    from playwright.sync_api import Route

    blocked: list[str] = []

    def only_loopback(route: Route) -> None:
        host = urlparse(route.request.url).hostname or ""
        if route.request.url.startswith(("data:", "blob:")) or host in LOOPBACK:
            route.continue_()
        else:
            blocked.append(route.request.url)
            route.abort()

    # ReDoc's bundle asks for its logo from its vendor's host; the page's Content-Security-Policy refuses it
    # before any request is made (what the policy is for), and the browser logs that refusal as an error.
    def refused_by_policy(text: str) -> bool:
        return "violates the following Content Security Policy directive" in text

    with browser_page(browser, 1280, 900, ignore=refused_by_policy) as (page, errors):
        page.route("**/*", only_loopback)
        page.goto(server.url + path)
        # ReDoc lays out every schema before it shows an operation (the expression types are recursive):
        # 50 s at a load average of 10. The test is about rendering offline, not about its speed.
        page.locator(operation).first.wait_for(state="attached", timeout=150_000)
        summary = page.locator(operation).get_by_text("Create a run").first
        assert summary.is_visible(), f"{path} shows the operation's summary"
    assert blocked == [], f"{path} asked for something beyond the server: {blocked}"
    assert errors == [], f"{path} raised in the browser: {errors}"


def test_the_docs_pages_name_only_local_assets(server: RunningServer) -> None:
    for path in ("/docs", "/redoc"):
        html = server.client.get(path).text
        assert "cdn." not in html and "https://" not in html, f"{path} loads from another host"
    for asset in ("swagger-ui-bundle.js", "swagger-ui.css", "redoc.standalone.js"):
        response = server.client.get(f"/api-docs-assets/{asset}")
        assert response.status_code == 200 and len(response.content) > 100_000, asset
