"""Protocol 1.1 KEEPALIVE: while a window is solving (the first one waits for the JIT compile),
a client that asked for it gets WORKING frames carrying the SOLVE's seq; a 1.0 client gets
none (served unchanged); wave_client's reply timeout then bounds the server's silence."""

from __future__ import annotations

import socket

import numpy as np

from protocol import (Capability, ClientSession, FrameDecoder, Hello, Result, Set, Solve, Welcome,
                      Working)
from server_harness import live_server
from sph_engine_double import EngineDouble
from wave_client.coupling import CouplingOptions, couple
from wave_client.theories.linear import AiryWave

DELAY = 0.5  # [s] each window's solve


def _slow(request, run_dir, **kw):
    return EngineDouble(request, solve_delay=DELAY)


def _frames_of_one_window(tcp_port: int, run_id: str, caps: int) -> list:
    cs, dec, got = ClientSession(), FrameDecoder(), []
    with socket.create_connection(("127.0.0.1", tcp_port), timeout=10) as sock:
        sock.sendall(cs.request(Hello(caps, bytes(32), run_id, "keepalive test")))
        welcome = cs.reply(*dec.feed(sock.recv(1 << 16))[0], expect=Welcome)
        z = np.zeros(welcome.n_nodes)
        sock.sendall(cs.request(Set(0.0, 0.05, z, z, z)) + cs.request(Solve()))
        while not got or not isinstance(got[-1][1], Result):
            got.extend(dec.feed(sock.recv(1 << 16)))
        assert all(seq == cs.seq for seq, _ in got)  # WORKING carries the SOLVE's seq
        return [welcome] + [m for _, m in got]


def test_working_frames_only_for_a_client_that_asked(tmp_path):
    with live_server(tmp_path, _slow, keepalive_every=0.1) as srv:
        a, b = srv.create(t_end=0.5), srv.create(t_end=0.5)
        for r in (a, b):
            srv.wait_state(r["id"], "waiting_for_client")
        new = _frames_of_one_window(srv.tcp_port, a["id"], int(Capability.KEEPALIVE))
        old = _frames_of_one_window(srv.tcp_port, b["id"], 0)
    assert new[0].capabilities & Capability.KEEPALIVE
    working = [m for m in new if isinstance(m, Working)]
    assert len(working) >= 2 and isinstance(new[-1], Result)
    assert all(0.05 < w.elapsed < DELAY + 1 for w in working)
    assert [w.elapsed for w in working] == sorted(w.elapsed for w in working)
    assert not old[0].capabilities & Capability.KEEPALIVE
    assert len(old) == 2 and isinstance(old[1], Result)  # 1.0: RESULT only


def test_wave_client_waits_through_working_frames(tmp_path):
    # every reply takes DELAY, longer than the client's timeout: only WORKING frames keep it going
    with live_server(tmp_path, _slow, keepalive_every=0.1) as srv:
        run = srv.create(t_end=0.1)
        srv.wait_state(run["id"], "waiting_for_client")
        report = couple(f"tcp://127.0.0.1:{srv.tcp_port}", AiryWave(height=0.02, period=1.0, depth=0.3),
                        CouplingOptions(window=0.05), run_id=run["id"], timeout=DELAY / 2,
                        progress=False)
        assert len(report.records) == 2
        assert srv.wait_state(run["id"], "finished")["windows"] == 2


def _frames_until(sock: socket.socket, dec: FrameDecoder, stop, limit: float) -> list:
    """Frames read until ``stop(frames)`` or ``limit`` seconds of silence."""
    got: list = []
    sock.settimeout(limit)
    while not stop(got):
        try:
            data = sock.recv(1 << 16)
        except socket.timeout:
            break
        if not data:
            break
        got.extend(dec.feed(data))
    return got


def test_working_frames_before_welcome_while_the_run_is_not_ready(tmp_path, factory):
    """A HELLO for a run that is queued (or being built, or waiting for a slot) waits for
    WELCOME; a 1.1 client that asked for KEEPALIVE gets WORKING meanwhile (the HELLO's seq,
    elapsed since the HELLO), a 1.0 client gets nothing but the WELCOME."""
    with live_server(tmp_path, factory, max_waiting=1, keepalive_every=0.1) as srv:
        blocker = srv.create()
        srv.wait_state(blocker["id"], "waiting_for_client")
        run = srv.create(t_end=0.1)
        assert srv.http.get(f"/runs/{run['id']}").json()["state"] == "queued"
        # 1.0: silence until WELCOME
        with socket.create_connection(("127.0.0.1", srv.tcp_port), timeout=10) as sock:
            sock.sendall(ClientSession().request(Hello(0, bytes(32), run["id"], "old client")))
            assert _frames_until(sock, FrameDecoder(), lambda g: bool(g), 1.0) == []
        # 1.1 with KEEPALIVE: WORKING frames, then WELCOME once the blocker is gone
        cs, dec = ClientSession(), FrameDecoder()
        with socket.create_connection(("127.0.0.1", srv.tcp_port), timeout=10) as sock:
            sock.sendall(cs.request(Hello(int(Capability.KEEPALIVE), bytes(32), run["id"], "new")))
            early = _frames_until(sock, dec, lambda g: len(g) >= 3, 10.0)
            assert len(early) == 3 and all(isinstance(m, Working) and seq == cs.seq for seq, m in early)
            elapsed = [m.elapsed for _, m in early]
            assert elapsed == sorted(elapsed) and elapsed[0] > 0.05
            assert srv.http.delete(f"/runs/{blocker['id']}").status_code in (200, 202, 204)
            rest = _frames_until(sock, dec, lambda g: any(isinstance(m, Welcome) for _, m in g), 30.0)
            assert rest and isinstance(rest[-1][1], Welcome)
            assert all(isinstance(m, Working) for _, m in rest[:-1])
            welcome = cs.reply(*rest[-1], expect=Welcome)
            assert welcome.capabilities & Capability.KEEPALIVE
