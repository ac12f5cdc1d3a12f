"""The browser dashboard (frontend/dist, built by `npm run build`) served at `/`.

`mount_frontend(app, dist_dir)` adds two things only: `GET /` (index.html) and `/assets` (Vite's hashed
bundles). Nothing is mounted at `/` itself, so `/api`, `/docs`, `/openapi.json` and any route added
later keep working, and an unknown `/api/...` path stays FastAPI's JSON 404. Without a build the page
at `/` says how to make one (503) instead of failing; the server needs a restart after the first build.
"""

from __future__ import annotations

from pathlib import Path

from fastapi import FastAPI
from fastapi.responses import FileResponse, HTMLResponse, Response
from fastapi.staticfiles import StaticFiles

DIST_DIR = Path(__file__).resolve().parents[3] / "frontend" / "dist"
"""Where `npm run build` writes the dashboard in a source checkout."""

NOT_BUILT = """<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>Horde Lab</title></head>
<body style="font: 18px system-ui, sans-serif; max-width: 40rem; margin: 3rem auto; line-height: 1.5">
<h1>Horde Lab</h1>
<p>The dashboard has not been built. Run <code>make serve</code>, or in <code>frontend/</code>:
<code>npm ci &amp;&amp; npm run build</code>, then reload.</p>
<p>The API works meanwhile: see <a href="/docs">/docs</a>.</p>
</body></html>
"""

# index.html names the hashed bundles of the current build, so it must be fetched fresh every time;
# the bundles themselves never change under their names.
NO_CACHE = {"Cache-Control": "no-cache"}


def mount_frontend(app: FastAPI, dist_dir: Path = DIST_DIR) -> None:
    """Serve the built dashboard: `dist_dir/index.html` at `/` and `dist_dir/assets` at `/assets`.

    Args:
        app: the FastAPI app; its other routes are left as they are.
        dist_dir: the Vite build output (default: the repository's frontend/dist).
    """
    index = dist_dir / "index.html"

    @app.get("/", include_in_schema=False)
    def dashboard() -> Response:
        if not index.is_file():
            return HTMLResponse(NOT_BUILT, status_code=503, headers=NO_CACHE)
        return FileResponse(index, media_type="text/html", headers=NO_CACHE)

    assets = dist_dir / "assets"
    if assets.is_dir():  # without a build, `/` explains how to make one and there are no assets to serve
        app.mount("/assets", StaticFiles(directory=assets), name="frontend-assets")
