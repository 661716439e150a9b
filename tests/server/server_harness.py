"""Server test helpers: a live server (uvicorn, 127.0.0.1, ephemeral ports) that stops itself."""

from __future__ import annotations

import threading
import time
from contextlib import contextmanager
from pathlib import Path

import httpx
import uvicorn

from server.main import create_app
from server.settings import Settings


def scene(**overrides) -> dict:
    """A small valid sph_core scene: 1 m x 0.5 m tank, 0.3 m of water, two gauges."""
    base = {
        "name": "flume", "dp": 0.05, "t_end": 1.0, "still_water_level": 0.3,
        "tank": {"x0": 0.0, "x1": 1.0, "z0": 0.0, "z1": 0.5},
        "water_blocks": [{"x0": 0.0, "x1": 1.0, "z0": 0.0, "z1": 0.3}],
        "probes": [{"kind": "elevation", "name": "g_mid", "x": 0.5},
                   {"kind": "elevation", "name": "dry_g", "x": 0.9}],
        "output": {"probe_every": 0.05},
    }
    base.update(overrides)
    return base


class LiveServer:
    def __init__(self, app, settings: Settings, log_level: str = "warning") -> None:
        self.app, self.settings = app, settings
        config = uvicorn.Config(app, host="127.0.0.1", port=0, log_level=log_level,
                                ws_max_size=settings.max_frame + 16, lifespan="on",
                                ws_per_message_deflate=False)  # as `wavesph serve`
        self.server = uvicorn.Server(config)
        self.thread = threading.Thread(target=self.server.run, daemon=True)

    def __enter__(self) -> "LiveServer":
        self.thread.start()
        deadline = time.monotonic() + 20
        while not self.server.started:
            if time.monotonic() > deadline or not self.thread.is_alive():
                raise RuntimeError("server did not start")
            time.sleep(0.02)
        self.port = self.server.servers[0].sockets[0].getsockname()[1]
        self.tcp_port = self.app.state.tcp_port
        self.url = f"http://127.0.0.1:{self.port}"
        self.http = httpx.Client(base_url=self.url, timeout=30,
                                 headers={"Authorization": f"Bearer {self.settings.token}"}
                                 if self.settings.token else {})
        return self

    @property
    def manager(self):
        return self.app.state.manager

    def __exit__(self, *exc) -> None:
        self.http.close()
        self.server.should_exit = True
        self.thread.join(timeout=20)

    def create(self, mode: str = "coupled", **scene_overrides) -> dict:
        if mode == "coupled":
            scene_overrides.setdefault("open_boundaries", [{"side": "left"}])
        r = self.http.post("/runs", json={"scene": scene(**scene_overrides), "mode": mode})
        assert r.status_code == 201, r.text
        return r.json()

    def wait_state(self, run_id: str, *states: str, timeout: float = 30.0) -> dict:
        deadline = time.monotonic() + timeout
        while True:
            info = self.http.get(f"/runs/{run_id}").json()
            if info["state"] in states:
                return info
            if time.monotonic() > deadline:
                raise AssertionError(f"run {run_id} stayed {info['status']}, wanted {states}")
            time.sleep(0.02)


@contextmanager
def live_server(tmp_path: Path, engine_factory=None, log_level: str = "warning", **settings):
    s = Settings(runs_dir=tmp_path / "runs", tcp_port=0, port=0, **settings)
    app = create_app(s) if engine_factory is None else create_app(s, engine_factory)
    with LiveServer(app, s, log_level) as srv:
        yield srv
