"""HTTP run management: validation, caps, queueing, standalone runs, events, restart, auth."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest
from fastapi.testclient import TestClient
from pydantic import ValidationError

from protocol import ErrorCode, GetNodes, Hello, Nodes, RemoteError, Welcome
from server.main import create_app
from server.settings import Settings

from server_harness import live_server, scene
from coupling_client import TcpClient, bye, handshake, run_windows


def test_billion_particle_scene_is_a_422_naming_dp(srv):
    r = srv.http.post("/runs", json={"scene": scene(dp=3e-5)})
    assert r.status_code == 422
    (err,) = r.json()["detail"]
    assert err["loc"] == ["body", "scene", "dp"] and "cap" in err["msg"]
    assert srv.http.get("/runs").json() == []  # nothing was created


@pytest.mark.parametrize("bad, loc", [
    ({"tank": {"x0": 0.0, "x1": 1.0, "z0": 0.5, "z1": 0.0}}, ["body", "scene", "tank"]),
    ({"dp": -1.0}, ["body", "scene", "dp"]),
    ({"t_end": "soon"}, ["body", "scene", "t_end"]),
])
def test_bad_scene_is_a_422_naming_the_field(srv, bad, loc):
    r = srv.http.post("/runs", json={"scene": scene(**bad)})
    assert r.status_code == 422
    assert any(e["loc"][:len(loc)] == loc for e in r.json()["detail"]), r.json()


def test_unknown_request_field_and_bad_mode(srv):
    r = srv.http.post("/runs", json={"scene": scene(), "mode": "turbo"})
    assert r.status_code == 422 and r.json()["detail"][0]["loc"] == ["body", "mode"]
    r = srv.http.post("/runs", json={"scene": scene(), "coupling": {"window_max": 0}})
    assert r.status_code == 422 and r.json()["detail"][0]["loc"] == ["body", "coupling", "window_max"]


def test_mode_and_open_boundaries_must_agree(srv):
    r = srv.http.post("/runs", json={"scene": scene(), "mode": "coupled"})
    assert r.status_code == 422
    assert r.json()["detail"][0]["loc"] == ["body", "scene", "open_boundaries"]
    r = srv.http.post("/runs", json={"scene": scene(open_boundaries=[{"side": "left"}]),
                                     "mode": "standalone"})  # open ends need a wave source
    assert r.status_code == 422 and r.json()["detail"][0]["loc"] == ["body", "source"]


def test_concurrency_cap_queues_runs(tmp_path, factory):
    # issue 15: a coupled run waiting for its client holds a waiting place, not a stepping slot
    with live_server(tmp_path, factory, max_runs=1, max_waiting=1) as srv:
        first, second = srv.create(), srv.create()
        srv.wait_state(first["id"], "waiting_for_client")
        info = srv.http.get(f"/runs/{second['id']}").json()
        assert info["state"] == "queued" and info["queue_position"] == 1
        third = srv.create()
        assert srv.http.get(f"/runs/{third['id']}").json()["queue_position"] == 2
        assert srv.http.delete(f"/runs/{third['id']}").json()["status"] == "cancelled"
        # the first run's client takes the one stepping slot; its waiting place goes to the second
        c = TcpClient(srv.tcp_port)
        welcome, nodes = handshake(c, first["id"])
        srv.wait_state(second["id"], "waiting_for_client")
        # while the first steps, the second's client waits for WELCOME (the run is its own)
        c2 = TcpClient(srv.tcp_port)
        c2.request(Hello(1, bytes(32), second["id"], "pytest"))
        c3 = TcpClient(srv.tcp_port)  # another holder of the id cannot take it
        c3.request(Hello(1, bytes(32), second["id"], "intruder"))
        with pytest.raises(RemoteError) as exc:
            c3.session.reply(*c3.recv(), expect=Welcome)
        assert exc.value.code == ErrorCode.BUSY and "already has a coupling client" in exc.value.text
        assert srv.http.get(f"/runs/{second['id']}").json()["state"] == "waiting_for_client"
        # finishing the first run frees its slot for the second
        run_windows(c, welcome, nodes, 1)
        bye(c)
        srv.wait_state(first["id"], "finished")
        welcome = c2.session.reply(*c2.recv(), expect=Welcome)
        nodes = c2.request(GetNodes(), expect=Nodes)
        run_windows(c2, welcome, nodes, 1)
        bye(c2)
        srv.wait_state(second["id"], "finished")


def test_standalone_run_with_sph_core(srv):
    run = srv.create(mode="standalone", t_end=0.2)
    events = []
    with srv.http.stream("GET", f"/runs/{run['id']}/events") as stream:
        for line in stream.iter_lines():
            if line.startswith("data: "):
                events.append(json.loads(line[6:]))
    assert events[-1]["state"] == "finished"  # the stream ends with the final state
    info = srv.http.get(f"/runs/{run['id']}").json()
    assert info["t"] == pytest.approx(0.2) and info["steps"] > 0 and info["particles"] > 200
    assert info["particle_steps_per_s"] > 0
    assert set(info["stability"]) >= {"dt", "v_max", "c0", "mach", "mass_drift"}
    assert abs(info["stability"]["mass_drift"]) < 1e-12  # closed tank: mass is conserved
    assert info["last_gauges"]["g_mid_eta"] == pytest.approx(0.0, abs=0.01)  # still water stays still
    assert info["last_gauges"]["dry_g_eta"] == pytest.approx(0.0, abs=0.01)
    csv = srv.http.get(f"/runs/{run['id']}/gauges").text.splitlines()
    assert csv[0].startswith("t,step,") and len(csv) == 1 + 5  # t = 0, 0.05, ..., 0.2
    rows = srv.http.get(f"/runs/{run['id']}/gauges", params={"format": "json"}).json()["rows"]
    assert rows[-1]["t"] == pytest.approx(0.2)
    # /probes: the SPH side's probes.csv (here the same file as the gauges)
    probes = srv.http.get(f"/runs/{run['id']}/probes", params={"format": "json"}).json()
    assert probes["rows"] == rows and "g_mid_eta" in probes["columns"]


def test_cancel_standalone_and_unknown_run(srv):
    run = srv.create(mode="standalone", t_end=50.0)
    srv.wait_state(run["id"], "running")
    info = srv.http.delete(f"/runs/{run['id']}").json()
    info = srv.wait_state(run["id"], "cancelled")
    assert info["status"] == "cancelled" and info["t"] < 50.0
    assert srv.http.get("/runs/nope").status_code == 404
    assert srv.http.delete("/runs/nope").status_code == 404


def test_event_loop_is_not_blocked_by_stepping(tmp_path, factory):
    import threading

    gate = threading.Event()  # the solve lasts until the test opens it: no timing guess
    with live_server(tmp_path, lambda r, d: factory(r, d, gate=gate)) as srv:
        run = srv.create()
        c, welcome, nodes = srv.couple(run["id"])
        n = welcome.n_nodes
        from protocol import Set, Solve
        import numpy as np
        c.request(Set(0.0, 0.05, np.zeros(n), np.zeros(n), np.zeros(n)), Solve())
        # while the engine is held in its solve, HTTP answers
        try:
            for _ in range(3):
                r = srv.http.get(f"/runs/{run['id']}", timeout=10)
                assert r.json()["state"] == "running" and r.json()["windows"] == 0
                # the page says what a run without progress does (ux.md F3)
                assert r.json()["detail"].startswith("first window")
        finally:
            gate.set()
        c.recv()
        assert srv.http.get(f"/runs/{run['id']}").json()["detail"] is None
        bye(c)


@pytest.mark.parametrize("cached, detail", [(True, "first window"),
                                            (False, "first window: compiling SPH kernels (first run only)")])
def test_run_detail_says_when_kernels_compile(monkeypatch, cached, detail):
    import sph_core.progress
    from server.run_manager import compile_detail

    monkeypatch.setattr(sph_core.progress, "kernels_cached", lambda: cached)
    assert compile_detail("first window") == detail


def test_restart_lists_finished_runs_with_their_data(tmp_path, factory):
    with live_server(tmp_path, factory) as srv:
        run = srv.create()
        c, welcome, nodes = srv.couple(run["id"])
        run_windows(c, welcome, nodes, 3)
        bye(c)
        srv.wait_state(run["id"], "finished")
        gauges = srv.http.get(f"/runs/{run['id']}/gauges").text
        waiting = srv.create()
        srv.wait_state(waiting["id"], "waiting_for_client")
    # a run killed with the server process: its meta.json still says running
    crashed = tmp_path / "runs" / waiting["id"] / "meta.json"
    meta = json.loads(crashed.read_text())
    crashed.write_text(json.dumps({**meta, "state": "running", "status": "running"}))
    with live_server(tmp_path) as srv:
        runs = {r["id"]: r for r in srv.http.get("/runs").json()}
        assert runs[run["id"]]["status"] == "finished" and runs[run["id"]]["windows"] == 3
        assert srv.http.get(f"/runs/{run['id']}/gauges").text == gauges
        assert runs[waiting["id"]]["status"].startswith("failed: server stopped")


def test_token_required_off_loopback(tmp_path):
    with pytest.raises(ValidationError, match="token"):
        Settings(host="0.0.0.0", runs_dir=tmp_path)
    s = Settings(host="0.0.0.0", token="t" * 20, runs_dir=tmp_path, tcp_port=None)
    with TestClient(create_app(s)) as client:
        assert client.get("/runs").status_code == 401
        assert client.get("/runs", headers={"Authorization": "Bearer wrong"}).status_code == 401
        assert client.get("/runs", headers={"Authorization": "Bearer " + "t" * 20}).status_code == 200
        assert client.get("/openapi.json").json()["paths"].keys() >= {"/runs", "/runs/{run_id}"}


def test_serve_cli_refuses_public_bind_without_token(tmp_path):
    out = subprocess.run([sys.executable, "-m", "wavesph", "serve", "--host", "0.0.0.0",
                          "--runs-dir", str(tmp_path)], capture_output=True, text=True, timeout=60,
                         env={"PATH": "/usr/bin:/bin"})
    assert out.returncode == 2 and "token" in out.stderr


def test_settings_from_environment(tmp_path):
    s = Settings.from_env({"WAVESPH_MAX_RUNS": "3", "WAVESPH_TCP_PORT": "", "WAVESPH_RUNS_DIR": str(tmp_path)},
                          port=9999)
    assert s.max_runs == 3 and s.tcp_port is None and s.port == 9999 and s.runs_dir == tmp_path
    with pytest.raises(ValidationError, match="max_runs"):
        Settings.from_env({"WAVESPH_MAX_RUNS": "zero"})


def test_run_interrupted_by_a_server_stop_resumes_after_restart(tmp_path, factory):
    with live_server(tmp_path, factory) as srv:
        run = srv.create()
        c, welcome, nodes = srv.couple(run["id"])
        run_windows(c, welcome, nodes, 2)
    # the server stopped under the connected client: the run says so, and kept its state
    with live_server(tmp_path, factory) as srv:
        info = srv.http.get(f"/runs/{run['id']}").json()
        assert info["status"] == "failed: server stopped before the run ended" and info["resumable"]
        assert srv.http.post(f"/runs/{run['id']}/resume").status_code == 202
        c, welcome, nodes = srv.couple(run["id"])
        assert welcome.t_start == pytest.approx(0.1)
        run_windows(c, welcome, nodes, 1, t0=0.1)
        bye(c)
        assert srv.wait_state(run["id"], "finished")["windows"] == 3


def test_device_cuda_without_a_gpu_is_a_422_naming_it(srv, monkeypatch):
    import sph_core.cuda

    monkeypatch.setattr(sph_core.cuda, "unavailable_reason",
                        lambda: "no CUDA GPU or driver found (test)")
    r = srv.http.post("/runs", json={"scene": scene(run={"device": "cuda"}), "mode": "standalone"})
    assert r.status_code == 422
    (err,) = r.json()["detail"]
    assert err["loc"] == ["body", "scene", "run", "device"]
    assert err["msg"] == "device cuda: no CUDA GPU or driver found (test)"
    r = srv.http.post("/runs", json={"scene": scene(run={"device": "tpu"}), "mode": "standalone"})
    assert r.status_code == 422
    assert r.json()["detail"][0]["loc"] == ["body", "scene", "run", "device"]
    assert srv.http.get("/runs").json() == []  # nothing was created


def test_the_servers_default_device_is_each_runs_unless_its_scene_says(tmp_path, factory,
                                                                        monkeypatch):
    import sph_core.cuda

    monkeypatch.setattr(sph_core.cuda, "unavailable_reason", lambda: None)
    with live_server(tmp_path, factory, device="cuda") as srv:
        default, own = srv.create(), srv.create(run={"device": "cpu"})
        assert default["device"] == "cuda" and own["device"] == "cpu"
        info = srv.http.get(f"/runs/{default['id']}").json()
        assert info["device"] == "cuda"
        # the run's stored request carries the device its scene runs on
        stored = json.loads((tmp_path / "runs" / default["id"] / "request.json").read_text())
        assert stored["scene"]["run"]["device"] == "cuda"
    with live_server(tmp_path / "cpu", factory) as srv:
        assert srv.create()["device"] == "cpu"


def test_runs_carry_their_scene_name(srv):
    a = srv.create(name="seawall")
    b = srv.create(name="seawall")
    listed = {r["id"]: r["name"] for r in srv.http.get("/runs").json()}
    assert listed[a["id"]] == listed[b["id"]] == "seawall" and a["id"] != b["id"]
    assert srv.http.get(f"/runs/{a['id']}/probes").status_code == 404   # no SPH data yet


def test_event_stream_ends_when_the_server_is_stopping(srv):
    """Ctrl-C on `wavesph serve` waited on the page's open stream of a running run (~20 s, the
    run stepping on): the stream ends as soon as the server is told to stop."""
    run = srv.create()
    srv.wait_state(run["id"], "waiting_for_client")
    events = []
    with srv.http.stream("GET", f"/runs/{run['id']}/events", timeout=30) as stream:
        for line in stream.iter_lines():
            if line.startswith("data: "):
                events.append(json.loads(line[6:]))
                srv.app.state.stopping.set()      # what Ctrl-C does (server.asgi.Server)
    assert len(events) == 1 and events[0]["state"] == "waiting_for_client"   # not a final state
    srv.app.state.stopping.clear()


def test_ctrl_c_tells_the_app_it_is_stopping(tmp_path):
    import signal

    from server.asgi import server
    from server.main import create_app
    from server.settings import Settings

    settings = Settings(host="127.0.0.1", port=0, tcp_port=0, runs_dir=tmp_path)
    app = create_app(settings)
    srv = server(app, settings)
    assert not app.state.stopping.is_set()
    srv.handle_exit(signal.SIGINT, None)
    assert app.state.stopping.is_set() and srv.should_exit
