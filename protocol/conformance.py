"""Conformance kit: a scripted peer that checks another implementation of PROTOCOL.md.

Against a server (any language)::

    python -m protocol.conformance ws://HOST:PORT/runs/RUN_ID/couple
    python -m protocol.conformance tcp://HOST:PORT --run-id RUN_ID [--error-run-id RUN2]

Against a client: ``python -m protocol.conformance --serve PORT [--ws]`` plays a scripted server
on TCP, or WebSocket at ws://HOST:PORT/runs/ANY_ID/couple (PORT 0: any free port, printed first
as ``listening on PORT``), for three connections in turn; point the client at it (any run id)
three times: the run, then a RESULT with a wrong seq, then an ERROR (``--sessions 1``: the run
only).

One line per check (``PASS``, ``FAIL`` or ``SKIP``, its name, what was seen); exit code 0 only
if no check failed. Server checks: frames before HELLO answered with the right ERROR code
(MALFORMED, UNSUPPORTED_VERSION, UNKNOWN_TYPE, OUT_OF_ORDER) on fresh connections that name no
run, the handshake and version negotiation, GETNODES, GETGAUGES (1.1), a few still-water
windows, GET, GOBACK exactness (the redone window bit-identical), BYE. ``--error-run-id`` names
a second run that the kit spends on an out-of-order SOLVE inside a session (answered ERROR
OUT_OF_ORDER with the SOLVE's seq; that run ends failed). The first run ends ``finished``.
Client checks: HELLO first, frames numbered 1, 2, 3, ..., windows contiguous with N finite values
each, BYE at the end (a SET before GETNODES is a NOTE); a client that asks for KEEPALIVE (1.1)
gets WORKING frames before WELCOME and before the first RESULT, and must wait through them; it
must refuse a RESULT with a wrong seq (ERROR or close) and send nothing after an ERROR.
The server checks ask for KEEPALIVE too and check every WORKING frame's seq and elapsed.

Imports only ``protocol`` (and the websockets package for ws://).
"""

from __future__ import annotations

import argparse
import math
import socket
import sys
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from .errors import ErrorCode, ProtocolError
from .framing import FrameDecoder, decode_frame, encode_frame
from .messages import (Bye, Error, Gauges, Get, GetGauges, GetNodes, GoBack, Hello, Message, Nodes,
                       Result, Set, Solve, Welcome, Working)
from .session import TIME_RTOL, Reply, Restore, SetWindow, SolveWindow, SphSession, Measure, PeerError
from .wire import HEADER, MAGIC, NO_GAUGE, NO_SCENE_HASH, Capability, GaugeKind

TIMEOUT = 120.0  # [s] per reply: the first RESULT of a server may wait for its JIT compile


@dataclass
class Report:
    """Check results in the order run; ``ok`` is False if any failed."""

    lines: list[tuple[str, str, str]] = field(default_factory=list)
    echo: bool = True

    def add(self, verdict: str, name: str, detail: str = "") -> None:
        self.lines.append((verdict, name, detail))
        if self.echo:
            print(f"{verdict} {name}" + (f" -- {detail}" if detail else ""), flush=True)

    def check(self, name: str, ok: bool, detail: str = "") -> bool:
        self.add("PASS" if ok else "FAIL", name, detail)
        return ok

    @property
    def ok(self) -> bool:
        return all(v != "FAIL" for v, _, _ in self.lines)

    def failed(self) -> list[str]:
        return [n for v, n, _ in self.lines if v == "FAIL"]


