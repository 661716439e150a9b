"""The C example client couples to the real server over the plain TCP port (engine: test double)."""

from __future__ import annotations

import subprocess

import numpy as np
import pytest

from server_harness import live_server



def test_c_client_against_the_server(srv, engines, c_client):
    run = srv.create()
    srv.wait_state(run["id"], "waiting_for_client")
    out = subprocess.run([str(c_client), "127.0.0.1", str(srv.tcp_port), run["id"], "6",
                          "0.02", "1.0", "0.05"], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    lines = [line.split() for line in out.stdout.splitlines()]
    assert len(lines) == 6 and all(w[0] == "RESULT" and w[4] == "dry" for w in lines)
    info = srv.wait_state(run["id"], "finished")
    assert info["windows"] == 6 and info["client"] == "wsph_client.c 1.0"
    # the double echoes the node-mean imposed eta: the C client's Airy elevation at the inlet
    engine = engines[0]
    t, _, eta = np.array(engine.imposed).T
    window_end_eta = eta[49::50]
    np.testing.assert_allclose([float(w[3]) for w in lines], window_end_eta, rtol=1e-12)
    assert np.ptp(window_end_eta) > 0.005  # a wave of H = 0.02 m actually went through
    rows = srv.http.get(f"/runs/{run['id']}/gauges", params={"format": "json"}).json()["rows"]
    assert [r["g_mid_eta"] for r in rows] == pytest.approx([float(w[3]) for w in lines], rel=1e-12)


def test_c_client_drives_the_sph_flume(tmp_path, c_client):
    """The real thing: C client -> TCP port -> server -> an sph_core Simulation with open ends, and back."""
    from test_server_flume import FLUME, WINDOW

    with live_server(tmp_path) as srv:
        r = srv.http.post("/runs", json={"scene": FLUME, "coupling": {"window_max": WINDOW}})
        run = r.json()
        srv.wait_state(run["id"], "waiting_for_client", timeout=120)
        out = subprocess.run([str(c_client), "127.0.0.1", str(srv.tcp_port), run["id"], "4",
                              "0.02", "1.0", str(WINDOW)], capture_output=True, text=True, timeout=300)
        assert out.returncode == 0, out.stderr
        info = srv.wait_state(run["id"], "finished")
        rows = srv.http.get(f"/runs/{run['id']}/gauges", params={"format": "json"}).json()["rows"]
    lines = [line.split() for line in out.stdout.splitlines()]
    assert info["windows"] == len(rows) == len(lines) == 4 and info["steps"] > 4
    for words, row in zip(lines, rows):
        assert float(words[1]) == pytest.approx(row["t"], abs=1e-12) and int(words[2]) > 0
        assert float(words[3]) == pytest.approx(row["left_boundary_eta"], rel=1e-12)


def test_c_client_gets_a_clear_error_for_an_unknown_run(srv, c_client):
    out = subprocess.run([str(c_client), "127.0.0.1", str(srv.tcp_port), "no-such-run", "3"],
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 3
    assert "server error 15: no run 'no-such-run' on this server" in out.stderr
