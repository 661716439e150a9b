"""The plain TCP coupling port: the first frame (HELLO) names the run, then the shared door."""

from __future__ import annotations

import asyncio
import logging

from protocol import ErrorCode, Hello, ProtocolError
from protocol.session import HELLO_LIMIT

from .doors import admit, serve_client
from .run_manager import RunManager
from .transports import TcpDoor

log = logging.getLogger("wavesph.server")


async def start_tcp_server(manager: RunManager, host: str, port: int) -> asyncio.base_events.Server:
    async def handle(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        transport = TcpDoor(reader, writer, min(HELLO_LIMIT, manager.settings.max_frame))
        try:
            await _handle(manager, transport)
        except Exception:  # noqa: BLE001 -- one bad connection never stops the port
            log.exception("tcp coupling connection failed")
            await transport.close()

    return await asyncio.start_server(handle, host, port)


def _run_id_of(hello: Hello) -> str:
    if not hello.run_id:
        raise ProtocolError(ErrorCode.BUSY, "HELLO.run_id is empty: the TCP port needs the run id")
    return hello.run_id


async def _handle(manager: RunManager, transport: TcpDoor) -> None:
    admitted = await admit(manager, transport, _run_id_of)
    if admitted is None:
        return await transport.close()  # left or refused (a second close is harmless)
    run, frames = admitted
    await serve_client(manager, run, transport, frames)