# --------------------------------------------------------------------------- connections
class _Conn:
    """One connection: ``send(bytes)``, ``recv()`` -> (seq, message) or None when closed."""

    def __init__(self, url: str, timeout: float) -> None:
        self.timeout = timeout
        if url.startswith("tcp://"):
            host, _, port = url[6:].rstrip("/").rpartition(":")
            self.sock = socket.create_connection((host.strip("[]"), int(port)), timeout=timeout)
            self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            self.decoder, self.pending, self.ws = FrameDecoder(), [], None
        elif url.startswith(("ws://", "wss://")):
            from websockets.sync.client import connect  # third party, only for ws://

            self.ws = connect(url, max_size=None, open_timeout=timeout).__enter__()
        else:
            raise ValueError(f"{url}: expected tcp://HOST:PORT or ws://HOST:PORT/runs/ID/couple")

    def send(self, data: bytes) -> None:
        if self.ws is not None:
            self.ws.send(data)
        else:
            self.sock.sendall(data)

    def recv(self) -> tuple[int, Message] | None:
        if self.ws is not None:
            from websockets.exceptions import ConnectionClosed

            try:
                return decode_frame(self.ws.recv(timeout=self.timeout))
            except ConnectionClosed:
                return None
        while not self.pending:
            try:
                data = self.sock.recv(1 << 16)
            except ConnectionResetError:
                return None
            if not data:
                return None
            self.pending.extend(self.decoder.feed(data))
        return self.pending.pop(0)

    def closed_after(self) -> bool:
        """The peer closes (or sends nothing more) after its last frame."""
        try:
            return self.recv() is None
        except (TimeoutError, OSError):
            return False

    def close(self) -> None:
        try:
            (self.ws or self.sock).close()
        except OSError:
            pass


def _raw_header(version: int, mtype: int, seq: int, length: int) -> bytes:
    return HEADER.pack(MAGIC, version, mtype, seq, length)


# --------------------------------------------------------------------------- against a server
PRE_HELLO_CASES: list[tuple[str, Callable[[], bytes], ErrorCode]] = [
    ("malformed frame -> MALFORMED", lambda: b"XSPH" + bytes(12), ErrorCode.MALFORMED),
    ("header version 2 -> UNSUPPORTED_VERSION", lambda: _raw_header(2, 3, 1, 0),
     ErrorCode.UNSUPPORTED_VERSION),
    ("message type 99 -> UNKNOWN_TYPE", lambda: _raw_header(1, 99, 1, 0), ErrorCode.UNKNOWN_TYPE),
    ("GETNODES before HELLO -> OUT_OF_ORDER", lambda: encode_frame(GetNodes(), 1),
     ErrorCode.OUT_OF_ORDER),
]


