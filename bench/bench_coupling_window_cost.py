"""Question: what does one coupling window cost in protocol + transport + server overhead?

A live server (uvicorn, 127.0.0.1, in a child process) runs a coupled run whose SPH engine does no work (a null
engine defined here), so the time per window is pure coupling overhead: framing, validation,
the session, a worker-thread hop for the engine calls, the gauge row written to disk, and the
round trip. Measured for the plain TCP port and the WebSocket endpoint, for a small and a large
boundary (number of nodes). One JSON object per line.

    .venv/bin/python bench/bench_coupling_window_cost.py [--windows 2000]
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import socket
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np
import uvicorn
from websockets.sync.client import connect as ws_connect

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from protocol import (Bye, ClientSession, FrameDecoder, GetNodes, Hello, Nodes, Result, Set,  # noqa: E402
                      Solve, Welcome, decode_frame)
from server.engine import BoundaryNodes, Measurement, SceneSummary  # noqa: E402
from server.main import create_app  # noqa: E402
from server.settings import Settings  # noqa: E402


class NullEngine:
    """Engine contract with no SPH work: isolates the coupling overhead."""

    def __init__(self, n_nodes: int, t_end: float) -> None:
        self.summary = SceneSummary(9.81, 0.5, 0.5, -0.25, 0.0, t_end, 1e-3)
        self._nodes = BoundaryNodes(np.zeros(n_nodes), np.linspace(-0.5, 0, n_nodes),
                                    np.zeros(n_nodes, np.uint32), np.array([1.0, 2.0]), ["a", "b"])
        self.t, self.steps, self.n_particles = 0.0, 0, 1
        self._m = Measurement(np.zeros(2), np.ones(2, bool), np.zeros(2), np.zeros(2), 1)
        self._t1 = 0.0

    def nodes(self): return self._nodes
    def set_window(self, t0, t1, u, w, eta): self._t1 = t1
    def solve_window(self):
        self.t, self.steps = self._t1, self.steps + 1
        return self._m
    def measure(self): return self._m
    def checkpoint(self): pass
    def goback(self): pass
    def stability(self): return {}
    def close(self): pass


SCENE = {"dp": 0.05, "t_end": 1.0e4, "still_water_level": 0.5,
         "tank": {"x0": 0.0, "x1": 1.0, "z0": 0.0, "z1": 1.0},
         "water_blocks": [{"x0": 0.0, "x1": 1.0, "z0": 0.0, "z1": 0.5}]}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--windows", type=int, default=2000)
    args = ap.parse_args()
    for n_nodes in (16, 4096):
        for door in ("tcp", "websocket"):
            with tempfile.TemporaryDirectory() as tmp:
                print(json.dumps(measure(Path(tmp), door, n_nodes, args.windows)), flush=True)


def serve(tmp: Path, n_nodes: int, ports) -> None:
    """Child process: the server, so client and server do not share one GIL."""
    settings = Settings(runs_dir=tmp, port=0, tcp_port=0)
    app = create_app(settings, lambda req, d: NullEngine(n_nodes, req.scene.t_end))
    server = uvicorn.Server(uvicorn.Config(app, host="127.0.0.1", port=0, log_level="error",
                                           ws_per_message_deflate=False))  # as `wavesph serve`
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    while not server.started:
        time.sleep(0.01)
    ports.put((server.servers[0].sockets[0].getsockname()[1], app.state.tcp_port))
    thread.join()


def measure(tmp: Path, door: str, n_nodes: int, windows: int) -> dict:
    ctx = multiprocessing.get_context("fork")
    ports = ctx.Queue()
    child = ctx.Process(target=serve, args=(tmp, n_nodes, ports), daemon=True)
    child.start()
    port, tcp_port = ports.get(timeout=60)
    import httpx

    run_id = httpx.post(f"http://127.0.0.1:{port}/runs", json={"scene": SCENE}).json()["id"]
    while httpx.get(f"http://127.0.0.1:{port}/runs/{run_id}").json()["state"] != "waiting_for_client":
        time.sleep(0.01)
    cs = ClientSession()
    if door == "tcp":
        sock = socket.create_connection(("127.0.0.1", tcp_port))
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        decoder, pending = FrameDecoder(), []

        def send(*frames: bytes) -> None:
            sock.sendall(b"".join(frames))

        def recv():
            while not pending:
                pending.extend(decoder.feed(sock.recv(1 << 20)))
            return pending.pop(0)
    else:
        ws = ws_connect(f"ws://127.0.0.1:{port}/runs/{run_id}/couple", max_size=None).__enter__()

        def send(*frames: bytes) -> None:
            for f in frames:
                ws.send(f)

        def recv():
            return decode_frame(ws.recv())
    send(cs.request(Hello(0, bytes(32), run_id, "bench")))
    welcome = cs.reply(*recv(), expect=Welcome)
    send(cs.request(GetNodes()))
    cs.reply(*recv(), expect=Nodes)
    u = np.linspace(0, 1, n_nodes)
    dt, t = 0.01, 0.0
    tic = time.perf_counter()
    for _ in range(windows):
        send(cs.request(Set(t, t + dt, u, u, u)), cs.request(Solve()))
        cs.reply(*recv(), expect=Result)
        t += dt
    wall = time.perf_counter() - tic
    send(cs.request(Bye("")))
    cs.reply(*recv(), expect=Bye)
    info = httpx.get(f"http://127.0.0.1:{port}/runs/{run_id}").json()
    child.terminate()
    child.join(timeout=10)
    set_bytes = 16 + 16 + 3 * (4 + 8 * welcome.n_nodes)
    return {"question": "coupling overhead per window (null SPH engine)", "transport": door,
            "n_nodes": n_nodes, "windows": windows, "set_frame_bytes": set_bytes,
            "us_per_window": round(1e6 * wall / windows, 1),
            "windows_per_s": round(windows / wall, 1), "status": info["status"],
            "gauge_rows": info["windows"]}


if __name__ == "__main__":
    main()
