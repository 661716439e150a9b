"""Question: what share of a real coupled run's wall time is coupling, and does SPH run as fast
behind the server as in-process?

The server (child process, default engine: sph_core's OpenFlume) runs a 2 m flume with open ends;
a Python client built on the protocol package imposes a linear (Airy) wave over TCP or WebSocket
for N windows. Reported per transport: the server's own figures (particle-steps/s while solving,
coupling_overhead_share = wall time not spent solving / wall time since the client connected) and
the client's wall time per window (first window, with the numba cache load, not timed); then the same flume driven in-process with the same boundary
data (no server) for the particle-steps/s baseline. One JSON object per line.

    .venv/bin/python bench/bench_coupled_flume_overhead.py [--windows 20] [--dp 0.02]
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

import httpx
import numpy as np
import uvicorn
from scipy.optimize import brentq
from websockets.sync.client import connect as ws_connect

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from protocol import (Bye, ClientSession, FrameDecoder, GetNodes, Hello, Nodes, Result, Set,  # noqa: E402
                      Solve, Welcome, decode_frame)
from server.flume_engine import FlumeEngine  # noqa: E402
from server.main import create_app  # noqa: E402
from server.schemas import RunRequest  # noqa: E402
from server.settings import Settings  # noqa: E402

G, DEPTH, H, T, WINDOW = 9.81, 0.3, 0.02, 1.0, 0.05


def flume(dp: float) -> dict:
    return {"name": "bench-flume", "dp": dp, "t_end": 100.0, "still_water_level": DEPTH,
            "tank": {"x0": 0.0, "x1": 2.0, "z0": 0.0, "z1": 0.45},
            "water_blocks": [{"x0": 0.0, "x1": 2.0, "z0": 0.0, "z1": DEPTH}],
            "open_boundaries": [{"side": "left", "elevation": "imposed", "absorb": True},
                                {"side": "right", "elevation": "extrapolated", "absorb": True}],
            "probes": [{"kind": "elevation", "name": "g1", "x": 1.0}],
            "output": {"probe_every": WINDOW}}


def airy(x, z, t):
    omega = 2 * np.pi / T
    k = brentq(lambda k: omega**2 - G * k * np.tanh(k * DEPTH), 1e-6, 100.0, xtol=1e-15)
    a, ph, zc = H / 2, k * x - omega * t, np.minimum(z, 0.0)
    return (a * omega * np.cosh(k * (zc + DEPTH)) / np.sinh(k * DEPTH) * np.cos(ph),
            a * omega * np.sinh(k * (zc + DEPTH)) / np.sinh(k * DEPTH) * np.sin(ph), a * np.cos(ph))


def serve(tmp: Path, ports) -> None:
    app = create_app(Settings(runs_dir=tmp, port=0, tcp_port=0))
    server = uvicorn.Server(uvicorn.Config(app, host="127.0.0.1", port=0, log_level="error",
                                           ws_per_message_deflate=False))
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    while not server.started:
        time.sleep(0.01)
    ports.put((server.servers[0].sockets[0].getsockname()[1], app.state.tcp_port))
    thread.join()


def coupled(door: str, body: dict, windows: int) -> dict:
    ctx = multiprocessing.get_context("spawn")  # fork after OpenMP is unsafe
    ports = ctx.Queue()
    with tempfile.TemporaryDirectory() as tmp:
        child = ctx.Process(target=serve, args=(Path(tmp), ports), daemon=True)
        child.start()
        port, tcp_port = ports.get(timeout=60)
        base = f"http://127.0.0.1:{port}"
        run_id = httpx.post(f"{base}/runs", json=body).json()["id"]
        while httpx.get(f"{base}/runs/{run_id}").json()["state"] != "waiting_for_client":
            time.sleep(0.05)
        cs = ClientSession()
        if door == "tcp":
            sock = socket.create_connection(("127.0.0.1", tcp_port))
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            dec, pending = FrameDecoder(), []

            def send(*frames):
                sock.sendall(b"".join(frames))

            def recv():
                while not pending:
                    pending.extend(dec.feed(sock.recv(1 << 20)))
                return pending.pop(0)
        else:
            ws = ws_connect(f"ws://127.0.0.1:{port}/runs/{run_id}/couple", max_size=None).__enter__()

            def send(*frames):
                for f in frames:
                    ws.send(f)

            def recv():
                return decode_frame(ws.recv())
        send(cs.request(Hello(0, bytes(32), run_id, "bench")))
        cs.reply(*recv(), expect=Welcome)
        send(cs.request(GetNodes()))
        nodes = cs.reply(*recv(), expect=Nodes)
        t, steps, tic = 0.0, 0, 0.0
        for k in range(windows):
            if k == 1:  # the first window (numba cache load in a fresh process) is not timed
                tic, steps = time.perf_counter(), 0
            u, w, eta = airy(nodes.x, nodes.z, t + WINDOW)
            send(cs.request(Set(t, t + WINDOW, u, w, eta)), cs.request(Solve()))
            steps += cs.reply(*recv(), expect=Result).steps
            t += WINDOW
        wall = time.perf_counter() - tic
        send(cs.request(Bye("")))
        cs.reply(*recv(), expect=Bye)
        info = httpx.get(f"{base}/runs/{run_id}").json()
        child.terminate()
        child.join(timeout=10)
    return {"question": "coupled flume: coupling share and SPH speed behind the server",
            "transport": door, "windows": windows, "particles": info["particles"],
            "steps": info["steps"],
            "particle_steps_per_s": round(info["particles"] * steps / wall),  # client clock, windows 2..N
            "server_particle_steps_per_s": round(info["particle_steps_per_s"]),  # all windows
            "coupling_overhead_share": round(info["coupling_overhead_share"], 4),
            "client_s_per_window": round(wall / (windows - 1), 4), "status": info["status"]}


def in_process(body: dict, windows: int) -> dict:
    engine = FlumeEngine(RunRequest.model_validate(body), None)
    nodes = engine.nodes()
    engine.set_window(0.0, WINDOW, *airy(nodes.x, nodes.z, WINDOW))
    engine.solve_window()  # first window outside the timing (numba warm-up), as the server's too
    t, solve, steps0 = WINDOW, 0.0, engine.steps
    for _ in range(windows - 1):
        engine.set_window(t, t + WINDOW, *airy(nodes.x, nodes.z, t + WINDOW))
        tic = time.perf_counter()
        engine.solve_window()
        solve += time.perf_counter() - tic
        t += WINDOW
    return {"question": "coupled flume: coupling share and SPH speed behind the server",
            "transport": "in-process (no server)", "windows": windows,
            "particles": engine.n_particles, "steps": engine.steps,
            "particle_steps_per_s": round(engine.n_particles * (engine.steps - steps0) / solve),
            "client_s_per_window": round(solve / (windows - 1), 4)}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--windows", type=int, default=20)
    ap.add_argument("--dp", type=float, default=0.02)
    args = ap.parse_args()
    body = {"scene": flume(args.dp), "mode": "coupled", "coupling": {"window_max": WINDOW}}
    print(json.dumps(in_process(body, args.windows)), flush=True)  # also warms the numba cache
    for door in ("tcp", "websocket"):
        print(json.dumps(coupled(door, body, args.windows)), flush=True)


if __name__ == "__main__":
    main()
