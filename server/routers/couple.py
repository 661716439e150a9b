"""WebSocket coupling endpoint: one binary message per protocol frame (PROTOCOL.md)."""

from __future__ import annotations

import asyncio

from fastapi import APIRouter, WebSocket

from protocol import ErrorCode, Hello, ProtocolError
from protocol.session import HELLO_LIMIT

from ..doors import claim_run, error_frame, serve_client
from ..deps import websocket_subprotocol, websocket_token_ok
from ..transports import WebSocketDoor

router = APIRouter(tags=["coupling"])


@router.websocket("/runs/{run_id}/couple")
async def couple_websocket(ws: WebSocket, run_id: str) -> None:
    if not websocket_token_ok(ws):
        await ws.close(code=1008, reason="missing or wrong API token")
        return
    await ws.accept(subprotocol=websocket_subprotocol(ws))
    manager = ws.app.state.manager
    transport = WebSocketDoor(ws, min(HELLO_LIMIT, manager.settings.max_frame))
    seq = 0
    try:
        frames = await asyncio.wait_for(transport.recv(), manager.settings.hello_timeout)
        if frames is None:
            return
        seq, msg = frames[0]
        if not isinstance(msg, Hello):
            raise ProtocolError(ErrorCode.OUT_OF_ORDER, f"{msg.TYPE.name} before HELLO")
        if msg.run_id not in ("", run_id):
            raise ProtocolError(ErrorCode.BUSY, f"HELLO.run_id {msg.run_id!r} differs from the URL's {run_id!r}")
        run = await claim_run(manager, run_id, msg, transport, seq)
        if run is None:
            return await transport.close()
    except ProtocolError as exc:
        await _refuse(transport, exc.code, exc.text, seq)
        return
    except TimeoutError:
        await _refuse(transport, ErrorCode.TIMEOUT, f"no HELLO within {manager.settings.hello_timeout:g} s", 0)
        return
    await serve_client(manager, run, transport, frames)


async def _refuse(transport: WebSocketDoor, code: ErrorCode, text: str, seq: int) -> None:
    try:
        await transport.send(error_frame(code, text, seq))
    except Exception:  # noqa: BLE001 -- the peer may already be gone
        pass
    await transport.close()
