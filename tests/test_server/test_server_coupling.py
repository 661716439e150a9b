"""Coupling doors of the real server (TCP and WebSocket) against the engine test double."""

from __future__ import annotations

import hashlib
import json
import socket
import struct

import numpy as np
import pytest

from protocol import (ErrorCode, GoBack, Hello, RemoteError, Result, Set,
                      Solve, scene_hash)
from protocol.wire import HEADER, MAGIC, MessageType

from server_harness import live_server, wait_until
from coupling_client import TcpClient, WsClient, bye, handshake, run_windows


def _clients(srv, run_id):
    return {"tcp": lambda: TcpClient(srv.tcp_port),
            "ws": lambda: WsClient(f"ws://127.0.0.1:{srv.port}/runs/{run_id}/couple")}


@pytest.mark.parametrize("door", ["tcp", "ws"])
def test_coupled_run_end_to_end(srv, engines, door):
    run = srv.create()
    srv.wait_state(run["id"], "waiting_for_client")
    client = _clients(srv, run["id"])[door]()
    scene_bytes = srv.http.get(f"/runs/{run['id']}/scene").content
    assert hashlib.sha256(scene_bytes).hexdigest() == run["scene_hash"]
    welcome, nodes = handshake(client, run["id"], scene_hash=hashlib.sha256(scene_bytes).digest())
    assert welcome.run_id == run["id"] and welcome.scene_hash.hex() == run["scene_hash"]
    assert welcome.depth == pytest.approx(0.3) and welcome.still_water_level == pytest.approx(0.3)
    assert welcome.n_gauges == 2 and list(nodes.gauge_x) == [0.5, 0.9]
    assert srv.http.get(f"/runs/{run['id']}").json()["state"] == "running"
    results = run_windows(client, welcome, nodes, 4)
    for k, res in enumerate(results):
        assert res.t == pytest.approx(0.05 * (k + 1)) and res.steps == 50
        assert res.eta[0] == pytest.approx(0.01 * (k + 1)) and res.wet.tolist() == [1, 0]
        assert res.eta[1] == 0.0  # dry gauge: zero on the wire, flagged by wet
    bye(client)
    info = srv.wait_state(run["id"], "finished")
    assert info["status"] == "finished" and info["windows"] == 4 and info["steps"] == 200
    assert info["t"] == pytest.approx(0.2) and info["client"] == "pytest"
    assert 0.0 <= info["coupling_overhead_share"] <= 1.0 and info["particle_steps_per_s"] > 0
    assert info["last_gauges"]["g_mid_eta"] == pytest.approx(0.04)
    assert info["last_gauges"]["dry_g_eta"] is None
    # linear interpolation in time inside each window, from the values in force at t0
    t, u, eta = np.array(engines[0].imposed).T
    assert t.size == 200
    np.testing.assert_allclose(eta[:50], 0.01 * np.arange(1, 51) / 50)
    np.testing.assert_allclose(eta[50:100], 0.01 + 0.01 * np.arange(1, 51) / 50)
    csv = srv.http.get(f"/runs/{run['id']}/gauges").text.splitlines()
    assert csv[0] == "t,steps,g_mid_eta,g_mid_u_ref,g_mid_w_ref,dry_g_eta,dry_g_u_ref,dry_g_w_ref"
    assert len(csv) == 5 and csv[1].split(",")[5] == ""   # dry: an empty field, not a word
    data = srv.http.get(f"/runs/{run['id']}/gauges", params={"format": "json"}).json()
    assert [r["g_mid_eta"] for r in data["rows"]] == pytest.approx([0.01, 0.02, 0.03, 0.04])
    # the run reads finished before its task closes the engine (ux.md F30: a race under load)
    wait_until(lambda: engines[0].closed, "the engine is closed after the run finished")


def test_goback_redoes_the_last_window_and_its_gauge_row(srv, engines):
    run = srv.create()
    client, welcome, nodes = srv.couple(run["id"])
    run_windows(client, welcome, nodes, 2)
    back = client.request(GoBack(), expect=Result)
    assert back.t == pytest.approx(0.05) and back.eta[0] == pytest.approx(0.01)
    redo = run_windows(client, welcome, nodes, 1, t0=0.05, amplitude=0.5)
    assert redo[0].eta[0] == pytest.approx(0.5)
    bye(client)
    srv.wait_state(run["id"], "finished")
    rows = srv.http.get(f"/runs/{run['id']}/gauges", params={"format": "json"}).json()["rows"]
    assert [r["g_mid_eta"] for r in rows] == pytest.approx([0.01, 0.5])
    assert engines[0].steps == 100


