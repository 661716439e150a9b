"""The project's own coupling client (wave_client) against the real server doors (engine: test
double). Proves both sides of the protocol agree when written by different hands."""

from __future__ import annotations

import numpy as np
import pytest

from wave_client.coupling import CouplingOptions, couple
from wave_client.theories.linear import AiryWave


@pytest.mark.parametrize("door", ["tcp", "ws"])
def test_wave_client_couples_an_airy_wave(srv, engines, door):
    run = srv.create(t_end=0.3)
    srv.wait_state(run["id"], "waiting_for_client")
    url = (f"tcp://127.0.0.1:{srv.tcp_port}" if door == "tcp"
           else f"ws://127.0.0.1:{srv.port}/runs/{run['id']}/couple")
    wave = AiryWave(height=0.02, period=1.0, depth=0.3)
    report = couple(url, wave, CouplingOptions(window=0.05), run_id=run["id"],
                    scene_hash=bytes.fromhex(run["scene_hash"]), timeout=20.0, progress=False)
    info = srv.wait_state(run["id"], "finished")
    assert info["windows"] == len(report.records) == 6 and info["t"] == pytest.approx(0.3)
    # the double reports the imposed inlet elevation (x = 0): the Airy surface at each window end
    t1 = 0.05 * np.arange(1, 7)
    expected = 0.01 * np.cos(-wave.omega * t1)
    rows = srv.http.get(f"/runs/{run['id']}/gauges", params={"format": "json"}).json()["rows"]
    np.testing.assert_allclose([r["g_mid_eta"] for r in rows], expected, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(report.t, t1)
    assert engines[0].steps == 300
