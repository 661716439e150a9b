"""Sans-I/O session of the SPH side: which message may come when, checked against the handshake.

The server's WebSocket and TCP doors share this one implementation. A door feeds each
received (seq, message) to ``SphSession.receive`` and gets back an action:

- ``Reply(data, close)``: send ``data``; close afterwards if ``close``.
- ``SetWindow``: hand the window to the engine; nothing is sent back.
- ``SolveWindow`` / ``Measure`` / ``Restore``: run the engine, then send ``session.result(...)``.
- ``PeerError``: the client reported an error and is closing.

Any ``ProtocolError`` raised by ``receive`` (or by the framing) is answered with
``session.error_frame(exc)`` and the connection is closed.

States: AWAIT_HELLO -> READY <-> WINDOW_SET -> CLOSED (see PROTOCOL.md, "Session").
"""

from __future__ import annotations

from copy import copy
from dataclasses import dataclass, replace
from enum import Enum

import numpy as np

from .errors import ErrorCode, ProtocolError
from .framing import encode_frame
from .messages import (Bye, Error, Gauges, Get, GetGauges, GetNodes, GoBack, Hello, Message, Nodes,
                       Result, Set, Solve, Welcome, Working)
from .wire import MAX_TEXT, NO_SCENE_HASH, Capability

TIME_RTOL = 1e-9  # relative tolerance when matching window times to the SPH clock
HELLO_LIMIT = 4 + 32 + 2 * (4 + MAX_TEXT)  # largest payload before WELCOME: a HELLO


class State(Enum):
    AWAIT_HELLO = "await_hello"
    READY = "ready"
    WINDOW_SET = "window_set"
    CLOSED = "closed"


@dataclass(frozen=True)
class Reply:
    data: bytes
    close: bool = False


@dataclass(frozen=True)
class SetWindow:
    t0: float
    t1: float
    u: np.ndarray
    w: np.ndarray
    eta: np.ndarray


@dataclass(frozen=True)
class SolveWindow:
    t0: float
    t1: float


@dataclass(frozen=True)
class Measure:
    pass


@dataclass(frozen=True)
class Restore:
    t: float  # the window start the engine returns to


@dataclass(frozen=True)
class PeerError:
    code: int
    text: str


Action = Reply | SetWindow | SolveWindow | Measure | Restore | PeerError


def set_payload_size(n_nodes: int) -> int:
    """Payload bytes of a SET for ``n_nodes`` nodes: the largest frame a client sends."""
    return 2 * 8 + 3 * (4 + 8 * n_nodes)


def _same_time(a: float, b: float) -> bool:
    return abs(a - b) <= TIME_RTOL * max(1.0, abs(a), abs(b))


