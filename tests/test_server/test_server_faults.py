"""Faults and bad input of issue 15, one reproducing case each (real server on 127.0.0.1)."""

from __future__ import annotations

import json
import math

import pytest

from server_harness import live_server, scene


def _strict(token: str):
    raise AssertionError(f"{token} in a reply: not JSON")


def _coupled_body(**overrides) -> dict:
    return {"scene": scene(open_boundaries=[{"side": "left"}], **overrides), "mode": "coupled"}


# 1. runs whose client never comes ---------------------------------------------------------------
def test_waiting_coupled_runs_do_not_hold_the_stepping_slots(tmp_path, factory):
    with live_server(tmp_path, factory, max_runs=2) as srv:
        idle = [srv.create(), srv.create()]  # clients that never come
        for run in idle:
            srv.wait_state(run["id"], "waiting_for_client")
        standalone = srv.create(mode="standalone", t_end=0.05)
        assert srv.wait_state(standalone["id"], "finished", timeout=60)["status"] == "finished"
        for run in idle:
            assert srv.http.get(f"/runs/{run['id']}").json()["state"] == "waiting_for_client"


def test_full_queue_is_a_429_with_retry_after(tmp_path, factory):
    with live_server(tmp_path, factory, max_waiting=1, max_queued=2) as srv:
        first = srv.create()
        srv.wait_state(first["id"], "waiting_for_client")
        queued = [srv.create(), srv.create()]
        assert all(srv.http.get(f"/runs/{r['id']}").json()["state"] == "queued" for r in queued)
        r = srv.http.post("/runs", json=_coupled_body())
        assert r.status_code == 429 and int(r.headers["retry-after"]) > 0
        assert "max_queued" in r.json()["detail"]
        assert len(srv.http.get("/runs").json()) == 3  # the refused run was not created
        srv.http.delete(f"/runs/{queued[0]['id']}")
        assert srv.http.post("/runs", json=_coupled_body()).status_code == 201


# 2. big scenes: a probe cap, and validation off the event loop -----------------------------------
def test_probe_count_is_capped(srv):
    probes = [{"kind": "elevation", "name": f"p{i}", "x": 0.5} for i in range(20_000)]
    r = srv.http.post("/runs", json={"scene": scene(probes=probes), "mode": "standalone"})
    assert r.status_code == 422
    (err,) = r.json()["detail"]
    assert err["loc"] == ["body", "scene", "probes"] and "max_probes" in err["msg"]


def test_duplicate_probe_names_are_named(srv):
    probes = [{"kind": "elevation", "name": f"p{i % 500}", "x": 0.5} for i in range(1000)]
    r = srv.http.post("/runs", json={"scene": scene(probes=probes), "mode": "standalone"})
    assert r.status_code == 422 and "duplicate names ['p0', 'p1'" in r.text


def test_request_validation_runs_off_the_event_loop(tmp_path, factory, monkeypatch):
    import threading

    import httpx

    import server.routers.runs as runs_router

    real = runs_router.parse_run_request

    entered, gate = threading.Event(), threading.Event()

    def slow(raw, settings, toml=False):  # stands for a heavy validation: no stalled server
        entered.set()
        gate.wait(30.0)  # held until the test has been answered: no timing guess under load
        return real(raw, settings, toml)

    monkeypatch.setattr(runs_router, "parse_run_request", slow)
    with live_server(tmp_path, factory) as srv:
        done = []
        post = threading.Thread(target=lambda: done.append(
            httpx.post(srv.url + "/runs", json=_coupled_body(), timeout=60).status_code))
        post.start()
        try:
            assert entered.wait(30.0), "the POST never reached its validation"
            for _ in range(3):  # answered while the validation is still held
                assert srv.http.get("/runs", timeout=10).status_code == 200
            assert not done
        finally:
            gate.set()
        post.join(timeout=60)
        assert done == [201]