def check_server(url: str, run_id: str = "", error_run_id: str | None = None, windows: int = 3,
                 timeout: float = TIMEOUT, report: Report | None = None) -> Report:
    """Run every server check against ``url``; the run ``run_id`` ends finished."""
    rep = report or Report()
    ws = not url.startswith("tcp://")
    for name, frame, code in PRE_HELLO_CASES:
        _expect_error(rep, name, url, frame(), code, 1 if code == ErrorCode.OUT_OF_ORDER else None,
                      timeout)
    try:
        conn = _Conn(url, timeout)
    except OSError as exc:
        rep.check("handshake: HELLO -> WELCOME", False, f"cannot connect: {exc}")
        return rep
    seq = 0
    working: list[str] = []  # WORKING frames seen (1.1 KEEPALIVE), and what was wrong with them
    bad_working: list[str] = []

    def ask(msg: Message) -> tuple[int, Message] | None:
        """The reply to ``msg``; WORKING frames for it (before WELCOME too) are checked, skipped."""
        nonlocal seq
        seq += 1
        conn.send(encode_frame(msg, seq))
        last = -math.inf
        while True:
            got = conn.recv()
            if got is None or not isinstance(got[1], Working):
                return got
            elapsed = got[1].elapsed
            working.append(f"{msg.TYPE.name}: {elapsed:.3g} s")
            if got[0] != seq or not (math.isfinite(elapsed) and elapsed >= max(last, 0.0)):
                bad_working.append(f"seq {got[0]} for request {seq}, elapsed {elapsed!r}")
            last = elapsed

    try:
        want = int(Capability.GOBACK | Capability.GAUGE_INFO | Capability.KEEPALIVE
                   | Capability.ZONE_NODES)
        got = ask(Hello(want, NO_SCENE_HASH, "" if ws and not run_id else run_id, "protocol.conformance"))
        if not rep.check("handshake: HELLO -> WELCOME", got is not None and isinstance(got[1], Welcome)
                         and got[0] == 1, _seen(got)):
            return rep
        w: Welcome = got[1]  # type: ignore[assignment]
        rep.check("handshake: WELCOME fields", w.n_nodes > 0 and w.window_max > 0
                  and w.t_end > w.t_start and math.isfinite(w.g) and w.depth > 0 and w.z_ref <= 0,
                  f"N={w.n_nodes} G={w.n_gauges} t=[{w.t_start}, {w.t_end}] window_max={w.window_max}")
        rep.check("version negotiation: capabilities granted within those asked",
                  w.capabilities & ~want == 0, f"asked {want}, granted {w.capabilities}")
        got = ask(GetNodes())
        ok = got is not None and isinstance(got[1], Nodes) and got[0] == seq
        n: Nodes | None = got[1] if ok else None  # type: ignore[assignment]
        sides = {0, 1, 2, 3} if w.capabilities & Capability.ZONE_NODES else {0, 1}
        rep.check("GETNODES -> NODES of N nodes and G gauges", n is not None
                  and n.x.size == w.n_nodes and n.gauge_x.size == w.n_gauges
                  and bool(np.all(np.isfinite(n.z))) and set(np.unique(n.side).tolist()) <= sides,
                  _seen(got))
        if n is not None and w.capabilities & Capability.ZONE_NODES:
            face = n.side <= 1
            k = int(face.sum())
            rep.check("NODES with ZONE_NODES (1.2): the faces' nodes first, then zone columns on "
                      "their face's levels", bool(np.all(face[:k]) and not np.any(face[k:]))
                      and all(np.array_equal(n.z[(n.side == s) & (n.x == x)], n.z[n.side == s - 2])
                              for s in (2, 3) for x in np.unique(n.x[n.side == s])),
                      f"sides {n.side.tolist()[:8]}...")
        if w.capabilities & Capability.GAUGE_INFO:
            got = ask(GetGauges())
            g = got[1] if got is not None and isinstance(got[1], Gauges) else None
            rep.check("GETGAUGES -> GAUGES (1.1)", g is not None and got[0] == seq
                      and len(g.names) == w.n_gauges == g.kind.size
                      and len(set(g.names)) == len(g.names)
                      and set(g.kind.tolist()) <= {int(GaugeKind.BOUNDARY), int(GaugeKind.PROBE)}
                      and g.eta_gauge.size == 2
                      and all(e == NO_GAUGE or e < w.n_gauges for e in g.eta_gauge.tolist()),
                      _seen(got) if g is None else f"names {g.names}, eta_gauge {g.eta_gauge.tolist()}")
        else:
            rep.add("SKIP", "GETGAUGES -> GAUGES (1.1)", "GAUGE_INFO not granted (a 1.0 server)")
        window = min(w.window_max, (w.t_end - w.t_start) / (windows + 2))
        still = np.zeros(w.n_nodes)
        t, last, ok = w.t_start, None, True
        for k in range(windows):
            seq += 1
            conn.send(encode_frame(Set(t, t + window, still, still, still), seq))
            got = ask(Solve())
            r = got[1] if got is not None and isinstance(got[1], Result) else None
            ok = (r is not None and got[0] == seq and _same_t(r.t, t + window) and r.steps >= 1
                  and r.eta.size == r.wet.size == r.u_ref.size == r.w_ref.size == w.n_gauges
                  and bool(np.all(np.isfinite(r.eta))))
            if not ok:
                rep.check("windows: SET + SOLVE -> RESULT at t1", False, f"window {k + 1}: {_seen(got)}")
                return rep
            last, t = r, t + window
        rep.check("windows: SET + SOLVE -> RESULT at t1", ok, f"{windows} still-water windows of "
                  f"{window:g} s, last RESULT t={last.t:g} steps={last.steps}")
        got = ask(Get())
        rep.check("GET -> RESULT now, steps 0", got is not None and isinstance(got[1], Result)
                  and got[0] == seq and got[1].steps == 0 and _same_t(got[1].t, t), _seen(got))
        if w.capabilities & Capability.GOBACK:
            got = ask(GoBack())
            back = got is not None and isinstance(got[1], Result) and _same_t(got[1].t, t - window)
            seq += 1
            conn.send(encode_frame(Set(t - window, t, still, still, still), seq))
            again = ask(Solve())
            r = again[1] if again is not None and isinstance(again[1], Result) else None
            same = (r is not None and last is not None and r.steps == last.steps
                    and all(np.array_equal(getattr(r, a), getattr(last, a))
                            for a in ("eta", "wet", "u_ref", "w_ref")))
            rep.check("GOBACK -> RESULT at t0; the redone window bit-identical", back and same,
                      f"GOBACK: {_seen(got)}; redo: {_seen(again)}")
        else:
            rep.add("SKIP", "GOBACK exactness", "GOBACK not granted")
        got = ask(Bye("conformance done"))
        rep.check("BYE -> BYE with the same seq, then close", got is not None
                  and isinstance(got[1], Bye) and got[0] == seq and conn.closed_after(), _seen(got))
        if w.capabilities & Capability.KEEPALIVE:
            rep.check("KEEPALIVE (1.1): WORKING only with the pending request's seq, elapsed growing",
                      not bad_working, "; ".join(bad_working[:3]) or
                      f"{len(working)} WORKING frames" + (f" ({', '.join(working[:3])})" if working else ""))
        else:
            rep.check("no WORKING without KEEPALIVE granted", not working, "; ".join(working[:3])
                      or "KEEPALIVE not granted (a 1.0 server)")
    except (OSError, TimeoutError, ProtocolError) as exc:
        rep.check("session", False, f"{type(exc).__name__}: {exc}")
    finally:
        conn.close()
    if error_run_id is not None:
        _out_of_order_in_session(rep, url if ws else url, error_run_id, timeout)
    else:
        rep.add("SKIP", "SOLVE without SET in a session -> OUT_OF_ORDER", "needs --error-run-id")
    return rep