@pytest.mark.parametrize("door", ["tcp", "ws"])
def test_vanished_client_fails_the_run_and_keeps_its_data(srv, door):
    run = srv.create()
    srv.wait_state(run["id"], "waiting_for_client")
    client = _clients(srv, run["id"])[door]()
    welcome, nodes = handshake(client, run["id"])
    run_windows(client, welcome, nodes, 3)
    client.close()
    info = srv.wait_state(run["id"], "failed")
    assert info["status"] == "failed: client disconnected" and info["windows"] == 3
    run_dir = srv.settings.runs_dir / run["id"]
    assert json.loads((run_dir / "meta.json").read_text())["status"] == "failed: client disconnected"
    assert len((run_dir / "gauges.csv").read_text().splitlines()) == 4  # header + 3 windows


def _expect_error(client, code: ErrorCode) -> str:
    with pytest.raises(RemoteError) as exc:
        client.session.reply(*client.recv(), expect=Result)
    assert exc.value.code is code, exc.value
    assert client.closed_by_server()
    return exc.value.text


def test_bad_input_on_the_tcp_door_gets_a_clear_error_and_the_server_keeps_serving(srv):
    run = srv.create()
    srv.wait_state(run["id"], "waiting_for_client")
    # 1. garbage instead of a frame
    c = TcpClient(srv.tcp_port)
    c.send_raw(b"GET / HTTP/1.1\r\n\r\n")
    assert "magic" in _expect_error(c, ErrorCode.MALFORMED)
    # 2. a future protocol version
    c = TcpClient(srv.tcp_port)
    c.send_raw(HEADER.pack(MAGIC, 2, MessageType.HELLO, 1, 0))
    assert "version 2" in _expect_error(c, ErrorCode.UNSUPPORTED_VERSION)
    # 3. a run that does not exist
    c = TcpClient(srv.tcp_port)
    c.request(Hello(0, bytes(32), "nope"))
    assert "no run 'nope'" in _expect_error(c, ErrorCode.NOT_FOUND)
    # 4. a scene the client did not expect: refused, and the run keeps waiting (issue 15: the
    #    spec says the server refuses the client, not that the run fails)
    c = TcpClient(srv.tcp_port)
    c.request(Hello(0, scene_hash(b"another scene"), run["id"]))
    assert "keeps waiting" in _expect_error(c, ErrorCode.SCENE_MISMATCH)
    assert srv.http.get(f"/runs/{run['id']}").json()["state"] == "waiting_for_client"
    # the server still serves: the run's own client couples fine, and so does a new run's
    c = TcpClient(srv.tcp_port)
    welcome, nodes = handshake(c, run["id"], scene_hash=bytes.fromhex(run["scene_hash"]))
    run_windows(c, welcome, nodes, 1)
    bye(c)
    srv.wait_state(run["id"], "finished")
    run2 = srv.create()
    c, welcome, nodes = srv.couple(run2["id"])
    run_windows(c, welcome, nodes, 1)
    bye(c)
    srv.wait_state(run2["id"], "finished")


def test_nan_array_and_wrong_shape_are_refused_naming_the_field(srv):
    run = srv.create()
    c, welcome, nodes = srv.couple(run["id"])
    n = welcome.n_nodes
    good = c.session.request(Set(0.0, 0.05, np.arange(n, dtype=float), np.zeros(n), np.zeros(n)))
    c.send_raw(good.replace(struct.pack("<d", 1.0), struct.pack("<d", float("nan"))))  # u[1]
    assert "SET.u[1]" in _expect_error(c, ErrorCode.BAD_VALUE)
    info = srv.wait_state(run["id"], "failed")
    assert "SET.u[1]" in info["status"]

    run = srv.create()
    c, welcome, nodes = srv.couple(run["id"])
    c.request(Set(0.0, 0.05, np.ones(n + 1), np.zeros(n + 1), np.zeros(n + 1)))
    assert f"SET.u has {n + 1} values" in _expect_error(c, ErrorCode.SHAPE_MISMATCH)


