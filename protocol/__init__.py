"""wavesph coupling protocol: the wire format, sans-I/O (bytes in, messages out; no sockets).

The byte-level specification is ``protocol/PROTOCOL.md``; this package implements it exactly.
Public API (stable -- wave_client and server depend on it):

Messages (``protocol.messages``): dataclasses with ``serialize() -> payload bytes`` and
``Cls.parse(payload) -> message``:
    Hello, Welcome, GetNodes, Nodes, Set, Solve, Get, Result, GoBack, Error, Bye
Framing (``protocol.framing``):
    encode_frame(msg, seq) -> bytes            one frame (header + payload)
    decode_frame(data, max_payload) -> (seq, msg)   exactly one frame (a WebSocket message)
    FrameDecoder(max_payload).feed(data) -> [(seq, msg), ...]   TCP stream; .eof() at close
Sessions:
    ClientSession (``protocol.client``): .request(msg) -> bytes, .reply(seq, msg, expect=Cls)
        numbers frames and checks replies; an ERROR frame raises RemoteError.
    SphSession (``protocol.session``): the SPH side's state machine shared by the server doors.
Constants (``protocol.wire``): MAGIC, VERSION, HEADER_SIZE, MAX_PAYLOAD, MAX_TEXT, MAX_COUNT,
    NO_SCENE_HASH, MessageType, Capability, Side.
Errors (``protocol.errors``): ProtocolError(code, text) -- the only exception raised on bad
    bytes or order; ErrorCode is the numeric table of the spec.
Scene hash: ``scene_hash(scene_json_bytes)`` = SHA-256 of the canonical scene JSON.
"""

from __future__ import annotations

import hashlib

from .client import ClientSession, RemoteError
from .errors import ErrorCode, ProtocolError
from .framing import FrameDecoder, decode_frame, encode_frame
from .messages import (Bye, Error, Gauges, Get, GetGauges, GetNodes, GoBack, Hello, Message, Nodes,
                       Result, Set, Solve, Welcome, Working)
from .session import SphSession
from .wire import (HEADER_SIZE, MAGIC, MAX_COUNT, MAX_PAYLOAD, MAX_TEXT, NO_SCENE_HASH, VERSION,
                   NO_GAUGE, Capability, GaugeKind, MessageType, Side)


def scene_hash(canonical_scene: bytes) -> bytes:
    """SHA-256 of the canonical scene bytes (the server publishes them with each run)."""
    return hashlib.sha256(canonical_scene).digest()


__all__ = [
    "Bye", "Capability", "ClientSession", "Error", "ErrorCode", "FrameDecoder", "GaugeKind", "Gauges",
    "Get", "GetGauges", "GetNodes", "NO_GAUGE",
    "GoBack", "HEADER_SIZE", "Hello", "MAGIC", "MAX_COUNT", "MAX_PAYLOAD", "MAX_TEXT", "Message",
    "MessageType", "NO_SCENE_HASH", "Nodes", "ProtocolError", "RemoteError", "Result", "Set", "Side",
    "Solve", "SphSession", "VERSION", "Welcome", "Working", "decode_frame", "encode_frame", "scene_hash",
]
