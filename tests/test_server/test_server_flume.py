"""The production coupled engine (an sph_core Simulation with open ends) behind the real server doors.

The server must be transparent: a flume driven over TCP gives exactly the gauge readings of the
same flume driven in-process with the same boundary data. The wave data are linear (Airy)
theory, computed here; the physics of the open boundaries is sph_core's to validate.
"""

from __future__ import annotations

import numpy as np
import pytest

from protocol import Result, Set, Solve
from server.flume_engine import FlumeEngine
from server.main import create_app  # noqa: F401  (default engine factory: the flume)
from server.schemas import RunRequest

from server_harness import live_server, open_flume
from coupling_client import bye
from linear_wave import airy

G, DEPTH, H, T, WINDOW = 9.81, 0.3, 0.02, 1.0, 0.05
FLUME = open_flume("flume", t_end=1.0, depth=DEPTH)


def wave(x: np.ndarray, z: np.ndarray, t: float):
    """The flume's linear wave at nodes."""
    return airy(x, z, t, H, T, DEPTH, G)


def test_flume_over_tcp_equals_the_flume_in_process(tmp_path):
    body = {"scene": FLUME, "mode": "coupled", "coupling": {"window_max": WINDOW}}
    sent, got = [], []
    with live_server(tmp_path) as srv:
        r = srv.http.post("/runs", json=body)
        assert r.status_code == 201, r.text
        run = r.json()
        c, welcome, nodes = srv.couple(run["id"], timeout=120, scene_hash=bytes.fromhex(run["scene_hash"]))
        assert welcome.depth == pytest.approx(DEPTH) and welcome.z_ref == pytest.approx(-DEPTH / 2)
        assert sorted(set(nodes.side.tolist())) == [0, 1] and nodes.gauge_x.size == 3
        assert nodes.x[nodes.side == 0].max() == 0.0 and nodes.x[nodes.side == 1].min() == 1.2
        t = 0.0
        for _ in range(4):
            u, w, eta = wave(nodes.x, nodes.z, t + WINDOW)
            sent.append((t, t + WINDOW, u, w, eta))
            got.append(c.request(Set(t, t + WINDOW, u, w, eta), Solve(), expect=Result))
            t += WINDOW
        bye(c)
        info = srv.wait_state(run["id"], "finished")
        rows = srv.http.get(f"/runs/{run['id']}/gauges", params={"format": "json"}).json()
    assert info["windows"] == 4 and info["steps"] > 4 and info["particles"] > 300
    assert info["stability"]["fluid_mass_ratio"] > 0.9
    assert rows["columns"][2:5] == ["left_boundary_eta", "left_boundary_u_ref", "left_boundary_w_ref"]
    assert all(r.wet[0] == 1 for r in got)  # the inlet gauge is in the water
    # the same flume, in this process, with the same boundary data
    engine = FlumeEngine(RunRequest.model_validate(body), None)
    for (t0, t1, u, w, eta), res in zip(sent, got):
        engine.set_window(t0, t1, u, w, eta)
        m = engine.solve_window()
        assert res.steps == m.steps and res.t == pytest.approx(engine.t, abs=1e-12)
        np.testing.assert_allclose(res.eta, np.where(m.wet, m.eta, 0.0), rtol=1e-12, atol=1e-15)
        np.testing.assert_allclose(res.u_ref, np.where(m.wet, m.u_ref, 0.0), rtol=1e-12, atol=1e-15)
    engine.close()


def test_flume_refuses_boundary_data_outside_the_tank(tmp_path):
    body = {"scene": FLUME, "mode": "coupled", "coupling": {"window_max": WINDOW}}
    with live_server(tmp_path) as srv:
        run = srv.http.post("/runs", json=body).json()
        c, welcome, nodes = srv.couple(run["id"], timeout=120)
        n = welcome.n_nodes
        c.request(Set(0.0, WINDOW, np.zeros(n), np.zeros(n), np.full(n, 5.0)), Solve())
        from protocol import ErrorCode, RemoteError
        with pytest.raises(RemoteError, match="outside the tank") as exc:
            c.session.reply(*c.recv(), expect=Result)
        assert exc.value.code is ErrorCode.BAD_VALUE
        info = srv.wait_state(run["id"], "failed")
        assert "outside the tank" in info["status"]


def broken_and_resumed(tmp_path, body: dict, check=lambda welcome, nodes: None, **couple_kw):
    """A coupled run of ``body`` broken off after 2 windows of the linear wave, resumed, and
    broken off after 2 more; ``check(welcome, nodes)`` at each session's start. Returns the 4
    RESULTs, the last session's nodes and the run's id."""
    got = []
    with live_server(tmp_path) as srv:
        run = srv.http.post("/runs", json=body).json()
        for session in range(2):
            c, welcome, nodes = srv.couple(run["id"], **couple_kw)
            check(welcome, nodes)
            t = welcome.t_start
            for _ in range(2):
                got.append(c.request(Set(t, t + WINDOW, *wave(nodes.x, nodes.z, t + WINDOW)), Solve(),
                                     expect=Result))
                t += WINDOW
            c.close()
            assert srv.wait_state(run["id"], "failed")["resumable"]
            if session == 0:
                assert srv.http.post(f"/runs/{run['id']}/resume").status_code == 202
    return got, nodes, run["id"]


