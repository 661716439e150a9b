"""The project's own coupling client (wave_client) against the real server doors (engine: test
double). Proves both sides of the protocol agree when written by different hands."""

from __future__ import annotations

import json

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


def test_wavesph_couple_waits_while_its_run_is_queued(tmp_path, factory, capsys, monkeypatch):
    """Issue 15: `wavesph couple` on a queued run waits (saying so) and then couples. The
    server's WORKING frames (1.1 KEEPALIVE) make it say once that the server prepares the run
    (ux.md F3: not a misleading "queued" line every 10 s)."""
    import argparse
    import threading

    import httpx

    from server_harness import live_server
    from wavesph.cli import couple as couple_cli
    from wave_client.coupling import runner

    monkeypatch.setattr(runner, "WAIT_NOTE_EVERY", 0.2)
    with live_server(tmp_path, factory, max_waiting=1, keepalive_every=0.1) as srv:
        blocker = srv.create()
        srv.wait_state(blocker["id"], "waiting_for_client")
        run = srv.create(t_end=0.1)
        assert srv.http.get(f"/runs/{run['id']}").json()["state"] == "queued"
        parser = argparse.ArgumentParser()
        couple_cli.add_arguments(parser)
        args = parser.parse_args(["--url", f"ws://127.0.0.1:{srv.port}/runs/{run['id']}/couple",
                                  "--model", "linear", "--H", "0.02", "--T", "1.0",
                                  "--window", "0.05", "--timeout", "20", "--queue-timeout", "30"])
        # the run starts only when the blocker ends, a second or so after the client came; the
        # timer thread has its own HTTP client (sharing srv.http across threads broke its socket)
        deleted: list[int] = []

        def end_blocker() -> None:
            with httpx.Client(base_url=srv.url, headers=srv.http.headers, timeout=30) as http:
                deleted.append(http.delete(f"/runs/{blocker['id']}").status_code)

        timer = threading.Timer(1.0, end_blocker)
        timer.start()
        assert couple_cli.main(args) == 0
        timer.join(30)
        assert deleted and 200 <= deleted[0] < 300, deleted
        assert srv.wait_state(run["id"], "finished")["windows"] == 2
    err = capsys.readouterr().err
    assert err.count("the server is preparing the run") == 1, err
    assert "no WELCOME yet" not in err  # WORKING came every 0.1 s: the server was never silent


def test_wave_client_names_its_log_columns_from_gauges(srv, engines, tmp_path):
    """Issue 15 / protocol 1.1: the client asks GETGAUGES when the server grants GAUGE_INFO and
    its gauges.csv names the columns after the server's gauges, not their indices."""
    run = srv.create(t_end=0.1)
    srv.wait_state(run["id"], "waiting_for_client")
    log = tmp_path / "client_gauges.csv"
    report = couple(f"tcp://127.0.0.1:{srv.tcp_port}", AiryWave(height=0.02, period=1.0, depth=0.3),
                    CouplingOptions(window=0.05), run_id=run["id"], timeout=20.0, progress=False,
                    log_path=log)
    assert len(report.records) == 2
    names = list(srv.http.get(f"/runs/{run['id']}/gauges", params={"format": "json"})
                 .json()["rows"][0])
    server_gauges = sorted({c[: -len("_eta")] for c in names if c.endswith("_eta")})
    text = log.read_text()
    header = next(ln for ln in text.splitlines() if not ln.startswith("#")).split(",")
    # <gauge>_<quantity>, the rule of gauges.csv and probes.csv
    assert sorted(c[: -len("_eta_model")] for c in header if c.endswith("_eta_model")) == server_gauges
    assert {f"{g}_{q}" for g in server_gauges for q in ("eta", "u_ref", "w_ref")} <= set(header)
    assert "0_eta" not in header and "#" not in text   # one header row, no comment lines
    meta = json.loads(log.with_suffix(".meta.json").read_text())
    assert sorted(g["name"] for g in meta["gauges"]) == server_gauges   # fields beside the CSV
    assert meta["model"] == {"name": "AiryWave", "parameters": meta["model"]["parameters"]}
    assert meta["model"]["parameters"]["height"] == 0.02 and " at 0x" not in json.dumps(meta)
