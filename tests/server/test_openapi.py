"""The OpenAPI schema holds every route of the contract (DESIGN section 8) with its responses."""

from __future__ import annotations

import re

import pytest
from fastapi.testclient import TestClient

CONTRACT = {
    ("get", "/api/health"),
    ("get", "/api/scenarios"),
    ("get", "/api/scenarios/{name}"),
    ("get", "/api/worlds"),
    ("post", "/api/worlds"),
    ("get", "/api/worlds/{name}"),
    ("put", "/api/worlds/{name}"),
    ("delete", "/api/worlds/{name}"),
    ("get", "/api/runs"),
    ("post", "/api/runs"),
    ("get", "/api/runs/{run_id}"),
    ("delete", "/api/runs/{run_id}"),
    ("patch", "/api/runs/{run_id}"),
    ("post", "/api/runs/{run_id}/start"),
    ("post", "/api/runs/{run_id}/pause"),
    ("post", "/api/runs/{run_id}/reset"),
    ("post", "/api/runs/{run_id}/step"),
    ("get", "/api/runs/{run_id}/state"),
    ("get", "/api/runs/{run_id}/demons"),
    ("post", "/api/runs/{run_id}/demons"),
    ("get", "/api/runs/{run_id}/demons/{name}"),
    ("delete", "/api/runs/{run_id}/demons/{name}"),
    ("get", "/api/runs/{run_id}/demons/{name}/values"),
    ("get", "/api/runs/{run_id}/demons/{name}/history"),
    ("post", "/api/runs/{run_id}/evaluate"),
    ("get", "/api/runs/{run_id}/snapshot"),
    ("post", "/api/runs/import"),
}


def test_every_contract_route_is_documented_with_its_responses(client: TestClient) -> None:
    schema = client.get("/openapi.json").json()
    found = {(method, path) for path, item in schema["paths"].items() for method in item}
    assert found >= CONTRACT
    for path, item in schema["paths"].items():
        for method, operation in item.items():
            codes = set(operation["responses"])
            assert any(code.startswith("2") for code in codes), (method, path)
            if "{run_id}" in path or ("{name}" in path and method != "put"):
                assert "404" in codes, (method, path)
            if method in ("post", "put", "patch", "delete"):
                assert "401" in codes, (method, path)
            if "parameters" in operation or "requestBody" in operation:
                assert "422" in codes, (method, path)


@pytest.mark.parametrize("page", ["/docs", "/redoc"])
def test_the_docs_pages_load_only_what_this_server_serves(client: TestClient, page: str) -> None:
    """The pages work with no network (api_docs.py): every script, style and icon they name is served here."""
    html = client.get(page).text
    urls = re.findall(r"""(?:src|href)\s*[=:]\s*['"]([^'"]+)['"]""", html) + re.findall(r"url: *'([^']+)'", html)
    assets = [u for u in urls if u.endswith((".js", ".css", ".png"))]
    assert len(assets) >= 2, f"{page} names no scripts or styles: {urls}"
    for url in [*assets, "/openapi.json"]:
        assert url.startswith("/"), f"{page} loads {url} from another host"
        assert client.get(url).status_code == 200, f"{page} names {url}, which this server does not serve"
