"""The API's documentation pages, `/docs` (Swagger UI) and `/redoc` (ReDoc), served with no network.

FastAPI's own pages load their scripts from a CDN, so without internet `/docs` is blank ("SwaggerUIBundle is
not defined"). The same pages are built here (FastAPI's `get_swagger_ui_html`, `get_redoc_html`) around the
script and style files that the `fastapi-offline` package ships, installed with the project's dependencies
and served from `/api-docs-assets`.
"""

from __future__ import annotations

from pathlib import Path

import fastapi_offline
from fastapi import FastAPI
from fastapi.openapi.docs import get_redoc_html, get_swagger_ui_html, get_swagger_ui_oauth2_redirect_html
from fastapi.responses import HTMLResponse
from fastapi.staticfiles import StaticFiles

ASSETS_DIR = Path(fastapi_offline.__file__).resolve().parent / "static"
ASSETS_URL = "/api-docs-assets"


def add_api_docs(app: FastAPI) -> None:
    """Serve `/docs` and `/redoc` from local assets; `app` must be made with `docs_url=None, redoc_url=None`."""
    openapi_url = app.openapi_url or "/openapi.json"
    redirect_url = app.swagger_ui_oauth2_redirect_url or "/docs/oauth2-redirect"
    app.mount(ASSETS_URL, StaticFiles(directory=ASSETS_DIR), name="api-docs-assets")

    @app.get("/docs", include_in_schema=False)
    def swagger_ui() -> HTMLResponse:
        return get_swagger_ui_html(
            openapi_url=openapi_url,
            title=f"{app.title}: API",
            oauth2_redirect_url=redirect_url,
            swagger_js_url=f"{ASSETS_URL}/swagger-ui-bundle.js",
            swagger_css_url=f"{ASSETS_URL}/swagger-ui.css",
            swagger_favicon_url=f"{ASSETS_URL}/favicon.png",
        )

    @app.get(redirect_url, include_in_schema=False)
    def swagger_ui_redirect() -> HTMLResponse:
        return get_swagger_ui_oauth2_redirect_html()

    @app.get("/redoc", include_in_schema=False)
    def redoc() -> HTMLResponse:
        page = get_redoc_html(
            openapi_url=openapi_url,
            title=f"{app.title}: API",
            redoc_js_url=f"{ASSETS_URL}/redoc.standalone.js",
            redoc_favicon_url=f"{ASSETS_URL}/favicon.png",
            with_google_fonts=False,
        )
        # ReDoc's sidebar credits its maker with a logo from the maker's host: the policy keeps images to
        # this server (the browser then asks for nothing elsewhere), the style hides the empty frame.
        body = bytes(page.body).replace(b"</head>", b"<style>a[href*='redocly'] { display: none }</style></head>")
        return HTMLResponse(body, headers={"Content-Security-Policy": "img-src 'self' data:"})
