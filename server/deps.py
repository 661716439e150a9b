"""Shared FastAPI dependencies as named Annotated aliases."""

from __future__ import annotations

import hmac
import logging
import re
from typing import Annotated

from fastapi import Depends, HTTPException, Request, WebSocket

from .run_manager import Run, RunManager


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


TOKEN_SUBPROTOCOL = "wavesph.token."   # a WebSocket subprotocol carrying the token (browsers)
SUBPROTOCOL = "wavesph"                 # the one the server selects when it is offered


def websocket_token_ok(ws: WebSocket) -> bool:
    """WebSocket clients give the token as a Bearer header, as a subprotocol
    ``wavesph.token.<token>`` (offered beside ``wavesph``, which the server selects), or as
    ``?token=`` (redacted in the server's logs)."""
    expected = ws.app.state.manager.settings.token
    offered = [p for p in ws.scope.get("subprotocols", []) if p.startswith(TOKEN_SUBPROTOCOL)]
    given = (_bearer(ws.headers.get("authorization"))
             or (offered[0][len(TOKEN_SUBPROTOCOL):] if offered else None)
             or ws.query_params.get("token"))
    return check_token(expected, given)


def websocket_subprotocol(ws: WebSocket) -> str | None:
    return SUBPROTOCOL if SUBPROTOCOL in ws.scope.get("subprotocols", []) else None


_TOKEN_IN_URL = re.compile(r"([?&](?:access_)?token=)[^&\s\"']*", re.IGNORECASE)  # ?TOKEN= too


def redact_tokens(text: str) -> str:
    """``?token=secret`` -> ``?token=***`` (URLs in log lines)."""
    return _TOKEN_IN_URL.sub(r"\1***", text)


class RedactTokens(logging.Filter):
    """Uvicorn's access and WebSocket log lines carry the query string: never the token."""

    def filter(self, record: logging.LogRecord) -> bool:
        if isinstance(record.msg, str):
            record.msg = redact_tokens(record.msg)
        if isinstance(record.args, tuple):
            record.args = tuple(redact_tokens(a) if isinstance(a, str) else a for a in record.args)
        return True


def redact_tokens_in_server_logs() -> None:
    """Install RedactTokens on uvicorn's loggers (once)."""
    for name in ("uvicorn.access", "uvicorn.error"):
        logger = logging.getLogger(name)
        if not any(isinstance(f, RedactTokens) for f in logger.filters):
            logger.addFilter(RedactTokens())


def get_run(run_id: str, manager: Annotated[RunManager, Depends(get_manager)]) -> Run:
    run = manager.runs.get(run_id)
    if run is None:
        # never the whole id: a 70 kB path would come back in the reply
        raise HTTPException(404, f"no run {run_id[:80]!r}" + (" (cut)" if len(run_id) > 80 else ""))
    return run


Manager = Annotated[RunManager, Depends(get_manager)]
RunDep = Annotated[Run, Depends(get_run)]
Auth = Depends(require_token)