def _out_of_order_in_session(rep: Report, url: str, run_id: str, timeout: float) -> None:
    name = "SOLVE without SET in a session -> OUT_OF_ORDER with the SOLVE's seq"
    if not url.startswith("tcp://"):
        url = url.rsplit("/runs/", 1)[0] + f"/runs/{run_id}/couple"
    conn = _Conn(url, timeout)
    try:
        conn.send(encode_frame(Hello(0, NO_SCENE_HASH, run_id, "protocol.conformance"), 1))
        got = conn.recv()
        if got is None or not isinstance(got[1], Welcome):
            rep.check(name, False, f"HELLO: {_seen(got)}")
            return
        conn.send(encode_frame(Solve(), 2))
        got = conn.recv()
        rep.check(name, got is not None and isinstance(got[1], Error)
                  and got[1].code == ErrorCode.OUT_OF_ORDER and got[0] == 2 and conn.closed_after(),
                  _seen(got))
    except (OSError, TimeoutError, ProtocolError) as exc:
        rep.check(name, False, f"{type(exc).__name__}: {exc}")
    finally:
        conn.close()


def _expect_error(rep: Report, name: str, url: str, frame: bytes, code: ErrorCode,
                  seq: int | None, timeout: float) -> None:
    try:
        conn = _Conn(url, timeout)
    except OSError as exc:
        rep.check(name, False, f"cannot connect: {exc}")
        return
    try:
        conn.send(frame)
        got = conn.recv()
        ok = (got is not None and isinstance(got[1], Error) and got[1].code == code
              and (seq is None or got[0] == seq))
        rep.check(name, ok and conn.closed_after(), _seen(got))
    except (OSError, TimeoutError, ProtocolError) as exc:
        rep.check(name, False, f"{type(exc).__name__}: {exc}")
    finally:
        conn.close()


def _same_t(a: float, b: float) -> bool:
    return abs(a - b) <= TIME_RTOL * max(1.0, abs(b))


