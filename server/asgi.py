"""The uvicorn configuration of every server start (`wavesph serve`, the in-process server of the
demo, cases and tests, the coupling benchmark): one place for the WebSocket options.

Keepalive pings (found 2026-11-23, docs in protocol/PROTOCOL.md "Timeouts"): uvicorn's defaults
(ping every 20 s, drop the client if its pong is 20 s late) dropped coupled runs on a loaded
machine. A coupling client answers pings only when its asyncio loop runs, and it runs its wave
model in that loop between frames: the Boussinesq model's cold numba compile blocked it 53 s in
window 1 (load ~16), and a client blocked > 40 s lost its run ("client disconnected").
The protocol has its own liveness rules (hello_timeout, idle_timeout, WORKING frames), so the
server still pings (proxies see traffic) but never drops a client for a late pong by default.
"""

from __future__ import annotations

from typing import Any

from server.settings import Settings


def head_timeout_protocol(timeout: float) -> type:
    """uvicorn's h11 HTTP protocol, closing a connection whose request head (request line and
    headers) has not all come within ``timeout`` seconds of the connection or of the previous
    response. uvicorn has no such limit: a client sending a header line now and then (slowloris)
    held its connection for ever. A request being served (an event stream, a body) and a
    connection upgraded to a WebSocket are never cut."""
    from uvicorn.protocols.http.h11_impl import H11Protocol

    class HeadTimeoutH11(H11Protocol):
        def connection_made(self, transport: Any) -> None:
            super().connection_made(transport)
            self._arm_head_timer()

        def on_response_complete(self) -> None:
            super().on_response_complete()
            self._arm_head_timer()

        def _arm_head_timer(self) -> None:
            self.loop.call_later(timeout, self._head_due, self.cycle)

        def _head_due(self, cycle: Any) -> None:
            transport = self.transport
            if (self.cycle is cycle  # no request head has come since the timer was armed
                    and (cycle is None or cycle.response_complete)
                    and transport.get_protocol() is self and not transport.is_closing()):
                transport.close()

    return HeadTimeoutH11


def uvicorn_config(app: Any, settings: Settings, *, log_level: str = "info") -> Any:
    """A ``uvicorn.Config`` serving ``app`` on ``settings.host:settings.port``."""
    import uvicorn

    return uvicorn.Config(
        app, host=settings.host, port=settings.port, log_level=log_level, lifespan="on",
        http=head_timeout_protocol(settings.header_timeout),
        ws_max_size=settings.max_frame + 16,  # one frame = one message: header + payload
        ws_per_message_deflate=False,  # float64 arrays do not compress: deflate only costs time
        ws_ping_interval=settings.ws_ping_interval,
        ws_ping_timeout=settings.ws_ping_timeout)


def _server_class() -> Any:
    import uvicorn

    class Server(uvicorn.Server):
        """uvicorn's server that tells the app it is stopping (``app.state.stopping``) as soon as
        it is asked to (Ctrl-C): uvicorn waits for open connections, and the page's event stream
        of a running run kept `wavesph serve` (and the run) going ~20 s after Ctrl-C."""

        def handle_exit(self, sig: int, frame: Any) -> None:
            stopping = getattr(getattr(self.config.app, "state", None), "stopping", None)
            if stopping is not None:
                stopping.set()
            super().handle_exit(sig, frame)

    return Server


def server(app: Any, settings: Settings, *, log_level: str = "info") -> Any:
    """The ``uvicorn.Server`` of ``uvicorn_config``, which ends event streams on Ctrl-C."""
    return _server_class()(uvicorn_config(app, settings, log_level=log_level))
