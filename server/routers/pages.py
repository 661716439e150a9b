"""The page to watch runs (``/``), its static assets (``/static``), and the API docs served
from packaged assets (``/docs``: Swagger UI from the ``swagger-ui-bundle`` wheel; ``/redoc``
points there, as no packaged ReDoc exists), so everything works offline.

``install(app)`` replaces FastAPI's CDN-backed /docs and /redoc routes and mounts the rest.
"""

from __future__ import annotations

from pathlib import Path

from fastapi import APIRouter, FastAPI
from fastapi.openapi.docs import get_swagger_ui_html, get_swagger_ui_oauth2_redirect_html
from fastapi.responses import FileResponse, HTMLResponse, RedirectResponse
from fastapi.staticfiles import StaticFiles

STATIC = Path(__file__).resolve().parents[1] / "static"


def _swagger_dir() -> Path | None:
    try:
        from swagger_ui_bundle import swagger_ui_path
    except ImportError:
        return None
    return Path(swagger_ui_path)


def install(app: FastAPI) -> None:
    """Mount the page, its assets and the offline API docs on ``app``."""
    docs = {app.docs_url, app.redoc_url, app.swagger_ui_oauth2_redirect_url, "/docs", "/redoc"}
    app.router.routes = [r for r in app.router.routes if getattr(r, "path", None) not in docs]
    router = APIRouter(include_in_schema=False)

    @router.get("/")
    async def index() -> FileResponse:
        """The run monitor: one static HTML file, no build step, no CDN."""
        return FileResponse(STATIC / "index.html", media_type="text/html")

    swagger = _swagger_dir()
    if swagger is not None:  # before /static, which would otherwise take its paths
        app.mount("/static/swagger", StaticFiles(directory=swagger), name="swagger")
    app.mount("/static", StaticFiles(directory=STATIC), name="static")

    @router.get("/docs")
    async def swagger_ui() -> HTMLResponse:
        if swagger is None:
            return HTMLResponse("<p>API docs need the swagger-ui-bundle package; the schema is "
                                "at <a href='/openapi.json'>/openapi.json</a>.</p>")
        return get_swagger_ui_html(
            openapi_url=app.openapi_url or "/openapi.json", title=f"{app.title} - API",
            swagger_js_url="/static/swagger/swagger-ui-bundle.js",
            swagger_css_url="/static/swagger/swagger-ui.css",
            swagger_favicon_url="/static/swagger/favicon-32x32.png",
            oauth2_redirect_url="/docs/oauth2-redirect")

    @router.get("/docs/oauth2-redirect")
    async def swagger_redirect() -> HTMLResponse:
        return get_swagger_ui_oauth2_redirect_html()

    @router.get("/redoc")
    async def redoc() -> RedirectResponse:
        return RedirectResponse("/docs")

    app.include_router(router)
