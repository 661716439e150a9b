"""What the coupling door reads and writes frames through (``DoorTransport``), and its two
socket forms: plain TCP (length-prefixed frames) and WebSocket (one frame per binary message).
The built-in theory source (theory_client.py) is a third, in memory."""

from __future__ import annotations

import asyncio
import socket
from typing import Protocol

from fastapi import WebSocket, WebSocketDisconnect

from protocol import ErrorCode, FrameDecoder, ProtocolError, decode_frame
from protocol.wire import HEADER_SIZE
from protocol.messages import Message

READ_CHUNK = 1 << 16


class DoorTransport(Protocol):
    """``recv()`` gives a list of (seq, message), or None when the peer closed."""

    max_payload: int

    async def recv(self) -> list[tuple[int, Message]] | None: ...
    async def send(self, data: bytes) -> None: ...
    async def close(self) -> None: ...


class PeerGone(Exception):
    """The connection broke while sending: the client vanished."""


class TcpDoor:
    def __init__(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter,
                 max_payload: int) -> None:
        self.reader, self.writer = reader, writer
        self.decoder = FrameDecoder(max_payload)
        sock = writer.get_extra_info("socket")
        if sock is not None:
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)

    @property
    def max_payload(self) -> int:
        return self.decoder.max_payload

    @max_payload.setter
    def max_payload(self, value: int) -> None:
        self.decoder.max_payload = value

    async def recv(self) -> list[tuple[int, Message]] | None:
        while True:
            try:
                data = await self.reader.read(READ_CHUNK)
            except ConnectionError:
                return None
            if not data:
                self.decoder.eof()  # a frame cut short is MALFORMED, a clean close is None
                return None
            frames = self.decoder.feed(data)
            if frames:
                return frames

    async def send(self, data: bytes) -> None:
        try:
            self.writer.write(data)
            await self.writer.drain()
        except (ConnectionError, RuntimeError) as exc:
            raise PeerGone(str(exc)) from None

    async def close(self) -> None:
        self.writer.close()
        try:
            await self.writer.wait_closed()
        except ConnectionError:
            pass


class WebSocketDoor:
    def __init__(self, ws: WebSocket, max_payload: int) -> None:
        self.ws = ws
        self.max_payload = max_payload

    def limit_messages(self, payload: int) -> bool:
        """Make the WebSocket connection refuse (close 1009) any message over a frame of
        ``payload`` bytes as it reads its header, before buffering it: the ASGI server's own
        limit (asgi.py, ws_max_size) is the largest frame of any session, 16 MiB, which a
        client that has not even said HELLO must not make the server hold. Works on uvicorn's
        websockets protocols (sans-I/O and legacy), whose limits are read per message; False
        where the server exposes none (its own limit stays)."""
        proto = getattr(getattr(self.ws, "_receive", None), "__self__", None)
        size = payload + HEADER_SIZE
        conn = getattr(proto, "conn", None)
        if conn is not None and hasattr(conn, "max_message_size"):
            conn.max_message_size = size
            return True
        if proto is not None and hasattr(proto, "max_size"):
            proto.max_size = size
            return True
        return False

    async def recv(self) -> list[tuple[int, Message]] | None:
        try:
            message = await self.ws.receive()
        except (WebSocketDisconnect, RuntimeError):
            return None
        if message["type"] == "websocket.disconnect":
            return None
        data = message.get("bytes")
        if data is None:
            raise ProtocolError(ErrorCode.MALFORMED, "a text WebSocket message: frames are binary messages")
        return [decode_frame(data, self.max_payload)]

    async def send(self, data: bytes) -> None:
        try:
            await self.ws.send_bytes(data)
        except (WebSocketDisconnect, ConnectionError, RuntimeError) as exc:
            raise PeerGone(str(exc)) from None

    async def close(self) -> None:
        try:
            await self.ws.close()
        except RuntimeError:
            pass  # already closed
