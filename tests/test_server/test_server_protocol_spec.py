"""Statements of protocol/PROTOCOL.md that a client written from the page alone relies on,
pinned against the live server (engine double): where to find the TCP port, which ERROR code
and seq a refusal carries, the WebSocket subprotocol and close codes, the time tolerances, and
RESULT.t as the next window's t0."""

from __future__ import annotations

import math
import struct

import numpy as np
import pytest
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import connect as ws_connect

from protocol import (Bye, Error, ErrorCode, GetNodes, Hello, RemoteError, Result, Set, Solve, Welcome,
                      decode_frame, encode_frame)

from coupling_client import TcpClient, WsClient, bye, handshake


def _error(client) -> tuple[int, Error]:
    seq, msg = client.recv()
    assert isinstance(msg, Error), msg
    return seq, msg


def test_runinfo_names_the_tcp_coupling_port(srv):
    """Transports: the TCP port is found over HTTP, in every RunInfo."""
    run = srv.create()
    assert run["tcp_port"] == srv.tcp_port
    assert srv.http.get(f"/runs/{run['id']}").json()["tcp_port"] == srv.tcp_port
    assert [r["tcp_port"] for r in srv.http.get("/runs").json()] == [srv.tcp_port]


@pytest.mark.parametrize("door", ["tcp", "ws"])
def test_hello_naming_an_unknown_run_is_not_found_with_the_hellos_seq(srv, door):
    client = (TcpClient(srv.tcp_port) if door == "tcp"
              else WsClient(f"ws://127.0.0.1:{srv.port}/runs/nope/couple"))
    client.send_raw(encode_frame(Hello(0, bytes(32), "nope", "pytest"), 1))
    seq, err = _error(client)
    assert (err.code, seq) == (ErrorCode.NOT_FOUND, 1) and "no run 'nope'" in err.text


def test_ws_hello_naming_another_run_than_the_url_is_bad_value(srv):
    run = srv.create()
    srv.wait_state(run["id"], "waiting_for_client")
    client = WsClient(f"ws://127.0.0.1:{srv.port}/runs/{run['id']}/couple")
    client.send_raw(encode_frame(Hello(0, bytes(32), "another", "pytest"), 1))
    seq, err = _error(client)
    assert (err.code, seq) == (ErrorCode.BAD_VALUE, 1) and "differs from the URL" in err.text
    assert srv.http.get(f"/runs/{run['id']}").json()["state"] == "waiting_for_client"


def test_hello_to_an_ended_run_is_busy_saying_it_ended(srv):
    run = srv.create()
    client, welcome, nodes = srv.couple(run["id"])
    bye(client)
    srv.wait_state(run["id"], "finished")
    with pytest.raises(RemoteError) as exc:
        handshake(TcpClient(srv.tcp_port), run["id"])
    assert exc.value.code is ErrorCode.BUSY and "is finished" in exc.value.text


def _nan_set(seq: int, n: int) -> bytes:
    frame = bytearray(encode_frame(Set(0.0, 0.05, np.zeros(n), np.zeros(n), np.zeros(n)), seq))
    struct.pack_into("<d", frame, 16 + 16 + 4, math.nan)  # SET.u[0]; our encoder refuses NaN
    return bytes(frame)


@pytest.mark.parametrize("case", ["nan", "wrong seq", "time"])
def test_an_error_refusing_a_frame_carries_its_seq_and_fails_the_run(srv, case):
    run = srv.create()
    client, welcome, _ = srv.couple(run["id"])      # HELLO 1, GETNODES 2
    n = welcome.n_nodes
    z = np.zeros(n)
    frame = {"nan": _nan_set(3, n), "wrong seq": encode_frame(Set(0.0, 0.05, z, z, z), 7),
             "time": encode_frame(Set(0.01, 0.05, z, z, z), 3)}[case]
    client.send_raw(frame)
    seq, err = _error(client)
    code = {"nan": ErrorCode.BAD_VALUE, "wrong seq": ErrorCode.OUT_OF_ORDER,
            "time": ErrorCode.TIME_MISMATCH}[case]
    assert (err.code, seq) == (code, int.from_bytes(frame[8:12], "little")), err.text
    assert client.closed_by_server()
    assert srv.wait_state(run["id"], "failed")["status"].startswith("failed: protocol error")


