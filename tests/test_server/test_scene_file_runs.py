"""TOML first (issue 16 item 4): a scene file is the run's one record. POST /runs takes it as it
is (Content-Type application/toml: its mode, [coupling] and [source] beside the scene),
`wavesph submit` sends it, `wavesph couple --scene` creates the coupled run and couples to it."""

from __future__ import annotations

import re
from pathlib import Path

import wavesph.cli

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "examples" / "scenes" / "demo_beach_flume.toml"
TOML = {"Content-Type": "application/toml"}


def _request(srv, run_id: str):
    return srv.manager.runs[run_id].request


def test_post_runs_takes_a_scene_file_as_toml(srv):
    r = srv.http.post("/runs", content=DEMO.read_bytes(), headers=TOML)
    assert r.status_code == 201, r.text
    info = r.json()
    assert info["mode"] == "coupled"          # open ends, no [source]: coupled
    req = _request(srv, info["id"])
    assert (req.coupling.window_max, req.coupling.z_ref) == (0.05, -0.12)   # the file's [coupling]
    assert req.scene.still_water_level == 0.24
    bad = srv.http.post("/runs", content=b"dp = [", headers=TOML)
    assert bad.status_code == 400 and "not TOML" in bad.json()["detail"]
    wrong = srv.http.post("/runs", headers=TOML, content=DEMO.read_bytes().replace(
        b"still_water_level = 0.24", b"still_water_level = 0.6"))   # above the tank: named, 422
    assert wrong.status_code == 422 and "still_water_level" in wrong.text


def test_submit_sends_the_file_with_a_source(srv, capsys):
    code = wavesph.cli.main(["submit", str(DEMO), "--url", srv.url, "--source", "stokes",
                             "--H", "0.04", "--T", "1.4", "--order", "2"])
    out = capsys.readouterr().out
    assert code == 0, out
    run_id = re.search(r"run (\S+) \(standalone", out).group(1)
    src = _request(srv, run_id).source
    assert (src.theory, src.H, src.T, src.order) == ("stokes", 0.04, 1.4, 2)


def test_submit_errors_are_one_line(srv, tmp_path, capsys):
    assert wavesph.cli.main(["submit", str(tmp_path / "none.toml"), "--url", srv.url]) == 2
    assert wavesph.cli.main(["submit", str(DEMO), "--url", srv.url, "--H", "0.04"]) == 2
    bad = tmp_path / "bad.toml"
    bad.write_text(DEMO.read_text().replace("window_max = 0.05", "window_max = -1.0"))
    assert wavesph.cli.main(["submit", str(bad), "--url", srv.url]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 3 and "coupling.window_max" in err[2] and "HTTP 422" in err[2]
    assert wavesph.cli.main(["submit", str(DEMO), "--url", "http://127.0.0.1:9"]) == 1
    assert "cannot reach the server" in capsys.readouterr().err


def test_couple_scene_creates_the_run_and_couples_to_it(srv, tmp_path, capsys):
    log = tmp_path / "client.csv"
    code = wavesph.cli.main(["couple", "--scene", str(DEMO), "--url", srv.url, "--model", "linear",
                             "--H", "0.01", "--T", "1.4", "--t-end", "0.5", "--no-progress",
                             "-o", str(log)])
    err = capsys.readouterr().err
    assert code == 0, err
    run_id = re.search(r"created run (\S+) from", err).group(1)
    assert _request(srv, run_id).coupling.z_ref == -0.12
    assert log.read_text().startswith("t,steps,")     # one header row, no comment lines
    assert log.with_suffix(".meta.json").exists()


def test_couple_scene_takes_the_file_submit_runs(srv, tmp_path, capsys):
    # one file for both: `submit` runs its [source]; `couple --scene` leaves the source and mode
    # out (its --model drives the run) and says so, instead of the server's 422
    both = tmp_path / "both.toml"
    both.write_text('mode = "standalone"\n' + DEMO.read_text()
                    + '\n[source]\ntheory = "stokes"\nH = 0.04\nT = 1.4\norder = 2\n')
    assert wavesph.cli.main(["submit", str(both), "--url", srv.url]) == 0
    assert "(standalone" in capsys.readouterr().out
    code = wavesph.cli.main(["couple", "--scene", str(both), "--url", srv.url, "--model", "linear",
                             "--H", "0.01", "--T", "1.4", "--t-end", "0.2", "--no-progress"])
    err = capsys.readouterr().err
    assert code == 0, err
    assert "mode and source left out" in err
    run_id = re.search(r"created run (\S+) from", err).group(1)
    req = _request(srv, run_id)
    assert req.mode == "coupled" and req.source is None and req.coupling.z_ref == -0.12