# 3. NaN, Infinity, overflow: 422 naming the field, never 500, never NaN in the reply ------------
@pytest.mark.parametrize("text, loc", [
    ('"dp": NaN', ["body", "scene", "dp"]),
    ('"t_end": Infinity', ["body", "scene", "t_end"]),
    ('"t_end": -Infinity', ["body", "scene", "t_end"]),
    ('"still_water_level": NaN', ["body", "scene", "still_water_level"]),
    ('"dp": 1e400', ["body", "scene", "dp"]),
    ('"constants": {"g": NaN}', ["body", "scene", "constants", "g"]),
    ('"beds": [{"points": [[0.0, 0.0], [NaN, 0.1], [1.0, 0.2]]}]', ["body", "scene", "beds", 0, "points", 1, 0]),
])
def test_non_finite_numbers_are_a_422_naming_the_field(srv, text, loc):
    base = _coupled_body()
    base["scene"].pop(text.split('"')[1], None)
    # the raw JSON token goes in as text: json.dumps would not write 1e400 (Python clients do
    # send NaN and Infinity by default)
    raw = json.dumps(base).replace('"scene": {', '"scene": {' + text + ", ", 1)
    r = srv.http.post("/runs", content=raw, headers={"content-type": "application/json"})
    assert r.status_code == 422, r.text
    detail = json.loads(r.text, parse_constant=_strict)["detail"]  # the reply is strict JSON
    assert [e["loc"] for e in detail] == [loc]
    assert srv.http.get("/runs").json() == []


@pytest.mark.parametrize("overrides", [
    {"tank": {"x0": -1e308, "x1": 1e308, "z0": 0.0, "z1": 0.5}},
    {"dp": 5e-324},
])
def test_overflowing_particle_estimate_is_the_particle_cap(srv, overrides):
    body = _coupled_body()
    body["scene"].update(overrides)
    body["scene"]["water_blocks"] = [{"x0": 0.0, "x1": 1.0, "z0": 0.0, "z1": 0.3}]
    r = srv.http.post("/runs", json=body)
    assert r.status_code == 422, r.text
    assert r.json()["detail"][0]["loc"] == ["body", "scene", "dp"]


def test_estimate_particles_never_raises():
    from server.schemas import estimate_particles
    from sph_core.scene import Scene

    s = Scene.model_validate(scene(dp=5e-324))
    assert estimate_particles(s) == math.inf
    s = Scene.model_validate(scene(tank={"x0": -1e308, "x1": 1e308, "z0": 0.0, "z1": 1e308}))
    assert estimate_particles(s) == math.inf
    assert 100 < estimate_particles(Scene.model_validate(scene())) < 1000


# 5. everything a run needs, checked before the 201 ----------------------------------------------
@pytest.mark.parametrize("change, loc", [
    ({"coupling": {"window_max": 1e-300}}, ["body", "coupling", "window_max"]),
    ({"coupling": {"z_ref": -5.0}}, ["body", "coupling", "z_ref"]),
    ({"coupling": {"window_max": "Infinity"}}, ["body", "coupling", "window_max"]),
])
def test_coupling_options_a_run_cannot_use_are_a_422(srv, change, loc):
    body = {**_coupled_body(), **change}
    r = srv.http.post("/runs", content=json.dumps(body).replace('"Infinity"', "Infinity"),
                      headers={"content-type": "application/json"})
    assert r.status_code == 422, r.text
    assert r.json()["detail"][0]["loc"] == loc


def test_tiny_source_window_is_a_422(srv):
    body = {**_coupled_body(), "mode": "standalone",
            "source": {"theory": "linear", "H": 0.02, "T": 1.0, "window": 1e-300}}
    r = srv.http.post("/runs", json=body)
    assert r.status_code == 422, r.text
    assert r.json()["detail"][0]["loc"] == ["body", "source", "window"]


# 8. body size, no echo, the answers in OpenAPI --------------------------------------------------
def test_body_over_max_body_is_a_413(tmp_path, factory):
    with live_server(tmp_path, factory, max_body=64 * 1024) as srv:
        body = _coupled_body(name="x" * 100_000)
        r = srv.http.post("/runs", json=body)
        assert r.status_code == 413 and "max_body" in r.text


def test_422_does_not_echo_the_input_and_400_for_non_json(srv):
    r = srv.http.post("/runs", json={**_coupled_body(), "mode": "m" * 500_000})
    assert r.status_code == 422 and len(r.content) < 2000
    assert r.json()["detail"][0]["loc"] == ["body", "mode"]
    r = srv.http.post("/runs", content=b"{not json", headers={"content-type": "application/json"})
    assert r.status_code == 400 and "not JSON" in r.json()["detail"]