def _seen(got: tuple[int, Message] | None) -> str:
    if got is None:
        return "connection closed"
    seq, msg = got
    if isinstance(msg, Error):
        return f"ERROR {ErrorCode(msg.code).name if msg.code in ErrorCode._value2member_map_ else msg.code} seq={seq}: {msg.text[:120]}"
    return f"{msg.TYPE.name} seq={seq}"


# --------------------------------------------------------------------------- against a client
FAULT_GRACE = 10.0  # [s] a client has to refuse a faulty reply (ERROR or close) or to stop after an ERROR
NAME_SEQ = "message order and seq 1, 2, 3, ..."
NAME_NODES = "GETNODES before the first SET"
NAME_WRONG_SEQ = "a RESULT with a wrong seq is refused (ERROR or close, nothing more)"
NAME_ERROR = "an ERROR from the server ends the session (the client sends nothing more)"
# the sessions a client is checked with: (fault, what the client is told to expect)
SESSIONS: list[tuple[str | None, str]] = [
    (None, "the scripted run (WORKING frames on the way, if KEEPALIVE is asked for)"),
    ("wrong_seq", "the first RESULT carries a wrong seq: the client must refuse it"),
    ("error", "the first SOLVE is answered ERROR ENGINE_FAILED: the client must stop"),
]


def scripted_scene(t_end: float = 0.2, window_max: float = 0.05,
                   run_id: str = "conformance") -> tuple[Welcome, Nodes, Gauges]:
    """The scripted server's run: one inlet column of 8 nodes, two gauges, depth 0.3 m."""
    z = np.linspace(-0.29, 0.1, 8)
    welcome = Welcome(int(Capability.GOBACK | Capability.KEEPALIVE), NO_SCENE_HASH, g=9.81, depth=0.3,
                      still_water_level=0.3, z_ref=-0.15, t_start=0.0, t_end=t_end, dt_sph=1e-3,
                      window_max=window_max, idle_timeout=TIMEOUT, n_nodes=z.size, n_gauges=2,
                      max_payload=0, run_id=run_id, server="protocol.conformance")
    nodes = Nodes(np.zeros(z.size), z, np.zeros(z.size, np.uint32), np.array([0.06, 1.0]))
    gauges = Gauges(["inlet_boundary", "probe_1"], np.array([GaugeKind.BOUNDARY, GaugeKind.PROBE]),
                    np.array([0, NO_GAUGE]))
    return welcome, nodes, gauges


class ClientPeer:
    """The scripted server's side of one client connection, TCP or WebSocket: ``recv(timeout)``
    gives the next (seq, message) or None when the client closed; ``max_payload`` bounds what
    the client may send now."""

    def __init__(self, sock: socket.socket | None = None, ws: object | None = None,
                 run_id: str = "", on_close: Callable[[], None] | None = None) -> None:
        self.sock, self.ws, self.run_id, self.on_close = sock, ws, run_id, on_close
        self.decoder = FrameDecoder(8236)
        self.pending: list[tuple[int, Message]] = []

    @property
    def max_payload(self) -> int:
        return self.decoder.max_payload

    @max_payload.setter
    def max_payload(self, value: int) -> None:
        self.decoder.max_payload = value

    def recv(self, timeout: float) -> tuple[int, Message] | None:
        if self.ws is not None:
            from websockets.exceptions import ConnectionClosed

            try:
                data = self.ws.recv(timeout=timeout)  # type: ignore[attr-defined]
            except ConnectionClosed:
                return None
            if isinstance(data, str):
                raise ProtocolError(ErrorCode.MALFORMED, "a text WebSocket message: frames are binary")
            return decode_frame(data, self.decoder.max_payload)
        assert self.sock is not None
        self.sock.settimeout(timeout)
        while not self.pending:
            try:
                data = self.sock.recv(1 << 16)
            except ConnectionResetError:
                return None
            if not data:
                self.decoder.eof()
                return None
            self.pending.extend(self.decoder.feed(data))
        return self.pending.pop(0)

    def send(self, data: bytes) -> None:
        if self.ws is not None:
            self.ws.send(data)  # type: ignore[attr-defined]
        else:
            assert self.sock is not None
            self.sock.sendall(data)

    def close(self) -> None:
        if self.on_close is not None:
            self.on_close()
        elif self.sock is not None:
            self.sock.close()


