"""The FastAPI app: routers, and the run manager + TCP coupling port created in lifespan."""

from __future__ import annotations

import logging
from contextlib import asynccontextmanager

from fastapi import FastAPI

from .engine import EngineFactory
from .flume_engine import flume_engine
from .routers import couple, pages, runs
from .runs import RunManager
from .settings import Settings
from .tcp import start_tcp_server

log = logging.getLogger("wavesph.server")


def create_app(settings: Settings | None = None,
               engine_factory: EngineFactory = flume_engine) -> FastAPI:
    """The app. ``engine_factory`` builds the SPH side of coupled runs: by default an sph_core
    Simulation with open ends (server/flume_engine.py); tests of the doors pass a deterministic double."""
    settings = settings or Settings.from_env()

    @asynccontextmanager
    async def lifespan(app: FastAPI):
        manager = RunManager(settings, engine_factory)
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
    app.include_router(runs.router)
    app.include_router(couple.router)
    pages.install(app)  # the run monitor at /, offline /docs (server/routers/pages.py)
    return app