def test_openapi_lists_the_error_answers_and_the_body(srv):
    paths = srv.http.get("/openapi.json").json()["paths"]
    post = paths["/runs"]["post"]
    assert {"201", "400", "413", "422", "429"} <= set(post["responses"])
    assert post["requestBody"]["content"]["application/json"]["schema"]["$ref"].endswith("/RunRequest")
    assert {"404"} <= set(paths["/runs/{run_id}"]["get"]["responses"])
    assert {"404", "409"} <= set(paths["/runs/{run_id}/resume"]["post"]["responses"])


# 4. the run store trusts its directory names and stays inside itself -----------------------------
def test_store_skips_bad_entries_and_never_writes_outside_itself(tmp_path, factory, caplog):
    import logging
    import shutil

    with live_server(tmp_path, factory) as srv:
        a, b = srv.create(), srv.create()
        for run in (a, b):
            srv.wait_state(run["id"], "waiting_for_client")
    runs = tmp_path / "runs"
    moved = runs / "moved-run"
    shutil.move(runs / a["id"], moved)  # meta.json still names the old id
    meta = json.loads((runs / b["id"] / "meta.json").read_text())
    (runs / b["id"] / "meta.json").write_text(json.dumps({**meta, "id": "../escaped"}))
    (runs / "garbage").mkdir()
    (runs / "garbage" / "meta.json").write_text("{not json")
    (runs / "stray.txt").write_text("not a run")
    caplog.set_level(logging.WARNING, logger="wavesph.server")
    with live_server(tmp_path, factory) as srv:
        listed = {r["id"]: r for r in srv.http.get("/runs").json()}
        assert set(listed) == {"moved-run", b["id"]}
        assert listed["moved-run"]["status"] == listed[b["id"]]["status"]
        assert srv.http.get("/runs/moved-run/scene").status_code == 200
        for run in srv.manager.runs.values():  # a record rewritten goes to its own directory
            srv.manager.save(run)
    assert not (tmp_path / "escaped").exists() and not (runs.parent / "escaped").exists()
    assert json.loads((moved / "meta.json").read_text())["id"] == "moved-run"
    assert json.loads((runs / b["id"] / "meta.json").read_text())["id"] == b["id"]
    logged = caplog.text
    assert "garbage" in logged and "stray.txt" in logged and "moved-run" in logged


# 6. the API token: never in a log line; a header or a subprotocol work too ---------------------
def test_websocket_token_is_redacted_in_logs_and_accepted_as_header_or_subprotocol(tmp_path, factory):
    import logging

    from websockets.sync.client import connect

    from coupling_client import WsClient, bye, handshake, run_windows

    token = "s3cret-token-0123456789"
    lines: list[str] = []

    class Keep(logging.Handler):
        def emit(self, record: logging.LogRecord) -> None:
            lines.append(record.getMessage())

    keep = Keep()
    loggers = [logging.getLogger(n) for n in ("uvicorn.access", "uvicorn.error")]
    try:
        with live_server(tmp_path, factory, log_level="info", token=token) as srv:
            for lg in loggers:  # after uvicorn configured its logging
                lg.addHandler(keep)
            runs = [srv.create() for _ in range(3)]
            for run in runs:
                srv.wait_state(run["id"], "waiting_for_client")
            base = f"ws://127.0.0.1:{srv.port}/runs"
            # 1. ?token= (documented): works, and the log shows it redacted
            c = WsClient(f"{base}/{runs[0]['id']}/couple?token={token}")
            welcome, nodes = handshake(c, runs[0]["id"])
            run_windows(c, welcome, nodes, 1)
            bye(c)
            # 2. a subprotocol beside "wavesph", which the server selects
            with connect(f"{base}/{runs[1]['id']}/couple",
                         subprotocols=["wavesph", f"wavesph.token.{token}"]) as ws:
                assert ws.subprotocol == "wavesph"
            # 3. the Authorization header
            with connect(f"{base}/{runs[2]['id']}/couple",
                         additional_headers={"Authorization": f"Bearer {token}"}):
                pass
            # a wrong token in any form is refused
            with pytest.raises(Exception, match="403"):
                connect(f"{base}/{runs[2]['id']}/couple?token=wrong-token-0123456789")
    finally:
        for lg in loggers:
            lg.removeHandler(keep)
    text = "\n".join(lines)
    assert "token=***" in text  # the access line was logged, redacted
    assert token not in text and "wrong-token" not in text


