"""Thin transports for the coupling client: WebSocket and plain TCP, the same frames.

- ``ws://host:port/runs/ID/couple`` (or wss://): one binary WebSocket message = one frame.
- ``tcp://host:port``: frames back to back on the stream (the HELLO names the run).

Both set TCP_NODELAY (one small frame per window must not wait for Nagle) and put a timeout
on every read: a vanished server becomes `CouplingTimeout`, never a hang.
"""

from __future__ import annotations

import asyncio
import socket
from collections import deque
from typing import Protocol
from urllib.parse import urlsplit

from protocol import MAX_PAYLOAD, HEADER_SIZE, FrameDecoder, Message, decode_frame


class TransportClosed(ConnectionError):
    """The server closed the connection."""


class Transport(Protocol):
    async def send(self, frames: list[bytes]) -> None: ...
    async def recv(self, timeout: float) -> tuple[int, Message]: ...
    async def close(self) -> None: ...


def _nodelay(sock: socket.socket | None) -> None:
    if sock is not None and sock.family in (socket.AF_INET, socket.AF_INET6):
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)


def parse_url(url: str) -> tuple[str, str, int, str]:
    """(scheme, host, port, run_id from a ws path /runs/ID/couple or '') with clear errors."""
    parts = urlsplit(url)
    if parts.scheme not in ("ws", "wss", "tcp"):
        raise ValueError(f"url must start with ws://, wss:// or tcp://, got {url!r}")
    if not parts.hostname:
        raise ValueError(f"url has no host: {url!r}")
    try:
        port = parts.port
    except ValueError as exc:
        raise ValueError(f"url has a bad port: {url!r}") from exc
    if parts.scheme == "tcp" and port is None:
        raise ValueError(f"a tcp:// url needs a port, e.g. tcp://127.0.0.1:8766, got {url!r}")
    segments = [s for s in parts.path.split("/") if s]
    run_id = segments[1] if len(segments) >= 2 and segments[0] == "runs" else ""
    default = 443 if parts.scheme == "wss" else 80
    return parts.scheme, parts.hostname, port or default, run_id


class WebSocketTransport:
    def __init__(self, ws) -> None:
        self._ws = ws

    @classmethod
    async def open(cls, url: str, timeout: float) -> "WebSocketTransport":
        from websockets.asyncio.client import connect

        # no proxy (a coupling server is reached directly), no compression (float arrays do
        # not compress and it costs time), no keepalive pings (our read timeouts detect a dead
        # peer; a server busy in a long window must not be dropped for a late pong)
        ws = await connect(url, open_timeout=timeout, proxy=None, compression=None,
                           ping_interval=None, max_size=HEADER_SIZE + MAX_PAYLOAD)
        _nodelay(ws.transport.get_extra_info("socket"))
        return cls(ws)

    async def send(self, frames: list[bytes]) -> None:
        from websockets.exceptions import ConnectionClosed

        try:
            for frame in frames:
                await self._ws.send(frame)
        except ConnectionClosed as exc:
            raise TransportClosed(f"the server closed the WebSocket ({exc})") from exc

    async def recv(self, timeout: float) -> tuple[int, Message]:
        from websockets.exceptions import ConnectionClosed

        try:
            data = await asyncio.wait_for(self._ws.recv(), timeout)
        except ConnectionClosed as exc:
            raise TransportClosed(f"the server closed the WebSocket ({exc})") from exc
        if isinstance(data, str):
            raise TransportClosed("the server sent a text WebSocket message; frames are binary")
        return decode_frame(data)

    async def close(self) -> None:
        await self._ws.close()


class TcpTransport:
    def __init__(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        self._reader, self._writer = reader, writer
        self._decoder = FrameDecoder(MAX_PAYLOAD)
        self._ready: deque[tuple[int, Message]] = deque()

    @classmethod
    async def open(cls, host: str, port: int, timeout: float) -> "TcpTransport":
        reader, writer = await asyncio.wait_for(asyncio.open_connection(host, port), timeout)
        _nodelay(writer.get_extra_info("socket"))
        return cls(reader, writer)

    async def send(self, frames: list[bytes]) -> None:
        try:
            self._writer.write(b"".join(frames))
            await self._writer.drain()
        except (ConnectionError, OSError) as exc:
            raise TransportClosed(f"the server closed the TCP connection ({exc})") from exc

    async def recv(self, timeout: float) -> tuple[int, Message]:
        loop = asyncio.get_running_loop()
        deadline = loop.time() + timeout
        while not self._ready:
            left = deadline - loop.time()
            if left <= 0:
                raise TimeoutError
            try:
                data = await asyncio.wait_for(self._reader.read(65536), left)
            except TimeoutError:  # an OSError too: let it through as what it is
                raise
            except (ConnectionError, OSError) as exc:
                raise TransportClosed(f"the TCP connection broke ({exc})") from exc
            if not data:
                self._decoder.eof()  # raises if a frame was cut short
                raise TransportClosed("the server closed the TCP connection")
            self._ready.extend(self._decoder.feed(data))
        return self._ready.popleft()

    async def close(self) -> None:
        self._writer.close()
        try:
            await asyncio.wait_for(self._writer.wait_closed(), 2.0)
        except (TimeoutError, ConnectionError, OSError):
            pass


async def open_transport(url: str, timeout: float) -> Transport:
    """Connect to ``url`` (ws://, wss:// or tcp://) within ``timeout`` seconds."""
    scheme, host, port, _ = parse_url(url)
    if scheme == "tcp":
        return await TcpTransport.open(host, port, timeout)
    return await WebSocketTransport.open(url, timeout)