def check_client(peer: ClientPeer | socket.socket, report: Report | None = None, t_end: float = 0.2,
                 fault: str | None = None) -> Report:
    """Play the scripted server for one client connection; check the client. ``fault``:
    None (the run to its end), "wrong_seq" (the first RESULT with the SET's seq instead of the
    SOLVE's) or "error" (the first SOLVE answered ERROR ENGINE_FAILED): then only what the
    client does about it is checked (and any violation before it)."""
    rep = report or Report()
    if isinstance(peer, socket.socket):
        peer = ClientPeer(peer)
    welcome = scripted_scene(t_end)[0]
    session: SphSession | None = None  # made at the first frame: it serves any run id
    seen_hello = asked_nodes = False
    windows, t, last_set = 0, welcome.t_start, None
    seqs: list[int] = []
    try:
        while True:
            got = peer.recv(TIMEOUT)
            if got is None:
                if fault is None:
                    rep.check("BYE at the end", False, f"the client closed after {windows} windows "
                              "without BYE")
                    return _client_summary(rep, seen_hello, asked_nodes, windows, seqs)
                rep.check(_fault_name(fault), False, "the client closed before the first RESULT")
                return rep
            seq, msg = got
            seqs.append(seq)
            if not seen_hello:
                seen_hello = rep.check("handshake: HELLO first, version 1", isinstance(msg, Hello),
                                       f"{msg.TYPE.name} seq={seq}")
            if isinstance(msg, Set) and not asked_nodes:
                # the state machine (section 6) lets a client that knows its nodes skip GETNODES
                rep.add("NOTE", NAME_NODES, "SET before GETNODES: the nodes were not asked for")
                asked_nodes = True  # said once
            asked_nodes |= isinstance(msg, GetNodes)
            if session is None:
                run_id = peer.run_id or (msg.run_id if isinstance(msg, Hello) and msg.run_id
                                         else "conformance")
                session = SphSession(*scripted_scene(t_end, run_id=run_id))
            action = session.receive(seq, msg)
            peer.max_payload = session.max_payload
            if isinstance(msg, Hello) or (isinstance(action, SolveWindow) and windows == 0):
                # a client that asked for KEEPALIVE must wait through WORKING before WELCOME (a
                # run being built) and before the first RESULT (the compile); None for 1.0
                for elapsed in (0.0, 0.01):
                    frame = session.working_frame(elapsed)
                    if frame is not None:
                        peer.send(frame)
            if isinstance(action, SolveWindow) and fault is not None:
                return _fault(rep, peer, session, action, seq, fault)
            if isinstance(action, Reply):
                peer.send(action.data)
                if action.close:
                    rep.check("BYE at the end", True, f"after {windows} windows, t = {t:g} s")
                    return _client_summary(rep, seen_hello, asked_nodes, windows, seqs)
            elif isinstance(action, SetWindow):
                last_set = action
            elif isinstance(action, SolveWindow):
                assert last_set is not None
                windows, t = windows + 1, last_set.t1
                peer.send(session.result(action, _scripted_result(10, float(np.mean(last_set.eta)))))
            elif isinstance(action, (Measure, Restore)):
                if isinstance(action, Restore):
                    windows = max(windows - 1, 0)
                peer.send(session.result(action, _scripted_result(0, 0.0)))
            elif isinstance(action, PeerError):
                rep.check("no ERROR from the client", False, f"code {action.code}: {action.text}")
                return _client_summary(rep, seen_hello, asked_nodes, windows, seqs)
    except ProtocolError as exc:
        name = {ErrorCode.OUT_OF_ORDER: NAME_SEQ,
                ErrorCode.SHAPE_MISMATCH: "SET arrays of N values",
                ErrorCode.TIME_MISMATCH: "windows contiguous (SET t0 = server time)",
                ErrorCode.BAD_VALUE: "SET values finite, window within window_max and t_end"}.get(
                    exc.code, "frames well formed")
        rep.check(name, False, f"{exc.code.name}: {exc.text}")
        try:
            if session is not None:
                peer.send(session.error_frame(exc))
        except OSError:
            pass
        return rep if fault else _client_summary(rep, seen_hello, asked_nodes, windows, seqs)
    except (OSError, TimeoutError) as exc:
        rep.check("connection", False, f"{type(exc).__name__}: {exc}")
        return rep if fault else _client_summary(rep, seen_hello, asked_nodes, windows, seqs)