# 7. a client may come before its run is started: it reserves the run and waits ----------------
def test_client_of_a_queued_run_reserves_it_and_waits_for_welcome(tmp_path, factory):
    from protocol import ErrorCode, GetNodes, Hello, Nodes, RemoteError, Welcome

    from coupling_client import TcpClient, bye, run_windows

    with live_server(tmp_path, factory, max_waiting=1) as srv:
        first = srv.create()
        srv.wait_state(first["id"], "waiting_for_client")
        queued, other = srv.create(), srv.create()
        assert srv.http.get(f"/runs/{queued['id']}").json()["state"] == "queued"
        owner = TcpClient(srv.tcp_port)
        owner.request(Hello(1, bytes(32), queued["id"], "owner"))
        intruder = TcpClient(srv.tcp_port)
        intruder.request(Hello(1, bytes(32), queued["id"], "intruder"))
        with pytest.raises(RemoteError) as exc:
            intruder.session.reply(*intruder.recv(), expect=Welcome)
        assert exc.value.code == ErrorCode.BUSY and "already has a coupling client" in exc.value.text
        # a client that leaves while waiting frees the run for the next one
        leaver = TcpClient(srv.tcp_port)
        leaver.request(Hello(1, bytes(32), other["id"], "leaver"))
        leaver.close()
        # the first run ends: the queued one is built and its waiting client gets WELCOME
        assert srv.http.delete(f"/runs/{first['id']}").json()["state"] == "cancelled"
        welcome = owner.session.reply(*owner.recv(), expect=Welcome)
        nodes = owner.request(GetNodes(), expect=Nodes)
        run_windows(owner, welcome, nodes, 1)
        bye(owner)
        assert srv.wait_state(queued["id"], "finished")["client"] == "owner"
        srv.wait_state(other["id"], "waiting_for_client")
        late = TcpClient(srv.tcp_port)
        late.request(Hello(1, bytes(32), other["id"], "late"))
        late.session.reply(*late.recv(), expect=Welcome)
        # cancelling a reserved, still queued run tells its waiting client
        filler = srv.create()  # takes the one waiting place
        srv.wait_state(filler["id"], "waiting_for_client")
        third = srv.create()
        assert srv.http.get(f"/runs/{third['id']}").json()["state"] == "queued"
        waiter = TcpClient(srv.tcp_port)
        waiter.request(Hello(1, bytes(32), third["id"], "waiter"))
        srv.http.delete(f"/runs/{third['id']}")
        with pytest.raises(RemoteError) as exc:
            waiter.session.reply(*waiter.recv(), expect=Welcome)
        assert exc.value.code == ErrorCode.CANCELLED


# 9. messages that said the wrong thing ------------------------------------------------------------
def test_second_hello_is_named_as_such(srv):
    from protocol import ErrorCode, Hello, RemoteError, Result

    run = srv.create()
    c, _, _ = srv.couple(run["id"])
    c.request(Hello(1, bytes(32), run["id"], "again"))
    with pytest.raises(RemoteError) as exc:
        c.session.reply(*c.recv(), expect=Result)
    assert exc.value.code == ErrorCode.OUT_OF_ORDER and "second HELLO" in exc.value.text
    assert "server only" not in exc.value.text


def test_public_tcp_host_without_token_names_the_tcp_host(tmp_path):
    from pydantic import ValidationError

    from server.settings import Settings

    with pytest.raises(ValidationError) as exc:
        Settings.from_env({"WAVESPH_TCP_HOST": "0.0.0.0", "WAVESPH_RUNS_DIR": str(tmp_path)})
    text = str(exc.value)
    assert "tcp_host '0.0.0.0'" in text and "127.0.0.1" not in text