class SphSession:
    """Protocol state of one coupling connection, SPH side.

    ``welcome`` is the server's offer (capabilities it supports, scene summary); the
    capabilities actually sent are the intersection with the client's, and ``max_payload`` is
    set to the largest frame the client may send for this scene (a SET). ``nodes`` is the reply
    to GETNODES; its lengths must agree with ``welcome``. ``gauges`` (1.1) is the reply to
    GETGAUGES: given, the GAUGE_INFO capability is offered; a 1.0 client does not ask for it and
    is served as before. ``zone_nodes`` (1.2) is the reply to GETNODES when ZONE_NODES is in
    force: ``nodes`` followed by the relaxation zones' columns (sides 2, 3); given, the
    capability is offered, and a client granted it sends SETs of that many nodes.
    """

    def __init__(self, welcome: Welcome, nodes: Nodes, gauges: Gauges | None = None,
                 zone_nodes: Nodes | None = None) -> None:
        if not (nodes.x.size == nodes.z.size == nodes.side.size == welcome.n_nodes
                and nodes.gauge_x.size == welcome.n_gauges):
            raise ValueError("nodes: array lengths disagree with welcome.n_nodes / n_gauges")
        if gauges is not None:
            if not len(gauges.names) == gauges.kind.size == welcome.n_gauges:
                raise ValueError("gauges: names / kind lengths disagree with welcome.n_gauges")
            welcome = replace(welcome, capabilities=welcome.capabilities | Capability.GAUGE_INFO)
        if zone_nodes is not None:
            n_face = nodes.x.size
            if not (zone_nodes.x.size == zone_nodes.z.size == zone_nodes.side.size > n_face
                    and np.array_equal(zone_nodes.x[:n_face], nodes.x)
                    and np.array_equal(zone_nodes.side[:n_face], nodes.side)
                    and np.array_equal(zone_nodes.gauge_x, nodes.gauge_x)):
                raise ValueError("zone_nodes: must be nodes followed by the zones' columns")
            welcome = replace(welcome, capabilities=welcome.capabilities | Capability.ZONE_NODES)
        self.gauges = gauges
        self.zone_nodes = zone_nodes
        # after HELLO the client may send nothing larger than a SET for this scene
        self.client_limit = max(set_payload_size(welcome.n_nodes), 4 + 4 + MAX_TEXT)
        self.offer = replace(welcome, max_payload=self.client_limit)
        self.nodes = nodes
        self.state = State.AWAIT_HELLO
        self.capabilities = 0
        self.t = welcome.t_start            # SPH time as far as the protocol knows
        self.window: tuple[float, float] | None = None  # pending SET window
        self.last_window: tuple[float, float] | None = None  # solved, not yet gone back over
        self.windows_solved = 0
        self._last_seq = 0                  # client frames count from 1
        self._reply_seq = 0                 # seq of the request being answered

    @property
    def max_payload(self) -> int:
        """Largest payload the client may send now: before HELLO only a small one."""
        if self.state is State.AWAIT_HELLO:
            return HELLO_LIMIT
        return self.client_limit

    # -- incoming ---------------------------------------------------------------------------
    def receive(self, seq: int, msg: Message) -> Action:
        """Validate one client frame against the state; the action the door must take."""
        if self.state is State.CLOSED:
            raise ProtocolError(ErrorCode.OUT_OF_ORDER, f"{msg.TYPE.name} after the session closed")
        if seq != self._last_seq + 1:
            raise ProtocolError(ErrorCode.OUT_OF_ORDER,
                                f"{msg.TYPE.name} has seq {seq}, expected {self._last_seq + 1}", seq)
        self._last_seq = self._reply_seq = seq
        if isinstance(msg, Error):
            self.state = State.CLOSED
            return PeerError(msg.code, msg.text)
        if isinstance(msg, Bye):
            self.state = State.CLOSED
            return Reply(self._frame(Bye("bye")), close=True)
        if self.state is State.AWAIT_HELLO:
            if not isinstance(msg, Hello):
                raise ProtocolError(ErrorCode.OUT_OF_ORDER, f"{msg.TYPE.name} before HELLO")
            return self._hello(msg)
        if isinstance(msg, Hello):
            raise ProtocolError(ErrorCode.OUT_OF_ORDER, "a second HELLO: this session is open "
                                                        "already (one HELLO per connection)")
        if isinstance(msg, (GetNodes, GetGauges)) and self.state is State.WINDOW_SET:
            raise ProtocolError(ErrorCode.OUT_OF_ORDER, f"{msg.TYPE.name} after SET: ask between "
                                                        "windows (state READY)")
        if isinstance(msg, GetNodes):
            return Reply(self._frame(self.nodes))
        if isinstance(msg, GetGauges):
            if not self.capabilities & Capability.GAUGE_INFO or self.gauges is None:
                raise ProtocolError(ErrorCode.OUT_OF_ORDER, "GETGAUGES without the GAUGE_INFO "
                                                            "capability (protocol 1.1)")
            return Reply(self._frame(self.gauges))
        if isinstance(msg, Set):
            return self._set(msg)
        if isinstance(msg, Solve):
            if self.state is not State.WINDOW_SET or self.window is None:
                raise ProtocolError(ErrorCode.OUT_OF_ORDER, "SOLVE without a SET for the window")
            return SolveWindow(*self.window)
        if isinstance(msg, Get):
            return Measure()
        if isinstance(msg, GoBack):
            if not self.capabilities & Capability.GOBACK:
                raise ProtocolError(ErrorCode.OUT_OF_ORDER, "GOBACK without the GOBACK capability")
            if self.last_window is None:
                raise ProtocolError(ErrorCode.OUT_OF_ORDER, "GOBACK with no solved window to return over")
            return Restore(self.last_window[0])
        raise ProtocolError(ErrorCode.OUT_OF_ORDER, f"{msg.TYPE.name} is sent by the server only")

    def _hello(self, msg: Hello) -> Reply:
        if msg.run_id and msg.run_id != self.offer.run_id:
            raise ProtocolError(ErrorCode.BAD_VALUE, f"HELLO.run_id {msg.run_id[:64]!r}: this "
                                                     f"connection serves run {self.offer.run_id!r}")
        if msg.scene_hash not in (NO_SCENE_HASH, self.offer.scene_hash):
            raise ProtocolError(ErrorCode.SCENE_MISMATCH,
                                f"client expects scene {msg.scene_hash.hex()[:16]}..., "
                                f"this run has {self.offer.scene_hash.hex()[:16]}...")
        self.capabilities = msg.capabilities & self.offer.capabilities
        if self.capabilities & Capability.ZONE_NODES and self.zone_nodes is not None:
            self.nodes = self.zone_nodes
            self.client_limit = max(set_payload_size(self.nodes.x.size), 4 + 4 + MAX_TEXT)
            self.offer = replace(self.offer, n_nodes=self.nodes.x.size,
                                 max_payload=self.client_limit)
        self.state = State.READY
        return Reply(self._frame(replace(self.offer, capabilities=self.capabilities)))

    def _set(self, msg: Set) -> SetWindow:
        n = self.offer.n_nodes
        for name in ("u", "w", "eta"):
            size = getattr(msg, name).size
            if size != n:
                raise ProtocolError(ErrorCode.SHAPE_MISMATCH,
                                    f"SET.{name} has {size} values, the scene has {n} nodes")
        if not _same_time(msg.t0, self.t):
            raise ProtocolError(ErrorCode.TIME_MISMATCH,
                                f"SET window starts at t0={msg.t0!r} s, SPH is at t={self.t!r} s")
        span = msg.t1 - msg.t0
        if not span > 0:
            raise ProtocolError(ErrorCode.BAD_VALUE, f"SET window [{msg.t0}, {msg.t1}] is empty")
        if span > self.offer.window_max * (1 + TIME_RTOL):
            raise ProtocolError(ErrorCode.BAD_VALUE, f"SET window of {span} s > window_max "
                                                     f"{self.offer.window_max} s")
        if msg.t1 > self.offer.t_end and not _same_time(msg.t1, self.offer.t_end):
            raise ProtocolError(ErrorCode.BAD_VALUE,
                                f"SET.t1={msg.t1} s is after the run's t_end={self.offer.t_end} s")
        self.window = (self.t, msg.t1)  # snap t0 to the clock so rounding never accumulates
        self.state = State.WINDOW_SET
        return SetWindow(self.t, msg.t1, msg.u, msg.w, msg.eta)

    # -- outgoing ---------------------------------------------------------------------------
    def result(self, action: SolveWindow | Measure | Restore, result: Result) -> bytes:
        """The RESULT frame answering ``action``, after the engine did its part."""
        n = self.offer.n_gauges
        for name in ("eta", "wet", "u_ref", "w_ref"):
            if getattr(result, name).size != n:
                raise ProtocolError(ErrorCode.INTERNAL,
                                    f"RESULT.{name} has {getattr(result, name).size} values, {n} gauges")
        if isinstance(action, SolveWindow):
            self.t = action.t1
            self.last_window = (action.t0, action.t1)
            self.window = None
            self.windows_solved += 1
            self.state = State.READY
        elif isinstance(action, Restore):
            self.t = action.t
            self.last_window = None
            self.window = None
            self.state = State.READY
        reply = copy(result)  # t is the session's clock; a shallow copy skips __post_init__
        reply.t = self.t
        return self._frame(reply)

    def working_frame(self, elapsed: float) -> bytes | None:
        """WORKING for the request being answered (1.1), None unless KEEPALIVE is in force."""
        if not self.capabilities & Capability.KEEPALIVE:
            return None
        return self._frame(Working(float(elapsed)))

    def error_frame(self, exc: ProtocolError | Exception) -> bytes:
        """ERROR frame for ``exc`` (the door closes after sending it). It carries the refused
        frame's own seq where its header was read, else that of the last client frame."""
        self.state = State.CLOSED
        seq = self._reply_seq
        if isinstance(exc, ProtocolError):
            code, text = exc.code, exc.text
            seq = seq if exc.seq is None else exc.seq
        else:
            code, text = ErrorCode.INTERNAL, f"{type(exc).__name__}: {exc}"
        return encode_frame(Error(int(code), _clip(text)), seq)

    def _frame(self, msg: Message) -> bytes:
        return encode_frame(msg, self._reply_seq)


def _clip(text: str) -> str:
    data = text.encode("utf-8")[:MAX_TEXT]
    return data.decode("utf-8", errors="ignore")

