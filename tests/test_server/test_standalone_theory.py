"""Standalone runs of open-boundary scenes driven by a built-in theory (server/theory_source.py).

The built-in source must be the coupled path without the socket: the same scene driven by the
same theory through wave_client's client over a WebSocket gives the same gauges to round-off.
"""

from __future__ import annotations

import csv
import time

import numpy as np
import pytest

from protocol import Capability
from wave_client.coupling import CouplingOptions, couple
from wave_client.theories import build_theory

from server_harness import live_server, open_flume

DEPTH, H, T, RAMP = 0.3, 0.02, 1.0, 0.5
FLUME = open_flume("theory-flume", t_end=0.3, depth=DEPTH)
SOURCE = {"theory": "stokes", "H": H, "T": T, "order": 2, "ramp_periods": RAMP / T}


def rows(path) -> list[list[str]]:
    with open(path, newline="") as f:
        return list(csv.reader(f))


# ISPH with relaxation zones: both clients ask protocol 1.2's ZONE_NODES and send the theory's
# wave inside the zones too (its front as in-process)
ISPH_ZONES = {"kind": "isph", "isph_relaxation_zone": 0.15}


@pytest.mark.parametrize("scheme", [None, ISPH_ZONES], ids=["wcsph", "isph_zones"])
def test_standalone_theory_run_equals_the_coupled_run(tmp_path, scheme):
    scene = FLUME if scheme is None else {**FLUME, "scheme": scheme}
    with live_server(tmp_path) as srv:
        r = srv.http.post("/runs", json={"scene": scene, "mode": "standalone", "source": SOURCE})
        assert r.status_code == 201, r.text
        alone = srv.wait_state(r.json()["id"], "finished", "failed", "unstable", timeout=120)
        assert alone["state"] == "finished", alone["status"]
        r = srv.http.post("/runs", json={"scene": scene, "mode": "coupled"})
        assert r.status_code == 201, r.text
        run = r.json()
        srv.wait_state(run["id"], "waiting_for_client", timeout=120)
        wave = build_theory("stokes", height=H, period=T, depth=DEPTH, order=2, ramp_time=RAMP)
        report = couple(f"ws://127.0.0.1:{srv.port}/runs/{run['id']}/couple", wave, CouplingOptions(),
                        timeout=60.0, progress=False, log_path=tmp_path / "client.csv")
        coupled = srv.wait_state(run["id"], "finished")
    assert bool(report.welcome.capabilities & Capability.ZONE_NODES) == (scheme is not None)
    runs = tmp_path / "runs"
    a, b = rows(runs / alone["id"] / "gauges.csv"), rows(runs / run["id"] / "gauges.csv")
    # T/50 windows (the client's default, below window_max) up to t_end
    assert alone["windows"] == coupled["windows"] == len(report.records) == 15
    assert a[0] == b[0] and len(a) == len(b) == 16
    va = np.array([[float(v) for v in r] for r in a[1:]])
    vb = np.array([[float(v) for v in r] for r in b[1:]])
    np.testing.assert_allclose(va, vb, rtol=1e-12, atol=1e-15)
    # the source's theory log holds the model's elevation at the gauges, as the client's does
    ta = rows(runs / alone["id"] / "theory.csv")
    tb = rows(tmp_path / "client.csv")
    model_a = [r for r in ta if not r[0].startswith("#")]
    model_b = [r for r in tb if not r[0].startswith("#")]
    # the inlet gauge saw the wave rise: the records compared above are not still water (in the
    # ramp's first 0.3 s it reads 0.87 mm of the model's 3.1 mm; 1.2 mm while the buffer's
    # particles kept their heights)
    eta_model = [float(r[model_a[0].index("left_boundary_eta_model")]) for r in model_a[1:]]
    assert np.all(np.isfinite(va)) and np.ptp(va[:, 2]) > 0.2 * np.ptp(eta_model)
    col = model_a[0].index("g1_eta_model")   # named after the server's gauge, as the client's
    np.testing.assert_allclose([float(r[col]) for r in model_a[1:]],
                               [float(r[col]) for r in model_b[1:]], rtol=1e-12, atol=1e-15)
    assert alone["particles"] == coupled["particles"] and alone["steps"] == coupled["steps"]