def _scripted_result(steps: int, eta: float) -> Result:
    """The scripted "SPH": the first gauge sees the imposed eta, the second still water."""
    return Result(0.0, steps, np.array([eta, 0.0]), np.ones(2, np.uint32), np.zeros(2), np.zeros(2))


def _fault_name(fault: str) -> str:
    return NAME_WRONG_SEQ if fault == "wrong_seq" else NAME_ERROR


def _fault(rep: Report, peer: ClientPeer, session: SphSession, action: SolveWindow, seq: int,
           fault: str) -> Report:
    """Send the faulty reply to the SOLVE of frame ``seq``; check what the client does next."""
    if fault == "wrong_seq":
        frame = bytearray(session.result(action, _scripted_result(10, 0.0)))
        frame[8:12] = (seq - 1).to_bytes(4, "little")  # the SET's seq: the reply to another frame
        peer.send(bytes(frame))
    else:
        peer.send(session.error_frame(ProtocolError(
            ErrorCode.ENGINE_FAILED, "conformance: a scripted engine failure (the kit's fault test)")))
    name = _fault_name(fault)
    try:
        got = peer.recv(FAULT_GRACE)
    except (TimeoutError, OSError):  # silent: refusing nothing, or waiting for our close
        if fault == "wrong_seq":
            rep.check(name, False, f"neither ERROR nor close within {FAULT_GRACE:g} s")
        else:
            rep.check(name, True, f"silent for {FAULT_GRACE:g} s, waiting for the server to close")
        return rep
    except ProtocolError as exc:
        rep.check(name, False, f"it then sent bytes that are no frame: {exc}")
        return rep
    if got is None:
        rep.check(name, True, "the client closed")
    else:
        refused = fault == "wrong_seq" and isinstance(got[1], Error)
        rep.check(name, refused, ("it sent " if refused else "it went on: ") + _seen(got))
    return rep


def _client_summary(rep: Report, hello: bool, nodes: bool, windows: int, seqs: list[int]) -> Report:
    names = {n for _, n, _ in rep.lines}
    if NAME_SEQ not in names:
        rep.check(NAME_SEQ, seqs == list(range(1, len(seqs) + 1)), f"{len(seqs)} frames")
    if NAME_NODES not in names:
        rep.check(NAME_NODES, nodes)
    rep.check("at least one window solved", windows >= 1, f"{windows} windows")
    if not hello and "handshake: HELLO first, version 1" not in names:
        rep.check("handshake: HELLO first, version 1", False, "no frame")
    return rep


def _run_sessions(next_peer: Callable[[], ClientPeer], t_end: float, sessions: int,
                  report: Report | None = None) -> Report:
    """Check ``sessions`` connections in turn (SESSIONS: the run, then the faults); each
    fault session reports its fault check, and any other check only if it failed."""
    rep = report or Report()
    for k, (fault, what) in enumerate(SESSIONS[:sessions], 1):
        if sessions > 1 and rep.echo:
            print(f"session {k}/{sessions}: {what}", flush=True)
        peer = next_peer()
        try:
            if fault is None:
                check_client(peer, rep, t_end)
                continue
            sub = check_client(peer, Report(echo=False), t_end, fault)
        finally:
            peer.close()
        for verdict, name, detail in sub.lines:
            if verdict == "FAIL" or name == _fault_name(fault):
                rep.add(verdict, name, (detail if name == _fault_name(fault)
                                        else f"(session {k}) {detail}"))
    return rep


