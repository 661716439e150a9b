"""Minimal blocking test clients over TCP and WebSocket, built on protocol.ClientSession."""

from __future__ import annotations

import socket

import numpy as np
from websockets.sync.client import connect as ws_connect

from protocol import (Bye, ClientSession, FrameDecoder, GetNodes, Hello, Nodes, Result, Set, Solve,
                      Welcome, decode_frame)


class TcpClient:
    def __init__(self, port: int, timeout: float = 10.0) -> None:
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=timeout)
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self.decoder = FrameDecoder()
        self.session = ClientSession()
        self._frames: list = []

    def send_raw(self, data: bytes) -> None:
        self.sock.sendall(data)

    def recv(self):
        while not self._frames:
            data = self.sock.recv(65536)
            if not data:
                raise ConnectionError("server closed")
            self._frames += self.decoder.feed(data)
        return self._frames.pop(0)

    def request(self, *msgs, expect=None):
        self.send_raw(b"".join(self.session.request(m) for m in msgs))
        if expect is not None:
            return self.session.reply(*self.recv(), expect=expect)

    def closed_by_server(self) -> bool:
        try:
            return self.sock.recv(1) == b""
        except ConnectionError:
            return True

    def close(self) -> None:
        self.sock.close()


class WsClient(TcpClient):
    def __init__(self, url: str, timeout: float = 10.0) -> None:
        # entered as a context manager, as websockets >= 17.1 asks (exit is our close())
        self.ws = ws_connect(url, open_timeout=timeout, max_size=None).__enter__()
        self.session = ClientSession()
        self.timeout = timeout

    def send_raw(self, data: bytes) -> None:
        self.ws.send(data)

    def request(self, *msgs, expect=None):
        for m in msgs:  # one WebSocket message per frame
            self.ws.send(self.session.request(m))
        if expect is not None:
            return self.session.reply(*self.recv(), expect=expect)

    def recv(self):
        return decode_frame(self.ws.recv(timeout=self.timeout))

    def close(self) -> None:
        self.ws.close()


def run_windows(client, welcome: Welcome, nodes: Nodes, n: int, t0: float = 0.0, dt: float = 0.05,
                amplitude: float = 0.01) -> list[Result]:
    """n windows of SET + SOLVE with eta = amplitude * (k + 1), u = eta (simple to check)."""
    out = []
    t = t0
    for k in range(n):
        value = amplitude * (k + 1)
        full = np.full(welcome.n_nodes, value)
        out.append(client.request(Set(t, t + dt, full, np.zeros(welcome.n_nodes), full), Solve(),
                                  expect=Result))
        t += dt
    return out


def handshake(client, run_id: str, caps: int = 1, scene_hash: bytes = bytes(32)):
    welcome = client.request(Hello(caps, scene_hash, run_id, "pytest"), expect=Welcome)
    nodes = client.request(GetNodes(), expect=Nodes)
    return welcome, nodes


def bye(client) -> None:
    client.request(Bye("done"), expect=Bye)
