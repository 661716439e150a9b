"""Server test helpers: a live server (uvicorn, 127.0.0.1, ephemeral ports) that stops itself."""

from __future__ import annotations

import time
from contextlib import contextmanager
from pathlib import Path

import httpx

from protocol import Nodes, Welcome
from wavesph.local_server import InProcessServer

from coupling_client import TcpClient, handshake


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


def open_flume(name: str, t_end: float, depth: float) -> dict:
    """A 1.2 m flume with open ends, both absorbing (the left's elevation imposed, the right's
    extrapolated), dp = depth / 8 (whole rows: the particles fill to the still-water level),
    one elevation gauge g1 at x = 0.6 m."""
    return {"name": name, "dp": depth / 8, "t_end": t_end, "still_water_level": depth,
            "tank": {"x0": 0.0, "x1": 1.2, "z0": 0.0, "z1": 0.45},
            "water_blocks": [{"x0": 0.0, "x1": 1.2, "z0": 0.0, "z1": depth}],
            "open_boundaries": [{"side": "left", "elevation": "imposed", "absorb": True},
                                {"side": "right", "elevation": "extrapolated", "absorb": True}],
            "probes": [{"kind": "elevation", "name": "g1", "x": 0.6}],
            "output": {"probe_every": 0.05}}


class LiveServer(InProcessServer):
    """The in-process server with an HTTP client (the token sent if set) and run helpers."""

    def __enter__(self) -> "LiveServer":
        super().__enter__()
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
        super().__exit__(*exc)

    def create(self, mode: str = "coupled", **scene_overrides) -> dict:
        if mode == "coupled":
            scene_overrides.setdefault("open_boundaries", [{"side": "left"}])
        r = self.http.post("/runs", json={"scene": scene(**scene_overrides), "mode": mode})
        assert r.status_code == 201, r.text
        return r.json()

    def couple(self, run_id: str, timeout: float = 10.0, **handshake_kw) -> tuple[TcpClient, Welcome, Nodes]:
        """A TCP client of the run once it waits for one, past HELLO and GETNODES (``timeout``:
        the client's reads; a longer one waits longer for the run too, e.g. an SPH flume's build)."""
        self.wait_state(run_id, "waiting_for_client", timeout=max(30.0, timeout))
        client = TcpClient(self.tcp_port, timeout=timeout)
        welcome, nodes = handshake(client, run_id, **handshake_kw)
        return client, welcome, nodes

    def wait_state(self, run_id: str, *states: str, timeout: float = 30.0) -> dict:
        deadline = time.monotonic() + timeout
        while True:
            info = self.http.get(f"/runs/{run_id}").json()
            if info["state"] in states:
                return info
            if time.monotonic() > deadline:
                raise AssertionError(f"run {run_id} stayed {info['status']}, wanted {states}")
            time.sleep(0.02)


def wait_until(condition, what: str, timeout: float = 30.0) -> None:
    """Poll ``condition()`` until true: a loaded machine delays what an idle one does at once
    (e.g. the engine closes just after the run reads finished), so never assert it immediately."""
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            raise AssertionError(f"not within {timeout:g} s: {what}")
        time.sleep(0.02)


@contextmanager
def live_server(tmp_path: Path, engine_factory=None, log_level: str = "warning", **settings):
    with LiveServer(tmp_path / "runs", engine_factory, log_level, **settings) as srv:
        yield srv