def _print_port(port: int) -> None:
    print(f"listening on {port}", flush=True)


def serve_scripted(port: int, t_end: float = 0.2, host: str = "127.0.0.1", ws: bool = False,
                   sessions: int = len(SESSIONS), report: Report | None = None,
                   listening: Callable[[int], None] = _print_port) -> Report:
    """Listen on ``port`` (0: any), tell ``listening`` the port (default: print it), check the
    next ``sessions`` clients that connect (over WebSocket at ws://HOST:PORT/runs/ID/couple if
    ``ws``)."""
    if ws:
        return _serve_ws(port, t_end, host, sessions, report, listening)
    with socket.create_server((host, port)) as srv:
        listening(srv.getsockname()[1])

        def accept() -> ClientPeer:
            sock, _ = srv.accept()
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            return ClientPeer(sock)

        return _run_sessions(accept, t_end, sessions, report)


def _serve_ws(port: int, t_end: float, host: str, sessions: int, report: Report | None,
              listening: Callable[[int], None]) -> Report:
    import queue
    import threading

    from websockets.sync.server import serve

    conns: queue.Queue = queue.Queue()

    def handler(ws: object) -> None:  # one thread per connection, held until the kit is done
        done = threading.Event()
        path = ws.request.path.split("?")[0]  # type: ignore[attr-defined]
        run_id = path.split("/")[2] if path.startswith("/runs/") and path.count("/") >= 3 else "conformance"
        conns.put(ClientPeer(ws=ws, run_id=run_id, on_close=done.set))
        done.wait()

    def subprotocol(_: object, offered: list[str]) -> str | None:
        return "wavesph" if "wavesph" in offered else None  # as our server: optional

    server = serve(handler, host, port, select_subprotocol=subprotocol, max_size=None,
                   compression=None, ping_interval=None)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    listening(server.socket.getsockname()[1])
    try:
        return _run_sessions(lambda: conns.get(timeout=TIMEOUT), t_end, sessions, report)
    finally:
        server.shutdown()
        thread.join(timeout=10)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m protocol.conformance",
                                 description="check a wavesph protocol peer (PROTOCOL.md)")
    ap.add_argument("url", nargs="?", help="server: ws://HOST:PORT/runs/ID/couple or tcp://HOST:PORT")
    ap.add_argument("--run-id", default="", help="the run to couple to (required with tcp://)")
    ap.add_argument("--error-run-id", help="a second run, spent on an in-session OUT_OF_ORDER check")
    ap.add_argument("--windows", type=int, default=3, help="still-water windows to solve")
    ap.add_argument("--timeout", type=float, default=TIMEOUT, help="[s] per reply")
    ap.add_argument("--serve", type=int, metavar="PORT", help="play a scripted server for a client")
    ap.add_argument("--ws", action="store_true", help="with --serve: over WebSocket "
                    "(ws://HOST:PORT/runs/ANY_ID/couple) instead of TCP")
    ap.add_argument("--sessions", type=int, choices=range(1, len(SESSIONS) + 1), default=len(SESSIONS),
                    help="with --serve: connections to check: 1 the run; 2 also a RESULT with a wrong "
                         "seq; 3 (default) also an ERROR")
    ap.add_argument("--t-end", type=float, default=0.2, help="[s] the scripted server's run length")
    args = ap.parse_args(argv)
    if args.serve is not None:
        rep = serve_scripted(args.serve, args.t_end, ws=args.ws, sessions=args.sessions)
    elif args.url:
        if args.url.startswith("tcp://") and not args.run_id:
            ap.error("tcp:// needs --run-id")
        rep = check_server(args.url, args.run_id, args.error_run_id, args.windows, args.timeout)
    else:
        ap.error("give a server URL or --serve PORT")
    print(f"{'ALL PASSED' if rep.ok else 'FAILED: ' + ', '.join(rep.failed())}", flush=True)
    return 0 if rep.ok else 1


if __name__ == "__main__":
    sys.exit(main())
