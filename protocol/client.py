"""Sans-I/O helper for the wave-model side: numbers outgoing frames, checks every reply.

    cs = ClientSession()
    sock.send(cs.request(Hello(Capability.GOBACK, scene_hash, "my-model")))
    welcome = cs.reply(*decode_frame(ws.recv()), expect=Welcome)

A reply of the wrong type, with the wrong seq, or with lengths that disagree with WELCOME raises
ProtocolError; an ERROR frame from the server raises RemoteError carrying its code and text.
"""

from __future__ import annotations

from typing import TypeVar

from .errors import ErrorCode, ProtocolError
from .framing import encode_frame
from .messages import Bye, Error, Gauges, Message, Nodes, Result, Welcome, Working

M = TypeVar("M", bound=Message)


class RemoteError(ProtocolError):
    """The server sent an ERROR frame (and is closing the connection)."""


class ClientSession:
    def __init__(self) -> None:
        self.seq = 0                       # seq of the last request sent
        self.welcome: Welcome | None = None

    def request(self, msg: Message) -> bytes:
        """The frame for ``msg`` with the next sequence number."""
        self.seq += 1
        return encode_frame(msg, self.seq)

    def keepalive(self, seq: int, msg: Message) -> bool:
        """True for a WORKING frame about the last request (1.1 KEEPALIVE): keep waiting."""
        return isinstance(msg, Working) and seq == self.seq

    def reply(self, seq: int, msg: Message, expect: type[M]) -> M:
        """Check a received frame answers the last request with a ``expect`` message."""
        if isinstance(msg, Error):
            raise RemoteError(ErrorCode(msg.code) if msg.code in ErrorCode._value2member_map_
                              else ErrorCode.INTERNAL, msg.text)
        if not isinstance(msg, expect):
            if isinstance(msg, Bye):
                raise ProtocolError(ErrorCode.OUT_OF_ORDER, f"server said BYE: {msg.reason}")
            raise ProtocolError(ErrorCode.OUT_OF_ORDER,
                                f"expected {expect.TYPE.name}, got {msg.TYPE.name}")
        if seq != self.seq:
            raise ProtocolError(ErrorCode.OUT_OF_ORDER, f"reply seq {seq}, request was {self.seq}")
        if isinstance(msg, Welcome):
            self.welcome = msg
        elif self.welcome is not None and isinstance(msg, (Nodes, Result)):
            _check_lengths(msg, self.welcome)
        elif self.welcome is not None and isinstance(msg, Gauges):
            if not len(msg.names) == msg.kind.size == self.welcome.n_gauges:
                raise ProtocolError(ErrorCode.SHAPE_MISMATCH, f"GAUGES has {len(msg.names)} names "
                                    f"and {msg.kind.size} kinds, WELCOME said {self.welcome.n_gauges}")
        return msg


def _check_lengths(msg: Nodes | Result, welcome: Welcome) -> None:
    if isinstance(msg, Nodes):
        expected = {"x": welcome.n_nodes, "z": welcome.n_nodes, "side": welcome.n_nodes,
                    "gauge_x": welcome.n_gauges}
    else:
        expected = {k: welcome.n_gauges for k in ("eta", "wet", "u_ref", "w_ref")}
    for name, n in expected.items():
        size = getattr(msg, name).size
        if size != n:
            raise ProtocolError(ErrorCode.SHAPE_MISMATCH,
                                f"{msg.TYPE.name}.{name} has {size} values, WELCOME said {n}")
