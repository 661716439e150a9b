"""`wavesph serve`: the SPH coupling server (HTTP + WebSocket + TCP coupling port)."""

from __future__ import annotations

import argparse
import logging
import socket
import sys
from pathlib import Path

from pydantic import ValidationError

from server.settings import Settings

from ._common import add_device_argument, device_problem


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--host", help="HTTP/WebSocket bind address (default 127.0.0.1; "
                                       "any other address requires --token)")
    parser.add_argument("--port", type=int, help="HTTP port (default 8765)")
    parser.add_argument("--tcp-port", type=int, help="plain TCP coupling port (default 8766)")
    parser.add_argument("--runs-dir", type=Path, help="run store directory (default ./runs)")
    parser.add_argument("--max-runs", type=int, help="runs stepping at once; more are queued (default 2)")
    parser.add_argument("--max-particles", type=int, help="particle cap per run (default 2e6)")
    parser.add_argument("--token", help="API token (or WAVESPH_TOKEN); required off loopback")
    add_device_argument(parser, " for runs whose scene names no [run] device")
    parser.epilog = "Every option can also be set as WAVESPH_<OPTION> in the environment."


def port_in_use(host: str, port: int) -> str | None:
    """Why ``host:port`` cannot be bound now (the OS's words), or None if it can: checked before
    the server starts, so a busy port is one line, not a traceback from deep in uvicorn."""
    try:
        with socket.socket(socket.AF_INET6 if ":" in host else socket.AF_INET) as s:
            s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)  # as uvicorn binds
            s.bind((host, port))
    except OSError as exc:
        return exc.strerror or str(exc)
    return None


def main(args: argparse.Namespace) -> int:
    from server.asgi import server
    from server.main import create_app

    try:
        settings = Settings.from_env(host=args.host, port=args.port, tcp_port=args.tcp_port,
                                     runs_dir=args.runs_dir, max_runs=args.max_runs,
                                     max_particles=args.max_particles, token=args.token,
                                     device=args.device)
    except ValidationError as exc:
        for err in exc.errors():
            field = ".".join(str(p) for p in err["loc"]) or "settings"
            print(f"wavesph serve: {field}: {err['msg'].removeprefix('Value error, ')}", file=sys.stderr)
        return 2
    if device_problem("serve", settings.device):
        return 2
    tcp_host = settings.tcp_host or settings.host
    for what, host, port in (("--port", settings.host, settings.port),
                             ("--tcp-port", tcp_host, settings.tcp_port)):
        busy = port_in_use(host, port)
        if busy:
            print(f"wavesph serve: {what} {port} on {host} is not free ({busy}); "
                  f"choose another port", file=sys.stderr)
            return 1
    from server.store import store_in_use

    locked = store_in_use(settings.runs_dir)
    if locked:
        print(f"wavesph serve: {locked}", file=sys.stderr)
        return 1
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(name)s %(message)s")
    app = create_app(settings)
    host = f"[{settings.host}]" if ":" in settings.host else settings.host  # an IPv6 URL
    print(f"wavesph serve: http://{host}:{settings.port} (docs at /docs), TCP coupling "
          f"port {settings.tcp_port}, runs in {settings.runs_dir.resolve()}", file=sys.stderr)
    server(app, settings, log_level="info").run()   # Ctrl-C ends the page's event streams
    return 0