def test_resumed_flume_continues_exactly(tmp_path):
    """Disconnect after 2 windows, resume, 2 more: the same as 4 windows without a break."""
    body = {"scene": FLUME, "mode": "coupled", "coupling": {"window_max": WINDOW}}
    got, nodes, run_id = broken_and_resumed(tmp_path, body, timeout=120)
    assert (tmp_path / "runs" / run_id / "sph.1" / "probes.csv").exists()  # nothing overwritten
    engine = FlumeEngine(RunRequest.model_validate(body), None)
    t = 0.0
    for res in got:
        engine.set_window(t, t + WINDOW, *wave(nodes.x, nodes.z, t + WINDOW))
        m = engine.solve_window()
        t += WINDOW
        assert res.steps == m.steps
        np.testing.assert_allclose(res.eta, np.where(m.wet, m.eta, 0.0), rtol=1e-12, atol=1e-15)
    engine.close()


def test_flume_gauge_metadata_names_the_ends_own_gauges():
    """Protocol 1.1 GAUGES: which gauge is which, and the gauge each end's absorber reads."""
    from protocol import NO_GAUGE, GaugeKind

    scene = {**FLUME, "open_boundaries": [{"side": "left", "absorb": True},
                                          {"side": "right", "elevation": "extrapolated", "absorb": False}]}
    engine = FlumeEngine(RunRequest.model_validate({"scene": scene, "mode": "coupled"}), None)
    try:
        nodes = engine.nodes()
        assert nodes.gauge_names == ["left_boundary", "right_boundary", "g1"]
        assert nodes.gauge_kind.tolist() == [GaugeKind.BOUNDARY, GaugeKind.BOUNDARY, GaugeKind.PROBE]
        assert nodes.eta_gauge == (0, NO_GAUGE)  # the right end does not absorb
    finally:
        engine.close()


def test_flume_window_stops_when_the_run_is_cancelled():
    """A cancelled run's window ends at the next chunk of steps, not at t1 (a window of hours)."""
    import threading

    from server.engine import SolveCancelled

    body = {"scene": FLUME, "mode": "coupled", "coupling": {"window_max": 1.0}}
    engine = FlumeEngine(RunRequest.model_validate(body), None)
    engine.cancel = threading.Event()
    engine.cancel.set()
    engine.cancel_grace = 0.0  # cut at once (a server gives a window 2 s to end by itself)
    n = engine.nodes().x.size
    engine.set_window(0.0, 1.0, np.zeros(n), np.zeros(n), np.zeros(n))
    with pytest.raises(SolveCancelled):
        engine.solve_window()
    assert engine.t < 1.0


def test_zone_nodes_give_isph_zones_the_wave_and_resume_exactly(tmp_path):
    """Protocol 1.2 ZONE_NODES on an ISPH flume with relaxation zones: a client that asks gets
    the zones' columns after the face nodes and sends the wave there; the run, broken after 2
    windows and resumed, equals an in-process engine fed the same 4 windows (the zones' targets
    at the break are in the saved state), and differs from the face's profile as target."""
    from protocol import Capability

    scene = {**FLUME, "scheme": {"kind": "isph", "isph_relaxation_zone": 0.15}}
    body = {"scene": scene, "mode": "coupled", "coupling": {"window_max": WINDOW}}

    def check(welcome, nodes):
        assert welcome.capabilities & Capability.ZONE_NODES
        zone = nodes.side >= 2
        assert sorted(set(nodes.side.tolist())) == [0, 1, 2, 3] and welcome.n_nodes == nodes.x.size
        assert np.all((nodes.x[nodes.side == 2] > 0) & (nodes.x[nodes.side == 2] <= 0.15 + 1e-9))
        assert np.all((nodes.x[nodes.side == 3] < 1.2) & (nodes.x[nodes.side == 3] >= 1.05 - 1e-9))
        assert np.array_equal(np.unique(nodes.z[zone]), np.unique(nodes.z[~zone]))

    got, nodes, _ = broken_and_resumed(tmp_path, body, check, timeout=300,
                                       caps=int(Capability.GOBACK | Capability.ZONE_NODES))
    engine = FlumeEngine(RunRequest.model_validate(body), None)
    face = FlumeEngine(RunRequest.model_validate(body), None)
    try:
        zn, fn = engine.zone_nodes(), face.nodes()
        assert np.array_equal(zn.x, nodes.x) and np.array_equal(zn.side, nodes.side)
        t, differs = 0.0, False
        for res in got:
            engine.set_window(t, t + WINDOW, *wave(zn.x, zn.z, t + WINDOW))
            face.set_window(t, t + WINDOW, *wave(fn.x, fn.z, t + WINDOW))
            m, mf = engine.solve_window(), face.solve_window()
            t += WINDOW
            assert res.steps == m.steps
            np.testing.assert_allclose(res.eta, np.where(m.wet, m.eta, 0.0), rtol=1e-12, atol=1e-15)
            differs |= not np.array_equal(m.eta, mf.eta)
        assert engine.flume.open.zone.local.all() and not face.flume.open.zone.local.any()
        assert differs   # the zones' targets reach the gauges
    finally:
        engine.close()
        face.close()


def test_the_kit_passes_against_a_run_with_zone_nodes(tmp_path):
    """The conformance kit asks ZONE_NODES (1.2): against an ISPH flume with relaxation zones
    it is granted, the zones' columns pass its check, and still-water windows solve."""
    from protocol.conformance import Report, check_server

    scene = {**FLUME, "scheme": {"kind": "isph", "isph_relaxation_zone": 0.15}}
    with live_server(tmp_path) as srv:
        run = srv.http.post("/runs", json={"scene": scene, "mode": "coupled",
                                           "coupling": {"window_max": WINDOW}}).json()
        srv.wait_state(run["id"], "waiting_for_client", timeout=300)
        rep = check_server(f"tcp://127.0.0.1:{srv.tcp_port}", run["id"], windows=2,
                           timeout=120.0, report=Report(echo=False))
    assert rep.ok, rep.lines
    assert [v for v, n, _ in rep.lines if n.startswith("NODES with ZONE_NODES")] == ["PASS"]
