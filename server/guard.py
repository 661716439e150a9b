"""Requests from web pages a loopback server must not serve (CSRF, DNS rebinding).

A server bound to loopback trusts its machine and asks no token. A web page the user visits can
still send requests to it: a POST with a "simple" content type needs no CORS preflight, and a
rebound DNS name reaches 127.0.0.1 under a foreign Host. So on a loopback-only server:
- the Host header must name a loopback address (else 421);
- a request that changes something (POST, PUT, PATCH, DELETE) or opens a WebSocket with an
  Origin header must come from a loopback origin (the server's own page; else 403).
A public server (it has a token, which no page knows) is left to the token.
"""

from __future__ import annotations

import ipaddress
import json
from typing import Any, Awaitable, Callable
from urllib.parse import urlsplit

Scope = dict[str, Any]
ASGIApp = Callable[[Scope, Callable[[], Awaitable[dict]], Callable[[dict], Awaitable[None]]],
                   Awaitable[None]]

CHANGES = frozenset({"POST", "PUT", "PATCH", "DELETE"})


def loopback_name(host: str) -> bool:
    """``host`` (no port; an IPv6 address without brackets) names this machine's loopback."""
    host = host.lower().rstrip(".")
    if host == "localhost" or host.endswith(".localhost"):
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def _host_of(value: str) -> str:
    """The host of a Host header value (``name:port``, ``[::1]:port``)."""
    return urlsplit("//" + value).hostname or ""


class LoopbackGuard:
    """ASGI middleware refusing foreign Host and Origin headers (see the module docstring)."""

    def __init__(self, app: ASGIApp, enabled: bool) -> None:
        self.app, self.enabled = app, enabled

    async def __call__(self, scope: Scope, receive: Any, send: Any) -> None:
        if not self.enabled or scope["type"] not in ("http", "websocket"):
            return await self.app(scope, receive, send)
        headers = {k.decode("latin-1").lower(): v.decode("latin-1") for k, v in scope["headers"]}
        why = None
        if not loopback_name(_host_of(headers.get("host", "localhost"))):
            why = (421, "this server answers to loopback names only (Host: localhost or 127.0.0.1)")
        elif "origin" in headers and (scope["type"] == "websocket"
                                      or scope.get("method", "GET") in CHANGES):
            origin = urlsplit(headers["origin"]).hostname or ""
            if not loopback_name(origin):
                why = (403, "requests from a web page of another origin are refused")
        if why is None:
            return await self.app(scope, receive, send)
        if scope["type"] == "websocket":  # refused before the handshake: HTTP 403
            await send({"type": "websocket.close", "code": 1008})
            return
        body = json.dumps({"detail": why[1]}).encode()
        await send({"type": "http.response.start", "status": why[0],
                    "headers": [(b"content-type", b"application/json"),
                                (b"content-length", str(len(body)).encode())]})
        await send({"type": "http.response.body", "body": body})
