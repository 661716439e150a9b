"""Post-processing a run (issue 27 item 13): wave height and period per gauge, mean overtopping
discharge, load peaks; the functions and `wavesph analyse RUN_DIR`. Records are synthetic, with
answers known in closed form."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import wavesph
import wavesph.cli
from wavesph.analysis import analyse_run, mean_overtopping, peaks, runup_statistics, wave_statistics

T, DT = 1.5, 0.01


def test_regular_wave_statistics():
    t = np.arange(0.0, 20 * T, DT)          # 20 whole periods
    eta = 0.05 * np.sin(2 * math.pi * t / T)
    s = wave_statistics(t, eta)
    assert s.Hm0 == pytest.approx(4 * 0.05 / math.sqrt(2), rel=1e-3)   # 4 sqrt(m0) of a sine
    assert s.Tp == pytest.approx(T, rel=1e-9)
    assert s.H1_3 == pytest.approx(0.1, rel=1e-3) and s.Hmax == pytest.approx(0.1, rel=1e-3)
    assert s.Tm == pytest.approx(T, rel=1e-6) and s.n_waves == 19


def test_one_high_wave_sets_hmax_and_h13():
    # period k has amplitude a_k; a zero-down-crossing wave spans the trough of period k and the
    # crest of k + 1, so its height is a_k + a_(k+1): one 0.1 amplitude gives two 0.15 waves
    amps = [0.05] * 9 + [0.1] + [0.05] * 10
    t = np.arange(0.0, len(amps) * T, DT)
    eta = np.array(amps)[(t // T).astype(int)] * np.sin(2 * math.pi * t / T)
    s = wave_statistics(t, eta)
    heights = sorted([0.15, 0.15] + [0.1] * 17, reverse=True)
    assert s.Hmax == pytest.approx(0.15, rel=2e-3)
    assert s.H1_3 == pytest.approx(np.mean(heights[:19 // 3]), rel=2e-3)


def test_a_dry_or_uneven_record_is_refused():
    t = np.arange(0.0, 10.0, DT)
    eta = 0.01 * np.sin(t)
    eta[5] = np.nan
    with pytest.raises(ValueError, match="dry"):
        wave_statistics(t, eta)
    with pytest.raises(ValueError, match="uniformly"):
        wave_statistics(t ** 1.1, 0.01 * np.sin(t))


def test_mean_overtopping_is_the_volume_change_over_the_time():
    t = np.arange(0.0, 10.0 + DT / 2, DT)
    volume = np.where(t > 2.0, 0.002 * (t - 2.0), 0.0)   # 0.002 m^2/s from t = 2 s
    assert mean_overtopping(t, volume, t_from=2.0) == pytest.approx(0.002, rel=1e-9)
    assert mean_overtopping(t, volume) == pytest.approx(0.002 * 8 / 10, rel=1e-9)


def test_load_peaks_per_period():
    t = np.arange(0.0, 10 * T + DT / 2, DT)   # 10 whole periods, the end sample included
    k = (t // T).astype(int)
    force = 100.0 + (10.0 + k) * np.sin(2 * math.pi * t / T)   # period maxima 110 ... 119
    p = peaks(t, force, period=T)
    assert p.max == pytest.approx(119.0, rel=1e-4) and p.t_max == pytest.approx(9.25 * T, abs=DT)
    assert p.n_periods == 10 and p.mean_of_period_maxima == pytest.approx(114.5, rel=1e-4)
    assert p.highest_tenth_mean == pytest.approx(119.0, rel=1e-4)


def test_runup_ru2_is_the_two_percent_event_of_the_incident_waves():
    # 100 swash cycles, the k-th reaching 0.01 k m above still water (order shuffled)
    rng = np.random.default_rng(3)
    heights = rng.permutation(0.01 * np.arange(1, 101))
    t = np.arange(0.0, 100 * T, DT)
    k = np.minimum((t // T).astype(int), 99)
    rise = heights[k] * np.sin(2 * np.pi * t / T)
    r = runup_statistics(t, rise)
    whole = np.sort(heights[1:-1])[::-1]    # events between up-crossings: the ends are cut
    assert r.n_events == 98 and r.n_waves == 98
    assert r.Rmax == pytest.approx(whole[0], abs=2e-3)
    # 2 % of 98 events -> rank 2 from the top; of 200 incident waves -> rank 4
    assert r.Ru2 == pytest.approx(whole[1], abs=2e-3)
    assert runup_statistics(t, rise, n_waves=200).Ru2 == pytest.approx(whole[3], abs=2e-3)
    with pytest.raises(ValueError, match="up-crossings"):
        runup_statistics(t[:10], rise[:10])


def _run_dir(tmp_path):
    t = np.arange(0.0, 12 * T, DT)
    cols = {"t": t, "step": np.arange(t.size),
            "flat_z_surface": 0.3 + 0.03 * np.sin(2 * math.pi * t / T),
            "flat_eta": 0.03 * np.sin(2 * math.pi * t / T),
            "wall_fx": 50 + 5 * np.sin(2 * math.pi * t / T), "wall_fz": 0 * t, "wall_my": 0 * t,
            "line_p0": 1000 + 100 * np.cos(2 * math.pi * t / T),
            "crest_q": 0.001 + 0 * t, "crest_volume": 0.001 * t,
            "shore_x": 0 * t, "shore_z": 0.3 + 0.04 * np.sin(2 * math.pi * t / T), "shore_R": 0 * t}
    run = tmp_path / "run"
    run.mkdir()
    lines = [",".join(cols)] + [",".join(f"{cols[c][i]:.12g}" for c in cols) for i in range(t.size)]
    (run / "probes.csv").write_text("\n".join(lines) + "\n")
    (run / "meta.json").write_text(json.dumps({"config": {"still_water_level": 0.3}}))
    return run


def test_analyse_run_reads_a_run_directory(tmp_path):
    res = analyse_run(_run_dir(tmp_path), t_from=3.0, period=T)
    assert res["files"] == ["probes.csv"]
    assert res["waves"]["flat"]["H1_3"] == pytest.approx(0.06, rel=1e-3)
    assert res["overtopping"]["crest"]["q_m2_s"] == pytest.approx(0.001, rel=1e-6)
    assert res["loads"]["wall_fx"]["max"] == pytest.approx(55.0, rel=1e-4)
    assert res["loads"]["line_p0"]["min"] == pytest.approx(900.0, rel=1e-4)
    assert "flat_z_surface" not in res["loads"] and "crest_q" not in res["loads"]
    assert res["runup"]["shore"]["Rmax"] == pytest.approx(0.04, rel=1e-3)
    assert res["runup"]["shore"]["n_waves"] == res["waves"]["flat"]["n_waves"]
    assert wavesph.analyse(tmp_path / "run", t_from=3.0)["waves"].keys() == {"flat"}


def test_analyse_command(tmp_path, capsys):
    run = _run_dir(tmp_path)
    assert wavesph.cli.main(["analyse", str(run), "--from", "3", "--period", str(T)]) == 0
    out = capsys.readouterr().out
    assert "Hm0 [m]" in out and "flat" in out and "mean q [m^2/s]" in out and "wall_fx" in out
    assert "Ru2% [m]" in out and "shore" in out
    assert wavesph.cli.main(["analyse", str(run), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["waves"]["flat"]["n_waves"] == 11
    assert wavesph.cli.main(["analyse", str(tmp_path)]) == 2
    assert "no probes.csv" in capsys.readouterr().err
