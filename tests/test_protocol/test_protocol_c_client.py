"""The C example client (examples/c_client) couples to a Python peer playing the SPH side.

The peer is built from the protocol package only (SphSession + sockets), with a trivial
deterministic 'engine' that echoes the imposed elevation back as the gauge reading. The test
checks the values the C client computed against linear theory evaluated here independently.
"""

from __future__ import annotations

import socket
import subprocess
import threading

import numpy as np
import pytest

from protocol import (ErrorCode, FrameDecoder, Nodes, ProtocolError, Result, SphSession, Welcome,
                      scene_hash)
from protocol.session import PeerError, Reply, SetWindow, SolveWindow

from linear_wave import airy

G_ACC, DEPTH, H, T = 9.81, 0.6, 0.04, 1.2
X_INLET = 0.0


class PythonPeer:
    """One-connection TCP server: the SPH side, made of protocol.SphSession and a fake engine."""

    def __init__(self, n_nodes: int = 5, gauges=(X_INLET, 2.0), refuse: ProtocolError | None = None):
        z = np.linspace(-DEPTH, 0.05, n_nodes)  # the top node sits above still water
        self.welcome = Welcome(0, scene_hash(b"c-test"), g=G_ACC, depth=DEPTH, still_water_level=DEPTH,
                               z_ref=-0.3, t_start=0.0, t_end=10.0, dt_sph=1e-3, window_max=0.05,
                               idle_timeout=10.0, n_nodes=n_nodes, n_gauges=len(gauges),
                               max_payload=0, run_id="run-c", server="python-peer")
        self.nodes = Nodes(np.full(n_nodes, X_INLET), z, np.zeros(n_nodes, np.uint32), list(gauges))
        self.refuse = refuse
        self.sets: list[SetWindow] = []
        self.peer_error: PeerError | None = None
        self.listener = socket.create_server(("127.0.0.1", 0))
        self.port = self.listener.getsockname()[1]
        self.thread = threading.Thread(target=self._serve, daemon=True)
        self.thread.start()

    def _serve(self) -> None:
        conn, _ = self.listener.accept()
        conn.settimeout(10.0)
        conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        session = SphSession(self.welcome, self.nodes)
        decoder = FrameDecoder(session.max_payload)
        with conn:
            while True:
                data = conn.recv(65536)
                if not data:
                    return
                try:
                    for seq, msg in decoder.feed(data):
                        if self.refuse is not None:
                            raise self.refuse
                        action = session.receive(seq, msg)
                        decoder.max_payload = session.max_payload
                        if isinstance(action, Reply):
                            conn.sendall(action.data)
                            if action.close:
                                return
                        elif isinstance(action, SetWindow):
                            self.sets.append(action)
                        elif isinstance(action, SolveWindow):
                            eta = float(self.sets[-1].eta.mean())
                            g = self.welcome.n_gauges
                            conn.sendall(session.result(action, Result(
                                0.0, 17, np.full(g, eta), np.array([1] + [0] * (g - 1)),
                                np.zeros(g), np.zeros(g))))
                        elif isinstance(action, PeerError):
                            self.peer_error = action
                            return
                except ProtocolError as exc:
                    conn.sendall(session.error_frame(exc))
                    return

    def close(self) -> None:
        self.thread.join(timeout=10)
        self.listener.close()


def test_c_client_couples_a_linear_wave(c_client):
    peer = PythonPeer()
    run = subprocess.run([str(c_client), "127.0.0.1", str(peer.port), "run-c", "8", str(H), str(T), "0.05"],
                         capture_output=True, text=True, timeout=30)
    peer.close()
    assert run.returncode == 0, run.stderr
    lines = [line.split() for line in run.stdout.splitlines()]
    assert len(lines) == 8 == len(peer.sets)
    for i, (words, window) in enumerate(zip(lines, peer.sets)):
        t1 = 0.05 * (i + 1)
        assert window.t0 == pytest.approx(0.05 * i) and window.t1 == pytest.approx(t1)
        u, w, eta = airy(X_INLET, peer.nodes.z, t1, H, T, DEPTH, G_ACC)
        np.testing.assert_allclose(window.u, u, rtol=1e-12, atol=1e-15)
        np.testing.assert_allclose(window.w, w, rtol=1e-12, atol=1e-15)
        np.testing.assert_allclose(window.eta, eta, rtol=1e-12, atol=1e-15)
        assert words[0] == "RESULT" and float(words[1]) == pytest.approx(t1) and words[2] == "17"
        assert float(words[3]) == pytest.approx(eta, rel=1e-12) and words[4] == "dry"


def test_c_client_reports_a_server_error(c_client):
    peer = PythonPeer(refuse=ProtocolError(ErrorCode.SCENE_MISMATCH, "scene differs from the run's"))
    run = subprocess.run([str(c_client), "127.0.0.1", str(peer.port), "run-c", "3"],
                         capture_output=True, text=True, timeout=30)
    peer.close()
    assert run.returncode == 3
    assert "server error 7: scene differs from the run's" in run.stderr