def test_oversized_frame_is_refused_from_its_header(srv):
    run = srv.create()
    c, _, _ = srv.couple(run["id"])
    c.send_raw(HEADER.pack(MAGIC, 1, MessageType.SET, 3, 10**8))  # announces 100 MB, sends none
    _expect_error(c, ErrorCode.FRAME_TOO_LARGE)


def test_websocket_text_message_and_second_client(srv):
    run = srv.create()
    srv.wait_state(run["id"], "waiting_for_client")
    url = f"ws://127.0.0.1:{srv.port}/runs/{run['id']}/couple"
    first = WsClient(url)
    handshake(first, run["id"])
    second = WsClient(url)
    second.request(Hello(0, bytes(32), "", "intruder"))
    with pytest.raises(RemoteError, match="already has a coupling client"):
        second.session.reply(*second.recv(), expect=Result)
    first.ws.send("hello as text")
    with pytest.raises(RemoteError, match="binary") as exc:
        first.session.reply(*first.recv(), expect=Result)
    assert exc.value.code is ErrorCode.MALFORMED


def test_silent_client_times_out(tmp_path, factory):
    with live_server(tmp_path, factory, idle_timeout=0.5, hello_timeout=0.5) as srv:
        run = srv.create()
        c, _, _ = srv.couple(run["id"])
        assert "no frame for 0.5 s" in _expect_error(c, ErrorCode.TIMEOUT)
        info = srv.wait_state(run["id"], "failed")
        assert info["status"] == "failed: client timed out (silent for 0.5 s)"
        silent = TcpClient(srv.tcp_port)  # connects, never says HELLO
        assert "no HELLO" in _expect_error(silent, ErrorCode.TIMEOUT)


def test_unstable_engine_is_reported_to_client_and_in_the_status(tmp_path, factory):
    with live_server(tmp_path, lambda r, d: factory(r, d, unstable_after=0.12)) as srv:
        run = srv.create()
        c, welcome, nodes = srv.couple(run["id"])
        run_windows(c, welcome, nodes, 2)
        n = welcome.n_nodes
        c.request(Set(0.1, 0.15, np.zeros(n), np.zeros(n), np.zeros(n)), Solve())
        assert "density out of band" in _expect_error(c, ErrorCode.ENGINE_FAILED)
        info = srv.wait_state(run["id"], "unstable")
        assert info["status"].startswith("unstable at step 150")  # issue 15: not "unstable: unstable"
        assert info["stability"]["unstable_step"] == 150 and info["windows"] == 2


def test_cancel_during_coupling_sends_cancelled(srv):
    run = srv.create()
    c, welcome, nodes = srv.couple(run["id"])
    run_windows(c, welcome, nodes, 1)
    info = srv.http.delete(f"/runs/{run['id']}").json()
    assert info["status"] == "cancelled"
    assert "cancelled" in _expect_error(c, ErrorCode.CANCELLED)
    assert len(srv.http.get(f"/runs/{run['id']}/gauges").text.splitlines()) == 2


def test_client_vanishing_during_a_solve_keeps_that_window(tmp_path, factory):
    with live_server(tmp_path, lambda r, d: factory(r, d, solve_delay=0.5)) as srv:
        run = srv.create()
        c, welcome, nodes = srv.couple(run["id"])
        n = welcome.n_nodes
        c.request(Set(0.0, 0.05, np.ones(n), np.zeros(n), np.ones(n)), Solve())
        c.sock.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
        c.close()  # reset while the engine is busy
        info = srv.wait_state(run["id"], "failed")
        assert info["status"] == "failed: client disconnected"
        rows = srv.http.get(f"/runs/{run['id']}/gauges", params={"format": "json"}).json()["rows"]
        assert len(rows) == 1 and info["windows"] == 1  # the solved window was written first


def test_scene_too_big_for_the_frame_cap_fails_clearly(tmp_path, factory):
    with live_server(tmp_path, factory, max_frame=4104) as srv:
        run = srv.create(dp=0.001)  # 300 nodes: a SET of 7228 bytes
        info = srv.wait_state(run["id"], "failed")
        assert "above the server's max_frame 4104" in info["status"]