def test_window_times_within_the_relative_tolerance_and_result_t_is_the_next_t0(srv):
    """SET: t0 matches within 1e-9 * max(1 s, |t0|, |t|), a window may exceed window_max by
    1e-9 of it, t1 may pass t_end within the same tolerance; RESULT.t is the SET's t1 bit for
    bit, and the next window starts there."""
    run = srv.create(t_end=0.2)
    client, welcome, _ = srv.couple(run["id"])
    z = np.zeros(welcome.n_nodes)
    t, ends = 0.0, []
    for t1 in (0.2 - 0.15, 0.05 + welcome.window_max * (1 + 5e-10), 0.15, 0.2 * (1 + 5e-10)):
        r = client.request(Set(t + 5e-10 if t else t, t1, z, z, z), Solve(), expect=Result)
        ends.append(r.t)
        assert r.t == t1  # bit for bit
        t = r.t
    assert ends[0] == 0.05000000000000002 and ends[-1] > 0.2
    bye(client)


@pytest.mark.parametrize("offer, echoed", [(["wavesph"], "wavesph"), (None, None)])
def test_ws_subprotocol_and_close_code_1000_after_bye(srv, offer, echoed):
    run = srv.create()
    srv.wait_state(run["id"], "waiting_for_client")
    with ws_connect(f"ws://127.0.0.1:{srv.port}/runs/{run['id']}/couple", subprotocols=offer) as ws:
        assert ws.subprotocol == echoed
        ws.send(encode_frame(Hello(0, bytes(32), "", "pytest"), 1))
        assert isinstance(decode_frame(ws.recv(timeout=10))[1], Welcome)
        ws.send(encode_frame(GetNodes(), 2))
        ws.recv(timeout=10)
        ws.send(encode_frame(Bye(""), 3))
        assert decode_frame(ws.recv(timeout=10))[0] == 3  # BYE with the same seq
        with pytest.raises(ConnectionClosed):
            ws.recv(timeout=10)
        assert ws.protocol.close_rcvd is not None and ws.protocol.close_rcvd.code == 1000


def test_ws_close_code_1000_after_a_server_error(srv):
    with ws_connect(f"ws://127.0.0.1:{srv.port}/runs/nope/couple") as ws:
        ws.send(encode_frame(GetNodes(), 1))
        seq, err = decode_frame(ws.recv(timeout=10))
        assert (err.code, seq) == (ErrorCode.OUT_OF_ORDER, 1)
        with pytest.raises(ConnectionClosed):
            ws.recv(timeout=10)
        assert ws.protocol.close_rcvd.code == 1000


def test_ws_without_the_token_is_refused_403_in_the_handshake(tmp_path, factory):
    from websockets.exceptions import InvalidStatus

    from server_harness import live_server

    with live_server(tmp_path, factory, token="s3cret-token-for-tests") as s:
        with pytest.raises(InvalidStatus) as exc:
            ws_connect(f"ws://127.0.0.1:{s.port}/runs/x/couple", open_timeout=10)
        assert exc.value.response.status_code == 403


def test_the_node_column_spans_bed_to_tank_top_at_most_dp_over_2_apart():
    """NODES: each end's column starts at the tank floor (z = -depth) and ends at the tank top,
    evenly spaced at most dp/2; the boundary gauge is 2h inside the face by default."""
    from sph_core.open_ends import flume_nodes
    from sph_core.scene import Scene

    from server_harness import open_flume

    sc = Scene.model_validate(open_flume("f", 1.0, 0.3))
    for side, nodes in flume_nodes(sc).items():
        z = nodes.z
        assert z[0] == sc.tank.z0 and z[-1] == sc.tank.z1
        assert np.allclose(np.diff(z), np.diff(z)[0]) and np.diff(z)[0] <= 0.5 * sc.dp
        assert abs(nodes.x_gauge - nodes.x_face) == pytest.approx(2 * sc.h)


def test_a_window_the_solver_refuses_is_answered_with_the_solves_seq(tmp_path):
    """SET's surface check is made by the solver (FlumeEngine raises BAD_VALUE "SET: ..." at
    solve time): the ERROR carries the SOLVE's seq, not the SET's."""
    from protocol import ProtocolError

    from server_harness import live_server
    from sph_engine_double import EngineDouble

    class SurfaceChecked(EngineDouble):
        def solve_window(self):
            if self.pending[2]["eta"].mean() > 0.1:
                self.pending = None
                raise ProtocolError(ErrorCode.BAD_VALUE, "SET: the surface is above the tank top")
            return super().solve_window()

    with live_server(tmp_path, lambda r, d: SurfaceChecked(r)) as srv:
        run = srv.create()
        client, welcome, _ = srv.couple(run["id"])          # HELLO 1, GETNODES 2
        z, high = np.zeros(welcome.n_nodes), np.full(welcome.n_nodes, 0.5)
        client.send_raw(encode_frame(Set(0.0, 0.05, z, z, high), 3) + encode_frame(Solve(), 4))
        seq, err = _error(client)
        assert (err.code, seq) == (ErrorCode.BAD_VALUE, 4) and "surface" in err.text
        assert srv.wait_state(run["id"], "failed")["status"].startswith("failed: protocol error")
