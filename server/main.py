"""The FastAPI app: routers, and the run manager + TCP coupling port created in lifespan."""

from __future__ import annotations

import threading

import logging
from contextlib import asynccontextmanager

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.openapi.utils import get_openapi
from fastapi.responses import JSONResponse

from .deps import redact_tokens_in_server_logs
from .engine import EngineFactory
from .flume_engine import flume_engine
from .guard import LoopbackGuard
from .routers import couple, pages, runs
from .run_manager import RunManager
from .schemas import RunRequest
from .settings import Settings
from .tcp import start_tcp_server
from .theory_client import serve_theory
from .validation import clean_errors

log = logging.getLogger("wavesph.server")


def create_app(settings: Settings | None = None,
               engine_factory: EngineFactory = flume_engine) -> FastAPI:
    """The app. ``engine_factory`` builds the SPH side of coupled runs: by default an sph_core
    Simulation with open ends (server/flume_engine.py); tests of the doors pass a deterministic double."""
    settings = settings or Settings.from_env()

    @asynccontextmanager
    async def lifespan(app: FastAPI):
        redact_tokens_in_server_logs()  # after uvicorn configured its logging
        manager = RunManager(settings, engine_factory, serve_theory)
        app.state.manager = manager
        tcp = None
        if settings.tcp_port is not None:
            tcp = await start_tcp_server(manager, settings.tcp_host or settings.host, settings.tcp_port)
            app.state.tcp_port = tcp.sockets[0].getsockname()[1]
            log.info("TCP coupling port %s", app.state.tcp_port)
        try:
            yield
        finally:
            if tcp is not None:
                tcp.close()
            await manager.shutdown()

    app = FastAPI(title="wavesph", version="0.1.0", lifespan=lifespan,
                  description="SPH coupling server: HTTP run management, WebSocket and TCP coupling "
                              "(protocol/PROTOCOL.md).")
    # set when the server is told to stop (server.asgi.Server): the page's event streams end at
    # once instead of holding uvicorn's "Waiting for connections to close" until the run ends
    app.state.stopping = threading.Event()
    app.include_router(runs.router)
    app.include_router(couple.router)

    @app.exception_handler(RequestValidationError)
    async def unprocessable(request: Request, exc: RequestValidationError) -> JSONResponse:
        """FastAPI's 422 without the input (it may be huge, or a NaN JSON cannot carry)."""
        return JSONResponse({"detail": clean_errors(list(exc.errors()))}, status_code=422)

    def openapi() -> dict:
        if app.openapi_schema is None:  # POST /runs reads its body itself: add RunRequest's schema
            schema = get_openapi(title=app.title, version=app.version, description=app.description,
                                 routes=app.routes)
            body = RunRequest.model_json_schema(ref_template="#/components/schemas/{model}")
            models = schema.setdefault("components", {}).setdefault("schemas", {})
            models.update(body.pop("$defs", {}))
            models["RunRequest"] = body
            app.openapi_schema = schema
        return app.openapi_schema

    app.openapi = openapi  # type: ignore[method-assign]
    app.add_middleware(LoopbackGuard, enabled=settings.loopback_only)  # CSRF, DNS rebinding
    pages.install(app)  # the run monitor at /, offline /docs (server/routers/pages.py)
    return app
