"""The plain TCP coupling port: the first frame (HELLO) names the run, then the shared door."""

from __future__ import annotations

import asyncio
import logging

from protocol import ErrorCode, Hello, ProtocolError
from protocol.session import HELLO_LIMIT

from .doors import claim_run, error_frame, serve_client
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


async def _handle(manager: RunManager, transport: TcpDoor) -> None:
    seq = 0
    try:
        frames = await asyncio.wait_for(transport.recv(), manager.settings.hello_timeout)
        if frames is None:
            return await transport.close()
        seq, msg = frames[0]
        if not isinstance(msg, Hello):
            raise ProtocolError(ErrorCode.OUT_OF_ORDER, f"{msg.TYPE.name} before HELLO")
        if not msg.run_id:
            raise ProtocolError(ErrorCode.BUSY, "HELLO.run_id is empty: the TCP port needs the run id")
        run = await claim_run(manager, msg.run_id, msg, transport, seq)
        if run is None:
            return await transport.close()
    except ProtocolError as exc:
        await _refuse(transport, exc.code, exc.text, seq)
        return
    except TimeoutError:
        await _refuse(transport, ErrorCode.TIMEOUT,
                      f"no HELLO within {manager.settings.hello_timeout:g} s", 0)
        return
    await serve_client(manager, run, transport, frames)


async def _refuse(transport: TcpDoor, code: ErrorCode, text: str, seq: int) -> None:
    try:
        await asyncio.wait_for(transport.send(error_frame(code, text, seq)), 5.0)
    except Exception:  # noqa: BLE001
        pass
    await transport.close()
