"""Question: what does coupling cost? Loopback round trip per window (p50, p99) and its share of
a coupled run's time, over WebSocket and over TCP (goal: <= 2 % at 64 boundary nodes and
>= 10 SPH sub-steps per window).

Cases, both with 64 boundary nodes: the server (child process, `wavesph serve`'s app, default
engine: an sph_core Simulation with open ends) runs
  - beach flume: the demo's flume (open inlet, 2 m flat, 1:10 beach, depth 0.24 m) at dp = 0.01 m
    (~9000 particles, H/dp = 2 for the bench's wave; a production-like SPH zone), 64 inlet levels;
  - small flume: 4 m, both ends open, depth 0.3 m, dp = 0.03 m (~1800 particles), 32 levels
    per end: little SPH work per window, so the coupling share is near its worst.
A linear wave (H = 0.02 m, T = 1 s) is imposed by a client on the protocol package, one window
of T/50 = 0.02 s at a time (~50-90 SPH sub-steps per window).

Definitions (per window i, windows 2..N; window 1 carries the numba cache load and is not timed):
    client_i  client wall time from sending SET+SOLVE to holding the decoded RESULT
              (the wave model's own time, sampling the boundary, is not included)
    solve_i   the engine's solve_window() time inside the server (timed by a thin wrapper)
    rtt_i     = client_i - solve_i: framing, validation, session, the worker-thread hop (none
              for windows solved in under 1 ms: they run on the event loop), the gauge row
              written to disk, both socket trips
    overhead_share = sum(rtt_i) / sum(client_i)
`server_overhead_share` is the server's own figure (GET /runs/{id}: 1 - solve time / wall time
since the client connected, handshake and window 1 included).

Also printed: the same flume driven in this process with the same data (particle-steps/s
without a server), and a null engine (no SPH work: rtt is the whole window) at 64 and 4096
nodes, the pure cost of a window, beside the asyncio echo floor of each transport measured in
the same run: the same request and reply sizes through a server that does nothing but answer
(TCP: asyncio streams; WebSocket: a Starlette endpoint under the same uvicorn configuration).
Every line carries the 1-minute load average before and after it (`load`).

`--profile` adds, for the null-engine runs, where a window's time goes inside the server:
timers around decode (frame bytes to messages), validate (the session's checks), engine (the
solve call, inline for a null engine), record (gauge row and run progress before the reply),
encode (RESULT frame) and write (the transport's send), summed per window; `server_busy` is from
the first decode of a window to the end of its write, `after_reply` the run's progress the
server records once the RESULT is written (overlapping the client's next window), and
`outside_server` = rtt - server_busy is the client's own encode/decode, the sockets, the kernel
and the event loops' wake-ups. One JSON object per line.

    .venv/bin/python bench/coupling_overhead.py [--windows 40] [--small-windows 150]
                                                [--null-windows 500] [--only null] [--profile]
The share scales as (per-window coupling cost) / (SPH work per window): a longer or finer SPH
zone lowers it, fewer particles raise it (see particles and solve_ms_per_window in the lines).
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import os
import socket
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any, Callable

# numba's OpenMP threads spin while idle by default; with other processes on the cores that
# makes each step 10-20x slower and the coupling share meaninglessly small
os.environ.setdefault("OMP_WAIT_POLICY", "passive")

import httpx  # noqa: E402
import numpy as np  # noqa: E402
import uvicorn  # noqa: E402
from websockets.sync.client import connect as ws_connect  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from protocol import (Bye, ClientSession, FrameDecoder, GetNodes, Hello, Nodes, Result, Set,  # noqa: E402
                      Solve, Welcome, decode_frame)
from server.asgi import uvicorn_config  # noqa: E402
from server.engine import EngineNodes, Measurement, SceneSummary  # noqa: E402
from server.flume_engine import FlumeEngine  # noqa: E402
from server.main import create_app  # noqa: E402
from server.schemas import RunRequest  # noqa: E402
from server.settings import Settings  # noqa: E402
from wave_client.theories import AiryWave  # noqa: E402

QUESTION = "coupling overhead: loopback round trip per window and its share of run time"
DEPTH, H, T = 0.3, 0.02, 1.0
WINDOW = T / 50
GOAL_SHARE = 0.02


def beach_flume() -> dict:
    """The demo's flume (open inlet, 1:10 beach, closed end) at dp = 0.01 m (H/dp = 4): the
    top 0.314 m gives ceil(0.314 / (dp/2)) + 1 = 64 node levels at the inlet."""
    from wavesph.cases.demo_flume import demo_scene

    scene = demo_scene(0.01, 100.0)
    d = scene["still_water_level"]
    x1 = 2.0 + (0.30 / 0.1)  # the beach ends 0.06 m above still water, under the tank top
    return {**scene, "name": "bench-beach-flume", "tank": {"x0": 0.0, "x1": x1, "z0": 0.0, "z1": 0.314},
            "beds": [{"points": [[2.0, 0.0], [x1, 0.30]]}],
            "water_blocks": [{"x0": 0.0, "x1": 2.0 + d / 0.1, "z0": 0.0, "z1": d}],
            "output": {"probe_every": WINDOW}}


def flume(dp: float, length: float) -> dict:
    """Open-ended flume; the top 0.46 m gives ceil(0.46 / (dp/2)) + 1 = 32 levels per end at 0.03."""
    length = dp * round(length / dp)  # a right open end needs a whole number of dp
    return {"name": "bench-flume", "dp": dp, "t_end": 100.0, "still_water_level": DEPTH,
            "tank": {"x0": 0.0, "x1": length, "z0": 0.0, "z1": 0.46},
            "water_blocks": [{"x0": 0.0, "x1": length, "z0": 0.0, "z1": DEPTH}],
            "open_boundaries": [{"side": "left", "elevation": "imposed", "absorb": True},
                                {"side": "right", "elevation": "extrapolated", "absorb": True}],
            "probes": [{"kind": "elevation", "name": "g1", "x": 0.5 * length}],
            "output": {"probe_every": WINDOW}}


def wave_at(wave: AiryWave, nodes: Nodes, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """u, w at the nodes and eta at their x, as the coupling client samples them."""
    wave.advance_to(t)
    u, w = wave.velocity(nodes.x, nodes.z)
    return np.asarray(u), np.asarray(w), np.asarray(wave.elevation(nodes.x))


# --------------------------------------------------------------------------- server side (child)
_SOLVES: Any = None  # child process: queue receiving each engine's solve times at close


class TimedFlumeEngine(FlumeEngine):
    """The production engine, timing each solve_window (what the client's wait is made of)."""

    def __init__(self, request: RunRequest, run_dir: Path) -> None:
        super().__init__(request, run_dir)
        self.solve_s: list[float] = []

    def solve_window(self) -> Measurement:
        tic = time.perf_counter()
        m = super().solve_window()
        self.solve_s.append(time.perf_counter() - tic)
        return m

    def close(self) -> None:
        _SOLVES.put((self.solve_s, None))
        super().close()


class NullEngine:
    """Engine contract with no SPH work: isolates the coupling cost of a window."""

    def __init__(self, n_nodes: int, t_end: float) -> None:
        self.summary = SceneSummary(9.81, DEPTH, DEPTH, -0.5 * DEPTH, 0.0, t_end, 1e-3)
        self._nodes = EngineNodes(np.zeros(n_nodes), np.linspace(-DEPTH, 0, n_nodes),
                                    np.zeros(n_nodes, np.uint32), np.array([1.0, 2.0]), ["a", "b"])
        self.t, self.steps, self.n_particles = 0.0, 0, 1
        self._m = Measurement(np.zeros(2), np.ones(2, bool), np.zeros(2), np.zeros(2), 1)
        self._t1 = 0.0
        self.solve_s: list[float] = []

    def nodes(self) -> EngineNodes: return self._nodes
    def set_window(self, t0, t1, u, w, eta) -> None: self._t1 = t1
    def solve_window(self) -> Measurement:
        self.t, self.steps = self._t1, self.steps + 1
        self.solve_s.append(0.0)
        return self._m
    def measure(self) -> Measurement: return self._m
    def checkpoint(self) -> None: pass
    def goback(self) -> None: pass
    def stability(self) -> dict: return {}
    def close(self) -> None: _SOLVES.put((self.solve_s, _PROFILE))


_PROFILE: list[dict[str, int]] | None = None  # child process, --profile: per-window stage ns


def install_profile() -> list[dict[str, int]]:
    """Child process: wrap the server's per-window stages in timers; one dict of ns per window,
    closed by the write of the window's RESULT."""
    from collections import defaultdict

    import protocol.framing as framing
    import protocol.session as session
    import server.doors as doors
    import server.store as store
    import server.transports as transports

    windows: list[dict[str, int]] = []
    cur: dict[str, int] = defaultdict(int)
    replied = [False]  # the window's RESULT is written: what follows is overlapped bookkeeping

    def timed(stage: str, fn: Callable) -> Callable:
        def wrapper(*a: Any, **k: Any) -> Any:
            tic = time.perf_counter_ns()
            if replied[0] and stage == "record" and windows:  # the run's progress, after the reply
                try:
                    return fn(*a, **k)
                finally:
                    windows[-1]["after_reply"] = windows[-1].get("after_reply", 0) + time.perf_counter_ns() - tic
            replied[0] = False
            cur.setdefault("first", tic)
            try:
                return fn(*a, **k)
            finally:
                cur[stage] += time.perf_counter_ns() - tic
        return wrapper

    def timed_send(fn: Callable) -> Callable:
        async def wrapper(self: Any, data: bytes) -> None:
            tic = time.perf_counter_ns()
            await fn(self, data)
            toc = time.perf_counter_ns()
            cur["write"] += toc - tic
            if "engine" in cur:  # the RESULT of a window: the window is over
                windows.append({**cur, "server_busy": toc - cur.pop("first")})
                cur.clear()
                replied[0] = True
        return wrapper

    framing.FrameDecoder.feed = timed("decode", framing.FrameDecoder.feed)
    transports.decode_frame = timed("decode", transports.decode_frame)
    session.SphSession.receive = timed("validate", session.SphSession.receive)
    doors._solve = timed("engine", doors._solve)
    session.SphSession.result = timed("encode", session.SphSession.result)
    doors._result = timed("encode", doors._result)
    doors._gauge_values = timed("record", doors._gauge_values)
    doors._progress = timed("record", doors._progress)
    store.GaugeWriter.row = timed("record", store.GaugeWriter.row)
    transports.TcpDoor.send = timed_send(transports.TcpDoor.send)
    transports.WebSocketDoor.send = timed_send(transports.WebSocketDoor.send)
    return windows


def event_loop(loop: str) -> str:
    """The event loop uvicorn runs for ``loop`` ("auto": uvloop where it is installed)."""
    if loop != "auto":
        return loop
    try:
        import uvloop  # noqa: F401
        return "uvloop"
    except ImportError:
        return "asyncio"


def serve(tmp: Path, null_nodes: int, ports: Any, solves: Any, profile: bool = False,
          loop: str = "auto") -> None:
    """Child process: the server, so client and server do not share one GIL."""
    global _SOLVES, _PROFILE
    _SOLVES = solves
    if profile:
        _PROFILE = install_profile()
    factory: Callable = (TimedFlumeEngine if not null_nodes
                         else lambda req, d: NullEngine(null_nodes, req.scene.t_end))
    settings = Settings(runs_dir=tmp, port=0, tcp_port=0)
    app = create_app(settings, factory)
    config = uvicorn_config(app, settings, log_level="error")  # as `wavesph serve`
    config.loop = event_loop(loop)
    server = uvicorn.Server(config)
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    while not server.started:
        time.sleep(0.01)
    ports.put((server.servers[0].sockets[0].getsockname()[1], app.state.tcp_port))
    thread.join()


# --------------------------------------------------------------------------- client side
def connect(door: str, port: int, tcp_port: int, run_id: str) -> tuple[Callable, Callable, Callable]:
    """send(*frames), recv() -> (seq, msg), close() over the chosen door (TCP_NODELAY on TCP)."""
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
        return send, recv, sock.close
    ws = ws_connect(f"ws://127.0.0.1:{port}/runs/{run_id}/couple", max_size=None).__enter__()

    def send_ws(*frames: bytes) -> None:
        for f in frames:
            ws.send(f)
    return send_ws, lambda: decode_frame(ws.recv()), ws.close


def _load() -> float:
    return round(os.getloadavg()[0], 2)


def _ms(a: np.ndarray, q: float) -> float:
    return round(1e3 * float(np.percentile(a, q)), 3)


def coupled(door: str, body: dict, windows: int, null_nodes: int = 0, case: str = "",
            profile: bool = False, loop: str = "auto") -> dict:
    load0 = _load()
    ctx = multiprocessing.get_context("spawn")  # the parent has OpenMP threads: no fork
    ports, solves = ctx.Queue(), ctx.Queue()
    with tempfile.TemporaryDirectory() as tmp:
        child = ctx.Process(target=serve, args=(Path(tmp), null_nodes, ports, solves, profile, loop),
                            daemon=True)
        child.start()
        try:
            port, tcp_port = ports.get(timeout=120)
            base = f"http://127.0.0.1:{port}"
            r = httpx.post(f"{base}/runs", json=body, timeout=60)
            if r.status_code != 201:
                raise RuntimeError(f"POST /runs: {r.status_code} {r.text}")
            run_id = r.json()["id"]
            deadline = time.monotonic() + 120
            while httpx.get(f"{base}/runs/{run_id}").json()["state"] != "waiting_for_client":
                if time.monotonic() > deadline:
                    raise RuntimeError("the run did not start")
                time.sleep(0.05)
            send, recv, close = connect(door, port, tcp_port, run_id)
            cs = ClientSession()
            send(cs.request(Hello(0, bytes(32), run_id, "bench")))
            welcome = cs.reply(*recv(), expect=Welcome)
            send(cs.request(GetNodes()))
            nodes = cs.reply(*recv(), expect=Nodes)
            wave = AiryWave(H, T, welcome.depth)
            client_s, steps, t = [], [], 0.0
            for _ in range(windows):
                u, w, eta = wave_at(wave, nodes, t + WINDOW)  # model time: outside the clock
                tic = time.perf_counter()
                send(cs.request(Set(t, t + WINDOW, u, w, eta)), cs.request(Solve()))
                res = cs.reply(*recv(), expect=Result)
                client_s.append(time.perf_counter() - tic)
                steps.append(res.steps)
                t += WINDOW
            send(cs.request(Bye("")))
            cs.reply(*recv(), expect=Bye)
            close()
            solve_s, stages = solves.get(timeout=60)
            info = httpx.get(f"{base}/runs/{run_id}").json()
        finally:
            child.terminate()
            child.join(timeout=10)
    c, s = np.array(client_s[1:]), np.array(solve_s[1:windows])
    rtt = c - s
    share = float(rtt.sum() / c.sum())
    out = {"question": QUESTION, "transport": "websocket" if door == "ws" else "tcp",
           "case": "null engine (no SPH work)" if null_nodes else case, "loop": event_loop(loop),
           "nodes": int(welcome.n_nodes), "substeps_per_window": int(np.median(steps)),
           "windows_timed": int(c.size), "rtt_p50_ms": _ms(rtt, 50), "rtt_p99_ms": _ms(rtt, 99)}
    if null_nodes:
        out["set_frame_bytes"] = 16 + 16 + 3 * (4 + 8 * int(welcome.n_nodes))
        out["windows_per_s"] = round(float(c.size / c.sum()), 1)
        if stages:
            out["profile"] = _stage_table(stages[1:windows], rtt)
        out["load"] = [load0, _load()]
        return out
    particles = info["particles"]
    out.update({"overhead_share": round(share, 4), "goal_share": GOAL_SHARE,
                "meets_goal": bool(share <= GOAL_SHARE and np.median(steps) >= 10),
                "solve_ms_per_window": round(1e3 * float(s.mean()), 2),
                "client_ms_per_window": round(1e3 * float(c.mean()), 2), "particles": particles,
                "particle_steps_per_s": round(particles * sum(steps[1:]) / float(s.sum())),
                "server_overhead_share": round(info["coupling_overhead_share"], 4),
                "status": info["status"], "load": [load0, _load()]})
    return out


def _stage_table(stages: list[dict[str, int]], rtt: np.ndarray) -> dict[str, dict[str, float]]:
    """p50, p99 and mean [us] of each server stage per window, and of what lies outside it."""
    def row(a: np.ndarray) -> dict[str, float]:
        return {"p50_us": round(float(np.percentile(a, 50)), 1),
                "p99_us": round(float(np.percentile(a, 99)), 1), "mean_us": round(float(a.mean()), 1)}

    names = ["decode", "validate", "engine", "record", "encode", "write", "server_busy", "after_reply"]
    table = {name: row(1e-3 * np.array([w.get(name, 0) for w in stages], dtype=float))
             for name in names}
    busy = 1e-3 * np.array([w["server_busy"] for w in stages], dtype=float)
    n = min(busy.size, rtt.size)
    table["outside_server"] = row(1e6 * rtt[:n] - busy[:n])
    return table


# --------------------------------------------------------------------------- echo floor
def _echo_tcp(ports: Any, request_bytes: int, reply: bytes, loop: str) -> None:
    """Child process: asyncio streams answering each request of ``request_bytes`` with ``reply``."""
    import asyncio

    async def handle(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        writer.get_extra_info("socket").setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        try:
            while True:
                await reader.readexactly(request_bytes)
                writer.write(reply)
                await writer.drain()
        except (asyncio.IncompleteReadError, ConnectionError):
            writer.close()

    async def main() -> None:
        srv = await asyncio.start_server(handle, "127.0.0.1", 0)
        ports.put(srv.sockets[0].getsockname()[1])
        await srv.serve_forever()

    if event_loop(loop) == "uvloop":
        import uvloop

        uvloop.run(main())
    else:
        asyncio.run(main())


def _echo_ws(ports: Any, reply: bytes, loop: str) -> None:
    """Child process: a Starlette WebSocket endpoint under the server's uvicorn configuration,
    answering each pair of binary messages (SET, SOLVE) with ``reply``."""
    from starlette.applications import Starlette
    from starlette.routing import WebSocketRoute

    async def echo(ws: Any) -> None:
        await ws.accept()
        while True:
            message = await ws.receive()
            if message["type"] == "websocket.disconnect":
                return
            message = await ws.receive()
            if message["type"] == "websocket.disconnect":
                return
            await ws.send_bytes(reply)

    app = Starlette(routes=[WebSocketRoute("/echo", echo)])
    config = uvicorn_config(app, Settings(port=0), log_level="error")
    config.loop = event_loop(loop)
    server = uvicorn.Server(config)
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    while not server.started:
        time.sleep(0.01)
    ports.put(server.servers[0].sockets[0].getsockname()[1])
    thread.join()


def echo_floor(door: str, windows: int, n_nodes: int = 64, n_gauges: int = 2,
               loop: str = "auto") -> dict:
    """The round trip of the same request (SET + SOLVE frames) and reply (a RESULT frame) sizes
    through a server that only answers: what the transport and asyncio cost by themselves."""
    load0 = _load()
    set_bytes = 16 + 16 + 3 * (4 + 8 * n_nodes)
    request = [bytes(set_bytes), bytes(16)]
    reply = bytes(16 + 8 + 4 + 4 * (4 + 8 * n_gauges) - 4 * n_gauges)
    ctx = multiprocessing.get_context("spawn")
    ports = ctx.Queue()
    target, args = ((_echo_tcp, (ports, set_bytes + 16, reply, loop)) if door == "tcp"
                    else (_echo_ws, (ports, reply, loop)))
    child = ctx.Process(target=target, args=args, daemon=True)
    child.start()
    try:
        port = ports.get(timeout=120)
        rtt = []
        if door == "tcp":
            sock = socket.create_connection(("127.0.0.1", port))
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            for _ in range(windows):
                tic = time.perf_counter()
                sock.sendall(b"".join(request))
                got = 0
                while got < len(reply):
                    got += len(sock.recv(1 << 20))
                rtt.append(time.perf_counter() - tic)
            sock.close()
        else:
            ws = ws_connect(f"ws://127.0.0.1:{port}/echo", max_size=None, compression=None).__enter__()
            for _ in range(windows):
                tic = time.perf_counter()
                for f in request:
                    ws.send(f)
                ws.recv()
                rtt.append(time.perf_counter() - tic)
            ws.close()
    finally:
        child.terminate()
        child.join(timeout=10)
    a = np.array(rtt[1:])
    return {"question": QUESTION, "transport": "websocket" if door == "ws" else "tcp",
            "case": "asyncio echo floor (same sizes, no protocol work)", "loop": event_loop(loop),
            "nodes": n_nodes,
            "windows_timed": int(a.size), "rtt_p50_ms": _ms(a, 50), "rtt_p99_ms": _ms(a, 99),
            "load": [load0, _load()]}


def in_process(body: dict, windows: int, case: str) -> dict:
    """The same flume and data without a server: the particle-steps/s baseline."""
    engine = FlumeEngine(RunRequest.model_validate(body), None)
    n = engine.nodes()
    nodes = Nodes(n.x, n.z, n.side, n.gauge_x)
    wave = AiryWave(H, T, engine.summary.depth)
    t, solve, steps = 0.0, [], []
    for _ in range(windows):
        engine.set_window(t, t + WINDOW, *wave_at(wave, nodes, t + WINDOW))
        tic = time.perf_counter()
        steps.append(engine.solve_window().steps)
        solve.append(time.perf_counter() - tic)
        t += WINDOW
    engine.close()
    return {"question": QUESTION, "transport": "in-process (no server)", "case": case,
            "nodes": int(n.x.size), "substeps_per_window": int(np.median(steps)),
            "windows_timed": windows - 1, "particles": engine.n_particles,
            "particle_steps_per_s": round(engine.n_particles * sum(steps[1:]) / sum(solve[1:])),
            "solve_ms_per_window": round(1e3 * float(np.mean(solve[1:])), 2)}


NULL_SCENE = {"dp": 0.05, "t_end": 1.0e4, "still_water_level": DEPTH,
              "tank": {"x0": 0.0, "x1": 1.0, "z0": 0.0, "z1": 0.5},
              "water_blocks": [{"x0": 0.0, "x1": 1.0, "z0": 0.0, "z1": DEPTH}],
              "open_boundaries": [{"side": "left"}]}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--windows", type=int, default=40, help="windows of the beach-flume runs")
    ap.add_argument("--small-windows", type=int, default=150, help="windows of the small-flume runs")
    ap.add_argument("--null-windows", type=int, default=500, help="windows of the null-engine runs")
    ap.add_argument("--only", choices=["all", "null"], default="all",
                    help="null: only the null-engine runs and the echo floor (no SPH)")
    ap.add_argument("--profile", action="store_true",
                    help="time the server's stages per window in the null-engine runs")
    ap.add_argument("--loop", choices=["auto", "asyncio", "uvloop"], default="auto",
                    help="the servers' event loop (auto, as `wavesph serve`: uvloop if installed)")
    ap.add_argument("--nodes", type=int, nargs="+", default=[64, 4096],
                    help="boundary nodes of the null-engine runs")
    args = ap.parse_args()
    cases = [("beach flume, dp 0.01 m, inlet only", beach_flume(), args.windows),
             ("small flume, dp 0.03 m, both ends open", flume(0.03, 4.0), args.small_windows)]
    for case, scene, windows in cases if args.only == "all" else []:
        body = {"scene": scene, "mode": "coupled", "coupling": {"window_max": WINDOW}}
        print(json.dumps(in_process(body, windows, case)), flush=True)  # also warms numba's cache
        for door in ("ws", "tcp"):
            print(json.dumps(coupled(door, body, windows, case=case)), flush=True)
    null_body = {"scene": NULL_SCENE, "mode": "coupled", "coupling": {"window_max": WINDOW}}
    for door in ("ws", "tcp"):
        print(json.dumps(echo_floor(door, args.null_windows, loop=args.loop)), flush=True)
    for n_nodes in args.nodes:
        for door in ("ws", "tcp"):
            print(json.dumps(coupled(door, null_body, args.null_windows, null_nodes=n_nodes,
                                     profile=args.profile, loop=args.loop)), flush=True)


if __name__ == "__main__":
    main()