def test_meta_catches_up_with_gauges_after_a_crash(tmp_path, factory):
    import shutil

    from coupling_client import run_windows

    with live_server(tmp_path, factory, meta_interval=1000.0) as srv:
        run = srv.create()
        c, welcome, nodes = srv.couple(run["id"])
        run_windows(c, welcome, nodes, 5)
        # the disk as a kill -9 would leave it now: gauges.csv has 5 rows, meta.json fewer
        crashed = tmp_path / "crashed" / "runs"
        shutil.copytree(tmp_path / "runs", crashed)
        assert json.loads((crashed / run["id"] / "meta.json").read_text())["windows"] < 5
        c.close()
    with live_server(tmp_path / "crashed", factory) as srv:
        info = srv.http.get(f"/runs/{run['id']}").json()
        assert info["windows"] == 5 and info["t"] == pytest.approx(0.25)
        assert info["status"] == "failed: server stopped before the run ended"
        assert info["last_gauges"]["g_mid_eta"] is not None


def test_damaged_saved_state_is_not_resumable(tmp_path, factory):
    from coupling_client import run_windows

    with live_server(tmp_path, factory) as srv:
        run = srv.create()
        c, welcome, nodes = srv.couple(run["id"])
        run_windows(c, welcome, nodes, 2)
        c.close()
        assert srv.wait_state(run["id"], "failed")["resumable"]
        state = tmp_path / "runs" / run["id"] / "state.npz"
        good = state.read_bytes()
        state.write_bytes(good[:-3] + b"xyz")  # damaged under a live server: resume refuses
        r = srv.http.post(f"/runs/{run['id']}/resume")
        assert r.status_code == 409 and "resumed" in r.json()["detail"]
        assert not srv.http.get(f"/runs/{run['id']}").json()["resumable"]
    # and after a restart the record says so
    with live_server(tmp_path, factory) as srv:
        info = srv.http.get(f"/runs/{run['id']}").json()
        assert not info["resumable"] and "saved state is damaged" in info["status"]
        r = srv.http.post(f"/runs/{run['id']}/resume")
        assert r.status_code == 409


# 10. resumable early, and queued runs survive a server stop ------------------------------------
def test_state_is_saved_by_simulated_progress_too(tmp_path, factory):
    import shutil

    from coupling_client import bye, run_windows

    with live_server(tmp_path, factory, checkpoint_every=1000.0, checkpoint_every_t=0.1) as srv:
        run = srv.create()
        c, welcome, nodes = srv.couple(run["id"])
        run_windows(c, welcome, nodes, 3)  # to t = 0.15: a state saved at t = 0.1
        crashed = tmp_path / "crashed" / "runs"  # the disk as a kill -9 leaves it now
        shutil.copytree(tmp_path / "runs", crashed)
        c.close()
    with live_server(tmp_path / "crashed", factory) as srv:
        info = srv.http.get(f"/runs/{run['id']}").json()
        assert info["resumable"] and info["windows"] == 3
        assert srv.http.post(f"/runs/{run['id']}/resume").status_code == 202
        c, welcome, nodes = srv.couple(run["id"])
        assert welcome.t_start == pytest.approx(0.1)
        run_windows(c, welcome, nodes, 1, t0=0.1)
        bye(c)
        assert srv.wait_state(run["id"], "finished")["windows"] == 3  # rows after t = 0.1 redone


def test_runs_not_started_are_queued_again_after_a_stop_or_a_crash(tmp_path, factory):
    import shutil

    from coupling_client import TcpClient, bye, handshake, run_windows

    with live_server(tmp_path, factory, max_waiting=1) as srv:
        waiting, queued = srv.create(), srv.create()
        srv.wait_state(waiting["id"], "waiting_for_client")
        assert srv.http.get(f"/runs/{queued['id']}").json()["state"] == "queued"
        crashed = tmp_path / "crashed" / "runs"
        shutil.copytree(tmp_path / "runs", crashed)
    for root in (tmp_path, tmp_path / "crashed"):  # after a clean stop, and after a kill -9
        with live_server(root, factory, max_waiting=1) as srv:
            srv.wait_state(waiting["id"], "waiting_for_client")
            info = srv.http.get(f"/runs/{queued['id']}").json()
            assert info["state"] == "queued" and info["queue_position"] == 1
            c = TcpClient(srv.tcp_port)
            welcome, nodes = handshake(c, waiting["id"])
            run_windows(c, welcome, nodes, 1)
            bye(c)
            srv.wait_state(waiting["id"], "finished")
            srv.wait_state(queued["id"], "waiting_for_client")
