"""Reliability defects of the server (docs: the reliability review), one reproducing case each.
Real servers on 127.0.0.1 with the engine double; every wait polls with a deadline."""

from __future__ import annotations

import errno
import json

import httpx
import pytest

from server_harness import live_server, scene, wait_until


def _coupled_body(**overrides) -> dict:
    return {"scene": scene(open_boundaries=[{"side": "left"}], **overrides), "mode": "coupled"}


def _enospc(*args, **kwargs):
    raise OSError(errno.ENOSPC, "No space left on device")


# tiny wave period: a 422, not a 500 -------------------------------------------------------------
def test_tiny_source_period_is_a_422(srv):
    body = {**_coupled_body(), "mode": "standalone",
            "source": {"theory": "stokes", "H": 0.04, "T": 1e-9, "order": 2}}
    r = srv.http.post("/runs", json=body)
    assert r.status_code == 422, r.text
    assert r.json()["detail"][0]["loc"][:2] == ["body", "source"]


# a 404 never echoes a huge id ------------------------------------------------------------------
def test_404_does_not_echo_a_long_run_id(srv):
    r = srv.http.get("/runs/" + "a" * 10_000)
    assert r.status_code == 404 and len(r.content) < 300


def test_upper_case_token_in_a_url_is_redacted():
    from server.deps import redact_tokens

    assert redact_tokens("GET /runs/x/couple?TOKEN=s3cr3t-0123456789&a=1") == \
        "GET /runs/x/couple?TOKEN=***&a=1"


# the store follows no symbolic link; a directory in place of gauges.csv is a 404 ---------------
def test_store_skips_a_symlinked_run_dir_and_serves_no_directory_as_gauges(tmp_path, factory):
    with live_server(tmp_path, factory) as srv:
        run = srv.create()
        srv.wait_state(run["id"], "waiting_for_client")
    runs = tmp_path / "runs"
    outside = tmp_path / "outside"
    (runs / run["id"]).rename(outside)
    (runs / run["id"]).symlink_to(outside, target_is_directory=True)
    before = (outside / "meta.json").read_text()
    with live_server(tmp_path, factory) as srv:
        assert srv.http.get("/runs").json() == []
    assert (outside / "meta.json").read_text() == before  # nothing written through the link
    (runs / run["id"]).unlink()
    outside.rename(runs / run["id"])
    (runs / run["id"] / "gauges.csv").unlink(missing_ok=True)
    (runs / run["id"] / "gauges.csv").mkdir()
    with live_server(tmp_path, factory) as srv:
        r = srv.http.get(f"/runs/{run['id']}/gauges")
        assert r.status_code == 404, r.text


# a full disk: the run ends, its slot comes back, no .tmp is left --------------------------------
def test_full_disk_at_the_end_of_a_session_ends_the_run_and_frees_its_slot(tmp_path, factory,
                                                                           monkeypatch):
    import server.store as store
    from coupling_client import bye, run_windows

    real = store.write_json_atomic
    with live_server(tmp_path, factory, max_runs=1) as srv:
        run = srv.create()
        c, welcome, nodes = srv.couple(run["id"])
        run_windows(c, welcome, nodes, 2)
        monkeypatch.setattr(store, "write_json_atomic", _enospc)  # meta.json cannot be written
        bye(c)
        assert srv.wait_state(run["id"], "finished", timeout=10)["state"] == "finished"
        wait_until(lambda: not srv.manager.active, "the stepping slot is released", 10)
        monkeypatch.setattr(store, "write_json_atomic", real)  # space freed
        second = srv.create()
        c, welcome, nodes = srv.couple(second["id"])  # the one slot is free again
        run_windows(c, welcome, nodes, 1)
        bye(c)
        srv.wait_state(second["id"], "finished")
        wait_until(lambda: json.loads((tmp_path / "runs" / run["id"] / "meta.json").read_text())
                   ["state"] == "finished", "the first run's record caught up once space was free")
    assert not list((tmp_path / "runs").rglob("*.tmp"))


def test_full_disk_while_writing_gauges_fails_the_run_and_frees_its_slot(tmp_path, factory,
                                                                        monkeypatch):
    import server.store as store
    from coupling_client import run_windows

    with live_server(tmp_path, factory, max_runs=1) as srv:
        run = srv.create()
        c, welcome, nodes = srv.couple(run["id"])
        run_windows(c, welcome, nodes, 1)
        monkeypatch.setattr(store.GaugeWriter, "row", _enospc)
        monkeypatch.setattr(store, "write_json_atomic", _enospc)
        with pytest.raises(Exception):
            run_windows(c, welcome, nodes, 1, t0=0.05)
        info = srv.wait_state(run["id"], "failed", timeout=10)
        assert "No space left" in info["status"]
        wait_until(lambda: not srv.manager.active, "the stepping slot is released", 10)
        c.close()


