"""The coupled 3D basin behind the real server doors: long-crested boundary data over the
unchanged protocol (PROTOCOL.md, "Three-dimensional runs"), gauges and the column's load back,
and the page's particle view as an x-z slice."""

from __future__ import annotations

import pytest

from protocol import Result, Set, Solve
from wavesph.cases.basin_3d import BASIN_WIDTH, basin_scene

from server_harness import live_server
from coupling_client import bye
from linear_wave import airy

H, T, WINDOW = 0.04, 1.4, 0.05


def test_a_3d_basin_couples_over_the_unchanged_protocol(tmp_path):
    scene = basin_scene(dp=0.06, t_end=0.2)
    scene["output"]["snapshot_every"] = 0.2
    depth = scene["still_water_level"]
    body = {"scene": scene, "mode": "coupled", "coupling": {"window_max": WINDOW}}
    with live_server(tmp_path) as srv:
        r = srv.http.post("/runs", json=body)
        assert r.status_code == 201, r.text
        run = r.json()
        c, welcome, nodes = srv.couple(run["id"], timeout=300,
                                       scene_hash=bytes.fromhex(run["scene_hash"]))
        assert sorted(set(nodes.side.tolist())) == [0, 1]       # one column of nodes per end
        assert nodes.gauge_x.size == 4    # the ends' own gauges and the two elevation probes
        t, got = 0.0, []
        for _ in range(4):
            u, w, eta = airy(nodes.x, nodes.z, t + WINDOW, H, T, depth, 9.81)
            got.append(c.request(Set(t, t + WINDOW, u, w, eta), Solve(), expect=Result))
            t += WINDOW
        bye(c)
        info = srv.wait_state(run["id"], "finished", timeout=120)
        probes = srv.http.get(f"/runs/{run['id']}/probes", params={"format": "json"}).json()
        page = srv.http.get(f"/runs/{run['id']}/particles").json()
        page_y = srv.http.get(f"/runs/{run['id']}/particles", params={"y": 0.01}).json()
        bad = srv.http.get(f"/runs/{run['id']}/particles", params={"y": "nan"})
    assert info["windows"] == 4 and info["particles"] > 1000
    assert info["stability"]["fluid_mass_ratio"] > 0.95
    assert all(r.wet[0] == 1 for r in got)                    # the inlet gauge is in the water
    assert abs(got[-1].eta[0]) < 2 * H
    cols = probes["columns"]
    assert {"column_load_fx", "column_load_fy", "column_load_fz", "column_load_mz"} <= set(cols)
    # the page: a slice within h of mid-width, the fluid in it, none of the side walls' particles
    assert page["slice"]["y"] == pytest.approx(0.5 * BASIN_WIDTH, abs=0.06)
    assert 0 in page["kind"] and len(page["x"]) > 50
    assert page_y["slice"]["y"] == 0.01 and len(page_y["x"]) != len(page["x"])
    assert bad.status_code == 422
