"""The wavesph server on free loopback ports in a thread of this process, for the demo and the
coupled-flume cases, which drive it over its real HTTP and coupling sockets (and for the server
tests' harness)."""

from __future__ import annotations

import threading
import time
from pathlib import Path
from typing import Any


class InProcessServer:
    """The wavesph server (HTTP + WebSocket + TCP) on free loopback ports, in a thread.

    ``settings``: overrides of `server.settings.Settings` (e.g. max_runs); ``engine_factory``:
    the SPH side of coupled runs (default the server's, an sph_core Simulation with open ends)."""

    def __init__(self, runs_dir: Path, engine_factory: Any = None, log_level: str = "warning",
                 **settings: Any) -> None:
        import uvicorn

        from server.asgi import uvicorn_config
        from server.main import create_app
        from server.settings import Settings

        self.settings = Settings(host="127.0.0.1", port=0, tcp_port=0, runs_dir=runs_dir, **settings)
        self.app = (create_app(self.settings) if engine_factory is None
                    else create_app(self.settings, engine_factory))
        self.server = uvicorn.Server(uvicorn_config(self.app, self.settings, log_level=log_level))
        self.thread = threading.Thread(target=self.server.run, name="wavesph-server", daemon=True)

    def __enter__(self) -> "InProcessServer":
        self.thread.start()
        deadline = time.monotonic() + 30
        while not self.server.started:
            if time.monotonic() > deadline or not self.thread.is_alive():
                raise RuntimeError("the in-process server did not start")
            time.sleep(0.02)
        self.port = self.server.servers[0].sockets[0].getsockname()[1]
        self.tcp_port = self.app.state.tcp_port
        return self

    def __exit__(self, *exc: object) -> None:
        self.app.state.stopping.set()   # event streams end (as on Ctrl-C of `wavesph serve`)
        self.server.should_exit = True
        self.thread.join(timeout=30)


def wait_for_state(http: Any, run_id: str, states: set[str] | frozenset[str], timeout: float) -> dict:
    """Poll GET /runs/{run_id} until its state is one of ``states`` or ``timeout`` [s] passed;
    returns the last run record."""
    deadline = time.monotonic() + timeout
    while True:
        info = http.get(f"/runs/{run_id}").json()
        if info["state"] in states or time.monotonic() > deadline:
            return info
        time.sleep(0.05)
