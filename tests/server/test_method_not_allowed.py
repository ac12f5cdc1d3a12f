"""A 405 says what the path allows (issue 24, item 8): `Allow` lists every method of every route at the path.

Starlette named only the methods of the first route it tried (PUT /api/runs: `Allow: GET`, not GET, POST).
"""

from __future__ import annotations

import re

from fastapi.testclient import TestClient

from .helpers import assert_healthy

METHODS = {"GET", "POST", "PUT", "PATCH", "DELETE"}


def test_every_405_allows_the_methods_its_path_has(client: TestClient) -> None:
    paths: dict[str, set[str]] = {}  # concrete path -> the methods the schema documents there
    for template, operations in client.get("/openapi.json").json()["paths"].items():
        concrete = re.sub(r"\{[^}]+\}", "x", template)
        paths.setdefault(concrete, set()).update(method.upper() for method in operations)
    assert len(paths) > 30  # every route of the API, not a few
    checked = 0
    for path, documented in paths.items():
        for method in sorted(METHODS - documented):
            response = client.request(method, path)
            if response.status_code != 405:
                continue  # another route answers this method at this concrete path (say /api/runs/x as /import)
            allowed = {m.strip() for m in response.headers["allow"].split(",")}
            assert documented <= allowed and method not in allowed, (method, path, allowed)
            assert response.json() == {"detail": "Method Not Allowed"}
            checked += 1
    assert checked > 3 * len(paths) // 2, checked
    response = client.put("/api/runs")
    assert response.status_code == 405 and response.headers["allow"] == "GET, POST"
    assert client.post("/api/worlds/x").headers["allow"] == "GET, PUT, DELETE"
    assert_healthy(client)
