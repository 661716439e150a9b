"""GET /runs/{id}/bodies: a run's rigid-body series, read like its gauges (issue 14)."""

from __future__ import annotations

import pytest


def test_standalone_run_serves_its_body_series(srv):
    box = {"name": "box", "shape": "box", "x0": 0.4, "x1": 0.6, "z0": 0.2, "z1": 0.4,
           "density": 500.0, "dofs": ["heave"]}
    run = srv.create(mode="standalone", t_end=0.1, bodies=[box])
    srv.wait_state(run["id"], "finished")
    csv = srv.http.get(f"/runs/{run['id']}/bodies").text.splitlines()
    assert csv[0].startswith("t,step,box_x,box_z,box_theta")
    assert len(csv) == 1 + 3  # t = 0, 0.05, 0.1
    rows = srv.http.get(f"/runs/{run['id']}/bodies", params={"format": "json"}).json()["rows"]
    assert rows[-1]["t"] == pytest.approx(0.1)
    assert rows[0]["box_fz"] > 0  # buoyancy
    plain = srv.create(mode="standalone", t_end=0.05)
    srv.wait_state(plain["id"], "finished")
    assert srv.http.get(f"/runs/{plain['id']}/bodies").status_code == 404
