"""WebSocket coupling endpoint: one binary message per protocol frame (PROTOCOL.md)."""

from __future__ import annotations

from fastapi import APIRouter, WebSocket

from protocol import ErrorCode, Hello, ProtocolError
from protocol.session import HELLO_LIMIT

from ..doors import admit, serve_client
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
    transport.limit_messages(transport.max_payload)  # before HELLO: a HELLO at most

    def run_id_of(hello: Hello) -> str:
        if hello.run_id not in ("", run_id):
            raise ProtocolError(ErrorCode.BAD_VALUE, f"HELLO.run_id {hello.run_id[:64]!r} differs from "
                                                     f"the URL's {run_id[:64]!r}")
        return run_id

    admitted = await admit(manager, transport, run_id_of)
    if admitted is not None:
        run, frames = admitted
        transport.limit_messages(manager.settings.max_frame)  # a session's SET frames
        await serve_client(manager, run, transport, frames)