def test_concurrent_runs_one_bad_client_does_not_disturb_the_other(srv):
    import threading

    good, bad = srv.create(), srv.create()
    srv.wait_state(good["id"], "waiting_for_client")
    srv.wait_state(bad["id"], "waiting_for_client")
    errors: list[BaseException] = []

    def couple_well() -> None:
        try:
            c = WsClient(f"ws://127.0.0.1:{srv.port}/runs/{good['id']}/couple")
            welcome, nodes = handshake(c, good["id"])
            run_windows(c, welcome, nodes, 10)
            bye(c)
        except BaseException as exc:  # noqa: BLE001 -- reported below
            errors.append(exc)

    thread = threading.Thread(target=couple_well)
    thread.start()
    c = TcpClient(srv.tcp_port)
    welcome, nodes = handshake(c, bad["id"])
    c.send_raw(b"\x00" * 64)  # garbage mid-session
    _expect_error(c, ErrorCode.MALFORMED)
    thread.join(timeout=30)
    assert not errors, errors
    assert srv.wait_state(good["id"], "finished")["windows"] == 10
    assert srv.wait_state(bad["id"], "failed")["status"].startswith("failed: protocol error: MALFORMED")


def test_a_run_whose_client_vanished_resumes_from_its_last_window(srv, engines):
    run = srv.create()
    assert srv.http.post(f"/runs/{run['id']}/resume").status_code == 409  # nothing to resume yet
    c, welcome, nodes = srv.couple(run["id"])
    run_windows(c, welcome, nodes, 3)
    c.close()
    info = srv.wait_state(run["id"], "failed")
    assert info["resumable"] and info["status"] == "failed: client disconnected"
    r = srv.http.post(f"/runs/{run['id']}/resume")
    assert r.status_code == 202 and r.json()["resumed"] == 1
    info = srv.wait_state(run["id"], "waiting_for_client")
    assert info["t"] == pytest.approx(0.15) and info["windows"] == 3
    c = WsClient(f"ws://127.0.0.1:{srv.port}/runs/{run['id']}/couple")
    welcome, nodes = handshake(c, run["id"])
    assert welcome.t_start == pytest.approx(0.15)
    results = run_windows(c, welcome, nodes, 2, t0=0.15, amplitude=0.1)
    assert results[-1].t == pytest.approx(0.25)
    bye(c)
    info = srv.wait_state(run["id"], "finished")
    assert info["windows"] == 5 and info["steps"] == 250 and not info["resumable"]
    # the resumed engine started from the saved boundary values (eta = 0.03 in force at 0.15)
    _, _, eta = np.array(engines[1].imposed).T
    np.testing.assert_allclose(eta[:50], 0.03 + (0.1 - 0.03) * np.arange(1, 51) / 50)
    rows = srv.http.get(f"/runs/{run['id']}/gauges", params={"format": "json"}).json()["rows"]
    assert [r["t"] for r in rows] == pytest.approx([0.05, 0.1, 0.15, 0.2, 0.25])


@pytest.mark.parametrize("door", ["tcp", "ws"])
def test_gauge_info_for_a_1_1_client_and_none_for_a_1_0_one(srv, door):
    from protocol import Capability, Gauges, GetGauges, GetNodes, Nodes, Welcome

    run = srv.create()
    srv.wait_state(run["id"], "waiting_for_client")
    c = _clients(srv, run["id"])[door]()
    caps = Capability.GOBACK | Capability.GAUGE_INFO
    welcome = c.request(Hello(caps, bytes(32), run["id"], "pytest 1.1"), expect=Welcome)
    assert welcome.capabilities == caps
    nodes = c.request(GetNodes(), expect=Nodes)
    gauges = c.request(GetGauges(), expect=Gauges)
    assert gauges.names == ["g_mid", "dry_g"] and len(gauges.names) == nodes.gauge_x.size
    run_windows(c, welcome, nodes, 1)
    bye(c)
    # a 1.0 client: the capability is not granted, everything else as before
    run2 = srv.create()
    srv.wait_state(run2["id"], "waiting_for_client")
    c = _clients(srv, run2["id"])[door]()
    welcome, nodes = handshake(c, run2["id"])
    assert welcome.capabilities == Capability.GOBACK
    run_windows(c, welcome, nodes, 1)
    bye(c)