def test_atomic_writes_leave_no_tmp_file_on_a_full_disk(tmp_path, monkeypatch):
    import os
    import pathlib

    from server.store import write_text_atomic
    from sph_core.checkpoint_file import save_checkpoint
    from sph_core.output import write_json_atomic

    real_write = pathlib.Path.write_text

    def half_then_full(self, text, *a, **kw):  # some bytes land, then the disk is full
        real_write(self, text[: len(text) // 2], *a, **kw)
        _enospc()

    monkeypatch.setattr(pathlib.Path, "write_text", half_then_full)
    for write in (write_json_atomic, write_text_atomic):
        with pytest.raises(OSError):
            write(tmp_path / "meta.json", {"a": 1} if write is write_json_atomic else "x" * 100)
    monkeypatch.setattr(os, "fsync", _enospc)
    with pytest.raises(OSError):
        save_checkpoint(tmp_path / "state.npz", {"t": 1.0})
    assert list(tmp_path.iterdir()) == []


# one server per run store ----------------------------------------------------------------------
def test_second_server_on_one_runs_dir_is_refused_with_one_line(tmp_path, factory):
    import argparse

    from server.store import RunStore, StoreLocked, store_in_use
    from wavesph.cli import serve

    with live_server(tmp_path, factory) as srv:
        run = srv.create()
        srv.wait_state(run["id"], "waiting_for_client")
        with pytest.raises(StoreLocked, match="in use by another wavesph server"):
            RunStore(tmp_path / "runs")
        reason = store_in_use(tmp_path / "runs")
        assert reason and "\n" not in reason and "--runs-dir" in reason
        args = argparse.Namespace(host=None, port=0, tcp_port=0, runs_dir=tmp_path / "runs",
                                  max_runs=None, max_particles=None, token=None, device=None)
        assert serve.main(args) == 1  # refused before it binds or touches a run
        assert srv.http.get(f"/runs/{run['id']}").json()["state"] == "waiting_for_client"
    assert store_in_use(tmp_path / "runs") is None  # released when the server stopped
    with live_server(tmp_path, factory) as srv:
        assert [r["id"] for r in srv.http.get("/runs").json()] == [run["id"]]


# output intervals are bounded; a DELETE reaches inside a window that does not end ---------------
@pytest.mark.parametrize("output", [{"probe_every": 1e-300}, {"snapshot_every": 1e-300}])
def test_output_interval_below_any_step_is_a_422(srv, output):
    r = srv.http.post("/runs", json=_coupled_body(output=output))
    assert r.status_code == 422, r.text
    assert next(iter(output)) in r.text and "outputs" in r.text


def test_delete_ends_a_window_that_never_ends(tmp_path, factory):
    import threading

    import numpy as np

    from protocol import Error, ErrorCode, Set, Solve

    gate = threading.Event()  # never opened: the window would take for ever
    with live_server(tmp_path, lambda r, d: factory(r, d, gate=gate, honours_cancel=True),
                     max_runs=1) as srv:
        run = srv.create()
        c, welcome, nodes = srv.couple(run["id"])
        n = welcome.n_nodes
        c.request(Set(0.0, 0.05, np.zeros(n), np.zeros(n), np.zeros(n)), Solve())
        wait_until(lambda: srv.http.get(f"/runs/{run['id']}").json()["state"] == "running",
                   "the window is being solved", 10)
        assert srv.http.delete(f"/runs/{run['id']}").status_code == 200
        info = srv.wait_state(run["id"], "cancelled", timeout=10)
        assert info["windows"] == 0
        while True:  # WORKING frames may come first
            seq, msg = c.recv()
            if isinstance(msg, Error):
                break
        assert msg.code == ErrorCode.CANCELLED
        wait_until(lambda: not srv.manager.active, "the stepping slot is released", 10)
        c.close()


# clientless coupled runs cannot deny service ---------------------------------------------------
def test_queued_run_without_a_client_expires_while_the_waiting_places_are_taken(tmp_path, factory):
    import threading

    building = threading.Event()  # the first run's build is held: it keeps the one waiting place

    def slow_first(request, run_dir):
        if not building.is_set():
            building.set()
            release.wait(30)
        return factory(request, run_dir)

    release = threading.Event()
    with live_server(tmp_path, slow_first, max_waiting=1, client_wait_timeout=0.3) as srv:
        try:
            first = srv.create()
            queued = srv.create()
            assert building.wait(10)
            info = srv.wait_state(queued["id"], "failed", timeout=10)
            assert "no client connected within 0.3 s" in info["status"]
            assert srv.http.get(f"/runs/{first['id']}").json()["state"] == "queued"  # still building
        finally:
            release.set()
        srv.wait_state(first["id"], "failed", timeout=10)  # it had no client either


def test_standalone_posts_are_not_refused_for_a_queue_of_clientless_runs(tmp_path, factory,
                                                                         monkeypatch):
    from server.run_manager import RunManager

    monkeypatch.setattr(RunManager, "_step_standalone", lambda self, run: None)  # no SPH here
    with live_server(tmp_path, factory, max_waiting=1, max_queued=1) as srv:
        srv.wait_state(srv.create()["id"], "waiting_for_client")
        srv.create()  # queued: the coupled queue is full now
        assert srv.http.post("/runs", json=_coupled_body()).status_code == 429
        standalone = srv.http.post("/runs", json={"scene": scene(t_end=0.05), "mode": "standalone"})
        assert standalone.status_code == 201, standalone.text


def test_resume_goes_ahead_of_strangers_clientless_runs(tmp_path, factory):
    from coupling_client import run_windows

    with live_server(tmp_path, factory, max_waiting=1, max_queued=1) as srv:
        mine = srv.create()
        c, welcome, nodes = srv.couple(mine["id"])
        run_windows(c, welcome, nodes, 2)
        c.close()  # gone without BYE: failed, resumable
        assert srv.wait_state(mine["id"], "failed")["resumable"]
        srv.wait_state(srv.create()["id"], "waiting_for_client")  # strangers: the waiting place
        srv.create()                                              # and the queue, full
        r = srv.http.post(f"/runs/{mine['id']}/resume")
        assert r.status_code == 202, r.text
        c, welcome, nodes = srv.couple(mine["id"])  # built at once, not behind the strangers
        assert welcome.t_start == pytest.approx(0.1)
        c.close()


# a 413 reaches a client that writes the whole body before it reads ------------------------------
def test_413_reaches_urllib_which_sends_the_whole_body_first(tmp_path, factory):
    import urllib.error
    import urllib.request

    with live_server(tmp_path, factory, max_body=1024 * 1024) as srv:
        body = b'{"a": "' + b"x" * 20_000_000 + b'"}'  # more than the socket buffers hold
        req = urllib.request.Request(srv.url + "/runs", data=body,
                                     headers={"Content-Type": "application/json"})
        with pytest.raises(urllib.error.HTTPError) as exc:
            urllib.request.urlopen(req, timeout=30)
        assert exc.value.code == 413 and b"max_body" in exc.value.read()
        assert srv.http.get("/runs").status_code == 200  # and the server serves on


# finite but absurd values: a 422 before the run exists, not a 201 and a failed run ---------------
@pytest.mark.parametrize("overrides, loc", [
    ({"constants": {"c0": 1e300}}, ["body", "scene", "constants", "c0"]),
    ({"constants": {"c0": 1e-300}}, ["body", "scene", "constants", "c0"]),
    ({"beds": [{"points": [[0.05, 0.0], [0.9, 0.2]]}]}, ["body", "scene", "beds", 0]),
])
def test_absurd_finite_values_are_a_422(srv, overrides, loc):
    r = srv.http.post("/runs", json=_coupled_body(**overrides))
    assert r.status_code == 422, r.text
    assert r.json()["detail"][0]["loc"] == loc
    assert srv.http.get("/runs").json() == []


# a loopback server refuses what a foreign web page can send (CSRF, DNS rebinding) --------------
def test_loopback_server_refuses_foreign_pages_and_hosts(srv):
    body = json.dumps(_coupled_body())
    r = srv.http.post("/runs", content=body, headers={"content-type": "text/plain"})
    assert r.status_code == 415  # a "simple" request no browser preflights
    r = srv.http.post("/runs", content=body, headers={"content-type": "application/json",
                                                      "origin": "http://evil.example"})
    assert r.status_code == 403
    assert srv.http.get("/runs", headers={"host": "evil.example"}).status_code == 421
    assert srv.http.get("/runs", headers={"host": f"localhost:{srv.port}"}).status_code == 200
    own = srv.http.post("/runs", content=body, headers={"content-type": "application/json",
                                                        "origin": srv.url})  # its own page
    assert own.status_code == 201, own.text
    assert len(srv.http.get("/runs").json()) == 1


def test_websocket_door_refuses_a_foreign_origin(srv):
    from websockets.exceptions import InvalidStatus
    from websockets.sync.client import connect

    run = srv.create()
    url = f"ws://127.0.0.1:{srv.port}/runs/{run['id']}/couple"
    with pytest.raises(InvalidStatus) as exc:
        with connect(url, origin="http://evil.example", open_timeout=10):
            pass
    assert exc.value.response.status_code == 403
    with connect(url, origin=srv.url, open_timeout=10):  # the server's own page may
        pass


# the WebSocket door holds no 16 MiB message from a client that has not said HELLO ---------------
def test_websocket_door_refuses_a_big_message_before_hello_at_its_header(srv):
    from websockets.exceptions import ConnectionClosed
    from websockets.sync.client import connect

    from protocol import Result
    from coupling_client import WsClient, handshake, run_windows

    run = srv.create(dp=0.0005)  # 600 boundary nodes: a SET frame of 14 kB, over a HELLO's 8 kB
    url = f"ws://127.0.0.1:{srv.port}/runs/{run['id']}/couple"
    with connect(url, open_timeout=10, max_size=None) as ws:
        # only the header of a binary frame that announces 1 MB (far over a HELLO) and its first
        # bytes: the door must refuse on the header; sending the whole megabyte raced the
        # server's close (a broken pipe before the close frame was read, under load)
        ws.socket.sendall(b"\x82\xff" + (1_000_004).to_bytes(8, "big") + bytes(4) + b"WSPH")
        with pytest.raises(ConnectionClosed) as exc:
            ws.recv(timeout=10)
    assert exc.value.rcvd is not None and exc.value.rcvd.code == 1009  # message too big
    srv.wait_state(run["id"], "waiting_for_client")
    c = WsClient(url)  # after HELLO, a session's frames up to max_frame pass
    welcome, nodes = handshake(c, run["id"])
    assert welcome.n_nodes == 600
    assert isinstance(run_windows(c, welcome, nodes, 1)[0], Result)
    c.close()


# an HTTP request head that never ends is cut (slowloris) ----------------------------------------
def test_incomplete_request_head_is_closed_after_header_timeout(tmp_path, factory):
    import socket
    import time

    from coupling_client import WsClient, handshake, run_windows

    with live_server(tmp_path, factory, header_timeout=0.5) as srv:
        run = srv.create()
        srv.wait_state(run["id"], "waiting_for_client")
        ws = WsClient(f"ws://127.0.0.1:{srv.port}/runs/{run['id']}/couple")
        welcome, nodes = handshake(ws, run["id"])
        slow = socket.create_connection(("127.0.0.1", srv.port), timeout=10)
        slow.sendall(b"GET /runs HTTP/1.1\r\nHost: 127.0.0.1\r\nX-a: ")
        deadline = time.monotonic() + 10
        while True:  # one more header byte now and then, as a slowloris client does
            try:
                slow.sendall(b"a")
                slow.settimeout(0.2)
                if slow.recv(1) == b"":
                    break
            except socket.timeout:
                pass
            except OSError:
                break
            assert time.monotonic() < deadline, "the incomplete request was never closed"
        slow.close()
        # served requests and an upgraded WebSocket outlive the header timeout; the request goes
        # on a new connection: the pooled one sat idle past the timeout too, and the server may
        # be closing it just as it is reused (the keep-alive race any client meets; CI saw the reset)
        with httpx.Client(base_url=f"http://127.0.0.1:{srv.port}", timeout=10) as fresh:
            assert fresh.get("/runs").status_code == 200
        run_windows(ws, welcome, nodes, 1)
        ws.close()


def test_delete_while_the_engine_is_built_is_cancelled_at_once(tmp_path, factory, engines):
    import threading

    building, release = threading.Event(), threading.Event()

    def slow(request, run_dir):
        building.set()
        release.wait(30)
        return factory(request, run_dir)

    with live_server(tmp_path, slow) as srv:
        try:
            run = srv.create()
            assert building.wait(10)
            assert srv.http.delete(f"/runs/{run['id']}").json()["state"] == "cancelled"
        finally:
            release.set()
        wait_until(lambda: engines and engines[0].closed, "the late engine is closed", 10)
        wait_until(lambda: not srv.manager.waiting, "the waiting place is free", 10)
        assert srv.http.get(f"/runs/{run['id']}").json()["state"] == "cancelled"  # and stays so


def test_client_gone_during_a_window_that_never_ends_stops_the_window(tmp_path, factory, engines):
    import threading

    import numpy as np

    from protocol import Capability, Set, Solve

    gate = threading.Event()  # never opened: the window would take for ever
    with live_server(tmp_path, lambda r, d: factory(r, d, gate=gate, honours_cancel=True),
                     max_runs=1, keepalive_every=0.05) as srv:
        run = srv.create()
        c, welcome, nodes = srv.couple(run["id"], caps=int(Capability.KEEPALIVE))
        n = welcome.n_nodes
        c.request(Set(0.0, 0.05, np.zeros(n), np.zeros(n), np.zeros(n)), Solve())
        c.recv()  # a WORKING frame: the window is being solved
        c.close()  # the client vanishes mid-window
        info = srv.wait_state(run["id"], "failed", timeout=10)
        assert info["status"] == "failed: client disconnected"
        wait_until(lambda: engines[0].cancelled_solves == 1, "the window stopped", 10)
        wait_until(lambda: engines[0].closed and not srv.manager.active, "the slot is free", 10)
