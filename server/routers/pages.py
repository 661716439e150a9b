"""The page to watch runs (``/``), its static assets (``/static``), and the API docs served
from packaged assets (``/docs``: Swagger UI, ``/redoc``: ReDoc, both from the
``fastapi-offline`` wheel), so everything works offline. FastAPI writes OpenAPI 3.1, which
Swagger UI reads from version 5 on: the 4.15.5 of the ``swagger-ui-bundle`` wheel showed
"Unable to render this definition" (tests/test_server/test_server_pages.py checks the version).

``install(app)`` replaces FastAPI's CDN-backed /docs and /redoc routes and mounts the rest.
"""

from __future__ import annotations

from pathlib import Path

from fastapi import APIRouter, FastAPI
from fastapi.openapi.docs import (get_redoc_html, get_swagger_ui_html,
                                  get_swagger_ui_oauth2_redirect_html)
from fastapi.responses import FileResponse, HTMLResponse, RedirectResponse
from fastapi.staticfiles import StaticFiles

STATIC = Path(__file__).resolve().parents[1] / "static"


def _docs_dir() -> Path | None:
    """swagger-ui-bundle.js, swagger-ui.css, redoc.standalone.js, favicon.png."""
    try:
        import fastapi_offline
    except ImportError:
        return None
    return Path(fastapi_offline.__file__).parent / "static"


def install(app: FastAPI) -> None:
    """Mount the page, its assets and the offline API docs on ``app``."""
    docs = {app.docs_url, app.redoc_url, app.swagger_ui_oauth2_redirect_url, "/docs", "/redoc"}
    app.router.routes = [r for r in app.router.routes if getattr(r, "path", None) not in docs]
    router = APIRouter(include_in_schema=False)

    @router.get("/")
    async def index() -> FileResponse:
        """The run monitor: one static HTML file, no build step, no CDN."""
        return FileResponse(STATIC / "index.html", media_type="text/html")

    swagger = _docs_dir()
    if swagger is not None:  # before /static, which would otherwise take its paths
        app.mount("/static/swagger", StaticFiles(directory=swagger), name="swagger")
    app.mount("/static", StaticFiles(directory=STATIC), name="static")

    @router.get("/docs")
    async def swagger_ui() -> HTMLResponse:
        if swagger is None:
            return HTMLResponse("<p>API docs need the fastapi-offline package; the schema is "
                                "at <a href='/openapi.json'>/openapi.json</a>.</p>")
        return get_swagger_ui_html(
            openapi_url=app.openapi_url or "/openapi.json", title=f"{app.title} - API",
            swagger_js_url="/static/swagger/swagger-ui-bundle.js",
            swagger_css_url="/static/swagger/swagger-ui.css",
            swagger_favicon_url="/static/swagger/favicon.png",
            oauth2_redirect_url="/docs/oauth2-redirect")

    @router.get("/docs/oauth2-redirect")
    async def swagger_redirect() -> HTMLResponse:
        return get_swagger_ui_oauth2_redirect_html()

    @router.get("/redoc", response_model=None)
    async def redoc() -> HTMLResponse | RedirectResponse:
        if swagger is None:
            return RedirectResponse("/docs")
        return get_redoc_html(openapi_url=app.openapi_url or "/openapi.json",
                              title=f"{app.title} - API", with_google_fonts=False,
                              redoc_js_url="/static/swagger/redoc.standalone.js",
                              redoc_favicon_url="/static/swagger/favicon.png")

    app.include_router(router)