@pytest.mark.parametrize("change, loc", [
    ({"source": None}, ["body", "source"]),
    ({"source": {**SOURCE, "H": 0.5}}, ["body", "source", "H"]),          # breaks at d = 0.3 m
    ({"source": {**SOURCE, "order": 9}}, ["body", "source", "order"]),
    ({"source": {**SOURCE, "theory": "linear"}}, ["body", "source", "order"]),  # linear has none
    ({"source": {**SOURCE, "T": -1.0}}, ["body", "source", "T"]),
    ({"source": {**SOURCE, "colour": 1}}, ["body", "source", "colour"]),
    ({"source": {**SOURCE, "theory": "cnoidal"}}, ["body", "source", "theory"]),
    ({"source": {**SOURCE, "window": 0.1}}, ["body", "source", "window"]),  # > window_max 0.05
    ({"mode": "coupled"}, ["body", "source"]),                              # a client drives it
])
def test_bad_source_is_422_naming_the_field(tmp_path, change, loc):
    body = {"scene": FLUME, "mode": "standalone", "source": SOURCE, **change}
    if body["source"] is None:
        del body["source"]
    with live_server(tmp_path) as srv:
        r = srv.http.post("/runs", json=body)
    assert r.status_code == 422, r.text
    assert r.json()["detail"][0]["loc"] == loc, r.text


def test_cancelled_theory_run_keeps_its_data_and_resumes_to_the_end(tmp_path):
    scene = {**FLUME, "t_end": 1.0}
    with live_server(tmp_path) as srv:
        run = srv.http.post("/runs", json={"scene": scene, "mode": "standalone",
                                           "source": SOURCE}).json()
        deadline = time.monotonic() + 120
        while srv.http.get(f"/runs/{run['id']}").json()["windows"] < 5:
            assert time.monotonic() < deadline, "the theory run did not progress"
            time.sleep(0.01)
        info = srv.http.delete(f"/runs/{run['id']}").json()
        info = srv.wait_state(run["id"], "cancelled")
        assert 5 <= info["windows"] < 50 and info["resumable"]
        kept = rows(tmp_path / "runs" / run["id"] / "gauges.csv")
        assert len(kept) - 1 == info["windows"]
        assert srv.http.post(f"/runs/{run['id']}/resume").status_code == 202
        done = srv.wait_state(run["id"], "finished", "failed", timeout=120)
    assert done["state"] == "finished", done["status"]
    run_dir = tmp_path / "runs" / run["id"]
    t = np.array([float(r[0]) for r in rows(run_dir / "gauges.csv")[1:]])
    assert t.size == done["windows"] == 50 and np.all(np.diff(t) > 0)
    np.testing.assert_allclose(t[-1], 1.0)
    assert (run_dir / "theory.csv").exists() and (run_dir / "theory.1.csv").exists()


def test_standalone_theory_run_waits_through_working_frames(tmp_path, factory):
    """reliability.md defect 1: a window solving longer than keepalive_every (the compile, a
    loaded machine) sends the built-in client WORKING frames; it waits, as a socket client does."""
    slow = lambda request, run_dir: factory(request, run_dir, solve_delay=0.05)  # noqa: E731
    with live_server(tmp_path, slow, keepalive_every=0.01) as srv:
        r = srv.http.post("/runs", json={"scene": {**FLUME, "t_end": 0.1}, "mode": "standalone",
                                         "source": {**SOURCE, "window": 0.05}})
        assert r.status_code == 201, r.text
        info = srv.wait_state(r.json()["id"], "finished", "failed", "unstable", timeout=60)
    assert info["state"] == "finished", info["status"]
    assert info["windows"] == 2


def test_standalone_solitary_source_brings_its_crest_to_the_inlet(tmp_path):
    """A scene's [source] theory = "solitary" (no T): the inlet gauge sees the crest at t0."""
    h, t0 = 0.06, 1.2
    scene = {**FLUME, "t_end": 1.6}
    with live_server(tmp_path) as srv:
        r = srv.http.post("/runs", json={"scene": scene, "mode": "standalone",
                                         "source": {"theory": "solitary", "H": h, "t0": t0}})
        assert r.status_code == 201, r.text
        done = srv.wait_state(r.json()["id"], "finished", "failed", "unstable", timeout=300)
    assert done["state"] == "finished", done["status"]
    table = rows(tmp_path / "runs" / done["id"] / "gauges.csv")
    col = next(i for i, name in enumerate(table[0]) if name.startswith("left_boundary")
               and "eta" in name)
    t = np.array([float(r[0]) for r in table[1:]])
    eta = np.array([float(r[col]) for r in table[1:]])
    assert abs(eta[0]) < 0.15 * h                      # the record starts near rest
    k = int(np.argmax(eta))
    x_gauge = 4 * FLUME["dp"]   # the boundary gauge stands 2h = 4 dp inside the inlet face
    assert t[k] == pytest.approx(t0 + x_gauge / np.sqrt(9.81 * (DEPTH + h)), abs=0.1), t[k]
    assert eta[k] == pytest.approx(h, rel=0.3), eta[k]
