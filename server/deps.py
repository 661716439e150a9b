"""Shared FastAPI dependencies as named Annotated aliases."""

from __future__ import annotations

import hmac
from typing import Annotated

from fastapi import Depends, HTTPException, Request, WebSocket

from .runs import Run, RunManager


def get_manager(request: Request) -> RunManager:
    return request.app.state.manager


def check_token(expected: str | None, given: str | None) -> bool:
    return expected is None or (given is not None and hmac.compare_digest(given, expected))


def _bearer(header: str | None) -> str | None:
    if header and header.lower().startswith("bearer "):
        return header[7:].strip()
    return None


def require_token(request: Request) -> None:
    """``Authorization: Bearer <token>`` when the server has a token."""
    expected = request.app.state.manager.settings.token
    if not check_token(expected, _bearer(request.headers.get("authorization"))):
        raise HTTPException(401, "missing or wrong API token (Authorization: Bearer <token>)",
                            headers={"WWW-Authenticate": "Bearer"})


def websocket_token_ok(ws: WebSocket) -> bool:
    """WebSocket clients give the token as a Bearer header or as ``?token=``."""
    expected = ws.app.state.manager.settings.token
    given = _bearer(ws.headers.get("authorization")) or ws.query_params.get("token")
    return check_token(expected, given)


def get_run(run_id: str, manager: Annotated[RunManager, Depends(get_manager)]) -> Run:
    run = manager.runs.get(run_id)
    if run is None:
        raise HTTPException(404, f"no run {run_id!r}")
    return run


Manager = Annotated[RunManager, Depends(get_manager)]
RunDep = Annotated[Run, Depends(get_run)]
Auth = Depends(require_token)
