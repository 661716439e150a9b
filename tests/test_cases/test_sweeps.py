"""The sweep machinery (wavesph.studies.sweeps on dask), the stability suite's records and
`wavesph plan`.

Default suite: a 3-point sweep of tiny dam breaks on a LocalCluster (one point fails on purpose),
resume, the CSV and chart; one stability scenario; the plan's arithmetic and JSON. Slow: the
quick presets end to end and the plan against measured runs (test_plan_predictions_slow).
"""

from __future__ import annotations

import csv
import datetime
import json
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest

from wavesph.studies import planning
from wavesph.studies import stability, sweeps
from wavesph.studies.sweeps import ACCURACY_COLUMNS, Point

ROOT = Path(__file__).resolve().parents[2]
TINY = {"a": 0.1}   # a 0.1 m column: 32 particles at dp = 0.025


def _boom(point: Point) -> dict:
    raise AssertionError("a finished point was run again")


@pytest.fixture(scope="module")
def swept(tmp_path_factory):
    out = tmp_path_factory.mktemp("sweep")
    points = [Point("dambreak", "wcsph_kdk", 0.025, TINY),
              Point("dambreak", "wcsph_symplectic", 0.025, TINY),
              Point("dambreak", "wcsph_kdk", 0.5, TINY)]   # dp wider than the column: fails
    records = sweeps.run_sweep(points, out, n_workers=2, progress=False)
    return out, points, records


def test_sweep_records_every_point_and_a_failure_does_not_stop_it(swept):
    out, points, records = swept
    assert [r["key"] for r in records] == [p.key for p in points]
    ok, also_ok, failed = records
    for r in (ok, also_ok):
        assert r["status"] == "ok", r
        assert 0 < r["error"] < 1 and math.isfinite(r["error"])
        assert r["wall_s"] > 0 and r["particles"] > 0 and r["steps"] > 0
        assert r["H_over_dp"] == pytest.approx(8.0)
    assert failed["status"] == "failed"
    assert "water_blocks" in failed["reason"]     # the scene's own error names the field
    assert sorted(p.name for p in (out / "points").iterdir()) == sorted(
        f"{p.key}.json" for p in points)


def test_sweep_resumes_without_rerunning_finished_points(swept):
    out, points, records = swept
    assert sweeps.pending(points, out) == []
    again = sweeps.run_sweep(points, out, runner=_boom, progress=False)   # no cluster, no run
    assert again == records
    assert sweeps.pending(points, out, retry_failed=True) == [points[2]]
    (out / "points" / f"{points[0].key}.json").unlink()
    assert sweeps.pending(points, out) == [points[0]]


def test_sweep_csv_and_chart(swept, tmp_path):
    out, points, records = swept
    path = tmp_path / "accuracy.csv"
    sweeps.write_csv(records, path, command="wavesph bench accuracy --test")
    assert path.read_text().startswith("case,method,")     # one header row, no # line
    meta = json.loads(path.with_suffix(".meta.json").read_text())
    assert meta["made_by"] == "wavesph bench accuracy --test"
    # the chart says when and where its wall times were taken (a loaded machine's are slower)
    assert meta["date"] == datetime.datetime.now(datetime.timezone.utc).date().isoformat()
    assert f"{os.cpu_count()} cores" in meta["machine"] and "load average" in meta["machine"]
    assert sweeps.chart_title(meta).splitlines() == [meta["made_by"], meta["date"], meta["machine"]]
    assert sweeps.chart_title({"made_by": "x"}) == "x"     # a table of an earlier version
    import pandas

    assert pandas.read_csv(path).shape == (3, len(ACCURACY_COLUMNS))
    rows = sweeps.read_csv(path)
    assert list(rows[0]) == ACCURACY_COLUMNS
    assert [r["status"] for r in rows] == ["ok", "ok", "failed"]
    assert rows[0]["error"] == pytest.approx(records[0]["error"], rel=1e-5)
    png = tmp_path / "accuracy.png"
    sweeps.plot_accuracy(records, png)
    assert png.stat().st_size > 10_000


def test_presets_cover_every_method_and_case():
    full = sweeps.accuracy_points(quick=False)
    cases = {p.case for p in full}
    assert cases == {f"flume_{c}" for c in sweeps.FLUME_CASES} | {"dambreak", "coupled"}
    for case in cases - {"coupled"}:
        for m in sweeps.METHODS:
            assert len({p.dp for p in full if p.case == case and p.method == m}) >= 3, (case, m)
    assert {p.method for p in full if p.case == "coupled"} == set(sweeps.COUPLED_METHODS)
    assert len({p.key for p in full}) == len(full)
    with pytest.raises(ValueError, match="unknown methods"):
        sweeps.accuracy_points(methods=["no_such_scheme"])
    # a subset of the cases: the same points as the preset's, nothing else
    some = sweeps.accuracy_points(quick=False, cases=["flume_V", "dambreak"])
    assert some == [p for p in full if p.case in ("flume_V", "dambreak")]
    with pytest.raises(ValueError, match="unknown cases"):
        sweeps.accuracy_points(cases=["flume_VII"])


def test_repeats_are_other_realisations_and_the_chart_shows_their_scatter(tmp_path):
    one = sweeps.accuracy_points(quick=True)
    two = sweeps.accuracy_points(quick=True, repeats=2)
    assert two[: len(one)] == one and len(two) == 2 * len(one)
    assert len({p.key for p in two}) == len(two)             # each repeat has its own record
    for p, q in zip(one, two[len(one):]):
        assert (q.case, q.method, q.dp, q.repeat) == (p.case, p.method, p.dp, 1)
        if p.case.startswith("flume_"):   # a round-off-sized change: another realisation
            assert q.options["ramp_periods"] == pytest.approx(
                p.options["ramp_periods"] * (1 + sweeps.REPEAT_RAMP_STEP))
        else:
            assert q.options == p.options
    assert sweeps.point_from_dict({"case": "flume_V", "method": "m", "dp": 0.02,
                                   "repeat": 1}).key.endswith("__r1")
    with pytest.raises(ValueError, match="repeats"):
        sweeps.accuracy_points(quick=True, repeats=0)

    def rec(dp, repeat, err, wall, status="ok"):
        return {"case": "flume_V", "method": "wcsph_kdk", "dp": dp, "repeat": repeat,
                "H_over_dp": 0.06 / dp, "error": err, "wall_s": wall, "status": status}

    records = [rec(0.02, 0, 0.05, 10.0), rec(0.02, 1, 0.07, 14.0), rec(0.02, 2, 0.06, 12.0),
               rec(0.01, 0, 0.03, 80.0), rec(0.01, 1, None, None, "unstable")]
    # three equal errors whose mean rounds above them (a deterministic case repeated): no
    # negative bar
    same = [rec(0.005, j, 0.7767689168250291, 0.48950868077918164) for j in range(3)]
    g = sweeps.repeat_groups(same)[0]
    assert g["error"] > g["error_max"] and g["wall_s"] < g["wall_min"]
    groups = sweeps.repeat_groups(records)
    assert [(g["dp"], g["n"]) for g in groups] == [(0.02, 3), (0.01, 1)]
    g = groups[0]
    assert (g["error"], g["error_min"], g["error_max"]) == pytest.approx((0.06, 0.05, 0.07))
    assert (g["wall_s"], g["wall_min"], g["wall_max"]) == pytest.approx((12.0, 10.0, 14.0))
    path = tmp_path / "accuracy.csv"
    sweeps.write_csv(records, path)
    assert [r["repeat"] for r in sweeps.read_csv(path)] == [0, 1, 2, 0, 1]
    png = tmp_path / "accuracy.png"
    sweeps.plot_accuracy(records + same, png)
    assert png.stat().st_size > 10_000
    # a case none of whose points ran through (ISPH's wave settings on the dam break) is an
    # empty panel beside the others: the sweep's chart is still drawn
    failed = [{**rec(0.1, j, None, None, "unstable"), "case": "dambreak"} for j in range(2)]
    sweeps.plot_accuracy(records + failed, png)
    assert png.stat().st_size > 10_000


def test_stability_unstable_run_has_a_reason_and_no_nan(tmp_path):
    """CFL 1.5 (three times the scene's limit, set through the suite's unchecked path) blows the
    dam break up: status unstable, the solver's cause and time, finite numbers only."""
    rec = stability.run_scenario(Point("stability_cfl_1.5", "wcsph_kdk", 0.0, {"quick": True}))
    assert rec["status"] == "unstable", rec
    assert rec["reason"] and 0 < rec["t_fail"] < rec["t_end"]
    stability.assert_finite(rec)
    path = tmp_path / "stability.csv"
    stability.write_stability_csv([rec], path)
    with open(path) as fh:
        row = next(csv.DictReader(fh))
    assert list(row)[:5] == ["scenario", "method", "status", "t_fail", "reason"]
    assert "nan" not in path.read_text().lower()
    stability.plot_stability([rec], tmp_path / "stability.png")
    assert (tmp_path / "stability.png").exists()


def test_stability_override_is_explicit():
    from wavesph.cases.dambreak import dambreak_scene
    from sph_core.scene import SceneError

    with pytest.raises(SceneError, match="cfl"):
        dambreak_scene(a=0.1, dp=0.025, cfl=1.5)
    scene = stability.unchecked(dambreak_scene(a=0.1, dp=0.025), cfl=1.5)
    assert scene.constants.cfl == 1.5


# ---------------------------------------------------------------------------- plan
PLANNED = "wcsph_kdk_h2_wallav0"   # the scene defaults' method; wcsph_kdk is SUPERSEDED


def _synthetic(tmp_path: Path, a: float = 0.3, p: float = 1.0, tp: float = 1.0e6) -> Path:
    """A sweep CSV whose flume points lie exactly on error = a (H/dp)^-p at throughput tp."""
    path = tmp_path / "sweep.csv"
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=ACCURACY_COLUMNS)
        w.writeheader()
        for r in (2.0, 4.0, 8.0):
            w.writerow({"case": "flume_V", "method": PLANNED, "dp": 0.06 / r, "H_over_dp": r,
                        "error": a * r ** -p, "wall_s": 10.0, "particles": 1000,
                        "steps": int(tp * 10 / 1000), "status": "ok", "reason": ""})
    return path


def test_plan_reaches_the_target_on_the_fitted_line(tmp_path):
    data = sweeps.read_csv(_synthetic(tmp_path))
    fit = planning.fit_error(data, PLANNED)
    assert fit["a"] == pytest.approx(0.3) and fit["p"] == pytest.approx(1.0)
    assert (fit["H_over_dp_min"], fit["H_over_dp_max"]) == pytest.approx((2.0, 8.0))
    req = planning.PlanRequest(height=0.06, period=2.0, depth=0.3, duration=10.0, target_error=0.05)
    plan = planning.make_plan(req, data)
    assert plan.method == PLANNED              # the only method with data
    assert plan.dp == pytest.approx(0.01)      # H/dp = 0.3 / 0.05 = 6
    assert plan.expected_error == pytest.approx(0.05, rel=1e-3) and plan.meets_target
    assert plan.zone_length_m == pytest.approx(plan.wavelength_m, abs=0.01)   # no structure
    dt = planning.step_estimate(0.01, 0.3, 0.06, 2.0, PLANNED)
    assert plan.steps == math.ceil(10.0 / dt)
    assert plan.expected_wall_s == pytest.approx(plan.particles * plan.steps / 1.0e6, rel=1e-3)
    assert plan.window_steps == round(2.0 / 50 / dt)
    # 0.025 needs H/dp 12, beyond the measured 8: the finest measured, and said not to meet it
    finer = planning.make_plan(req.__class__(**{**req.__dict__, "target_error": 0.025}), data)
    assert finer.dp == pytest.approx(0.0075) and not finer.meets_target
    assert finer.expected_error == pytest.approx(0.3 / 8, rel=1e-3)
    # 0.2 would be H/dp 1.5, below the measured 2: no coarser than measured
    coarse = planning.make_plan(req.__class__(**{**req.__dict__, "target_error": 0.2}), data)
    assert coarse.dp == pytest.approx(0.03) and coarse.meets_target


def test_plan_dp_divides_the_depth_and_counts_steps_at_the_scenes_c0(tmp_path):
    data = sweeps.read_csv(_synthetic(tmp_path))
    # H/dp 6 asks for dp 0.04 / 6 = 0.00667 in 0.25 m (37.5 rows): the next divisor is 0.25 / 38
    req = planning.PlanRequest(height=0.04, period=2.0, depth=0.25, duration=10.0)
    plan = planning.make_plan(req, data)
    assert round(0.25 / plan.dp, 3) == 38 and plan.expected_error <= 0.05
    # ... written so that a scene accepts it: 0.3 m / 17 rounded to 0.01765 fills to 0.30005 m
    # and the scene refuses it (datum_mismatch)
    from sph_core.scene import datum_mismatch

    odd = planning.make_plan(planning.PlanRequest(height=0.06, period=2.0, depth=0.3,
                                                  duration=10.0, target_error=0.3 / 3.4), data)
    assert round(0.3 / odd.dp) == 17 and datum_mismatch(0.3, 0.3, 0.0, odd.dp) is None
    assert datum_mismatch(0.25, 0.25, 0.0, plan.dp) is None
    # a scene's default c0 is 10 sqrt(2 g d), sqrt 2 that of the plan's own flumes: as many more
    # steps (the review measured x1.49 more than `plan` predicted)
    fast = planning.make_plan(req, data, dp=0.01)
    slow = planning.make_plan(req.__class__(**{**req.__dict__, "c0": math.sqrt(2) * fast.c0}),
                              data, dp=0.01)
    assert slow.steps / fast.steps == pytest.approx(math.sqrt(2), rel=0.03)


def test_plan_of_a_scene_stays_inside_it_and_proposes_no_superseded_or_flume_sized_method(tmp_path):
    from sph_core.scene import load_scene

    data = sweeps.read_csv(_synthetic(tmp_path))
    old = [{**r, "method": "wcsph_kdk", "error": 0.5 * r["error"], "steps": 10 * r["steps"]}
           for r in data]                       # better and faster, but the pre-study defaults
    scene = load_scene(ROOT / "examples/scenes/demo_beach_flume.toml")
    short = scene.model_copy(update={"beds": [scene.beds[0].model_copy(update={
        "points": [(1.0, 0.0), (5.4, 0.44)]})]})      # only 1 m of flat: less than a wavelength
    # ISPH's wave settings: its zones and ramp are sized to each flume, which the plan's zone
    # scene does not do
    isph = [{**r, "method": "isph_waves", "error": 0.5 * r["error"], "steps": 10 * r["steps"]}
            for r in data]
    plan = planning.make_plan(planning.request_from_scene(short, 0.04, 1.4), data + old + isph)
    assert plan.method == PLANNED
    assert plan.flat_m == pytest.approx(1.0) and plan.structures_m == pytest.approx(4.4)
    assert plan.zone_length_m <= short.tank.x1 - short.tank.x0 + plan.dp


def test_plan_skips_unstable_and_barely_converging_methods(tmp_path):
    """A method whose flume points ended unstable is not planned; one whose fit barely
    converges (p 0.04 asked for dp ~1e-5 m, and a lattice of terabytes, before the plan kept to
    the measured H/dp) is proposed only at its finest measured H/dp, as missing the target."""
    good = sweeps.read_csv(_synthetic(tmp_path))
    flat = [{**r, "method": "riemann_muscl", "error": 0.3 * r["H_over_dp"] ** -0.04} for r in good]
    shaky = [{**r, "method": "isph_bicgstab", "error": 0.2 * r["H_over_dp"] ** -2.0} for r in good]
    shaky[-1] = {**shaky[-1], "status": "unstable", "error": None}
    req = planning.PlanRequest(height=0.06, period=2.0, depth=0.3, duration=10.0, target_error=0.05)
    plan = planning.make_plan(req, good + flat + shaky)
    assert plan.method == PLANNED and plan.dp == pytest.approx(0.01)
    alone = planning.make_plan(req, flat + shaky)
    assert alone.method == "riemann_muscl" and alone.H_over_dp == pytest.approx(8.0)
    assert not alone.meets_target and alone.expected_error > 0.2
    with pytest.raises(ValueError):
        planning.make_plan(req, shaky)


def test_plan_cli_json_for_the_demo_scene(tmp_path):
    data = _synthetic(tmp_path)
    cmd = [sys.executable, "-m", "wavesph", "plan", str(ROOT / "examples/scenes/demo_beach_flume.toml"),
           "--height", "0.04", "--period", "1.4", "--json", "--data", str(data)]
    res = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=300,
                         env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"})
    assert res.returncode == 0, res.stderr
    out = json.loads(res.stdout)
    for key in ("dp", "zone_length_m", "window_steps", "method", "expected_error",
                "expected_wall_s", "particles", "steps", "scene"):
        assert key in out
    assert out["dp"] == pytest.approx(0.04 / 6, rel=0.02)
    # the zone: one wavelength of flat bed (2.0 m at T = 1.4 s, d = 0.24 m) and the demo's beach
    assert 5.0 < out["zone_length_m"] < 5.8
    assert out["scene"]["dp"] == 0.02


def test_run_warns_when_a_scene_costs_far_more_than_the_plan(tmp_path):
    data = sweeps.read_csv(_synthetic(tmp_path))
    req = planning.PlanRequest(height=0.06, period=2.0, depth=0.3, duration=5.0)
    planned = planning.zone_scene(req, 0.02)
    assert planning.expense_warning(planned, 0.06, 2.0, data) is None
    long = planned.model_copy(update={   # the same flume ten wavelengths long, all in SPH
        "tank": planned.tank.model_copy(update={"x1": 10 * planned.tank.x1}),
        "water_blocks": [planned.water_blocks[0].model_copy(update={"x1": 10 * planned.tank.x1})]})
    msg = planning.expense_warning(long, 0.06, 2.0, data)
    assert msg and "x the plan for the same accuracy" in msg


def test_shipped_sweep_data_plans_the_demo():
    rows = planning.sweep_data()
    assert rows and set(ACCURACY_COLUMNS) <= set(rows[0])
    meta = (ROOT / "wavesph" / "cases" / planning.SWEEP_CSV).with_suffix(".meta.json")
    assert json.loads(meta.read_text())["made_by"].startswith("wavesph bench accuracy")
    from sph_core.scene import load_scene

    scene = load_scene(ROOT / "examples/scenes/demo_beach_flume.toml")
    plan = planning.make_plan(planning.request_from_scene(scene, 0.04, 1.4), rows)
    assert plan.expected_error <= planning.DEFAULT_TARGET * 1.001 or plan.H_over_dp >= 0.04 / 0.06
    assert plan.expected_wall_s > 0 and plan.particles > 1000


def test_shipped_case_tables_are_the_test_data_copies():
    for name in ("wave_cases_seed002.csv", "dambreak_koshizuka_oka_1996.csv"):
        assert (ROOT / "wavesph/cases/data" / name).read_text() == (ROOT / "tests/data" / name).read_text()


# ---------------------------------------------------------------------------- slow
PLAN_SCENES = [  # (H, T, d) of three regular waves; the stream-function theory drives each flume
    (0.06, 2.0, 0.3),     # seed 002's case V
    (0.05, 1.5, 0.3),
    (0.04, 1.4, 0.24),    # the demo's wave
]


@pytest.mark.slow
@pytest.mark.parametrize("height,period,depth", PLAN_SCENES)
def test_plan_predictions_slow(height, period, depth):
    """The plan's predicted RMSE/H and wall time against a run of the planned flume (one
    wavelength, the planned dp and method), each within a factor 1.5. The machine may be loaded:
    the throughput is calibrated by a short run in this process first (measure_throughput), so
    prediction and measurement see the same conditions; the error model is the shipped sweep."""
    from wave_client.theories import build_theory

    from wavesph.analysis import group_velocity
    from wavesph.cases.wave_flume import flume_case

    method = "wcsph_kdk_h2_wallav0"   # today's WCSPH defaults (the plan's own choice of scheme)
    tp = planning.measure_throughput(method)
    model = build_theory("stream", height=height, period=period, depth=depth, ramp_time=period,
                         n_fourier=16)
    wl = float(model.length)
    periods = 2.0
    duration = period + 0.5 * wl / group_velocity(wl, period, depth) + periods * period
    req = planning.PlanRequest(height=height, period=period, depth=depth, duration=duration,
                               target_error=0.02)   # inside the sweep's H/dp range, not
    # clamped to its coarsest end: a plan of a few seconds' run is mostly fixed per-step costs
    plan = planning.make_plan(req, throughput=tp, methods=[method])
    res = flume_case(model, height=height, period=period, depth=depth, wavelength=wl, dp=plan.dp,
                     periods=periods, ramp=period, **sweeps.METHODS[plan.method])
    info = {"plan": plan.to_json(), "measured_error": res["rmse_over_H"],
            "measured_wall_s": res["wall_s"], "particles": res["particles"], "steps": res["steps"]}
    print(json.dumps(info))
    assert 1 / 1.5 <= plan.expected_error / res["rmse_over_H"] <= 1.5, info
    assert 1 / 1.5 <= plan.expected_wall_s / res["wall_s"] <= 1.5, info


@pytest.mark.slow
def test_quick_accuracy_preset_end_to_end(tmp_path):
    """`wavesph bench accuracy --quick` (<= 10 min on 2 quiet cores): every point recorded,
    the CSV and chart written."""
    res = subprocess.run([sys.executable, "-m", "wavesph", "bench", "accuracy", "--quick",
                          "--out", str(tmp_path)], cwd=ROOT, capture_output=True, text=True,
                         timeout=3600)
    assert res.returncode == 0, res.stderr[-2000:]
    rows = sweeps.read_csv(tmp_path / "accuracy.csv")
    assert len(rows) == len(sweeps.accuracy_points(quick=True))
    assert sum(r["status"] == "ok" for r in rows) >= 0.8 * len(rows)
    assert (tmp_path / "accuracy.png").stat().st_size > 10_000


@pytest.mark.slow
def test_quick_stability_suite_has_no_nan(tmp_path):
    res = subprocess.run([sys.executable, "-m", "wavesph", "bench", "stability", "--quick",
                          "--out", str(tmp_path)], cwd=ROOT, capture_output=True, text=True,
                         timeout=3600)
    assert res.returncode == 0, res.stderr[-2000:]
    with open(tmp_path / "stability.csv") as fh:
        rows = list(csv.DictReader(ln for ln in fh if not ln.startswith("#")))
    assert len(rows) == len(stability.stability_points(quick=True))
    assert {r["status"] for r in rows} <= set(stability.STATUSES)
    assert all(r["reason"] for r in rows if r["status"] in ("unstable", "noisy", "failed"))
    assert "nan" not in (tmp_path / "stability.csv").read_text().lower()
    # still water must stay stable with the default method
    still = next(r for r in rows if r["scenario"] == "still_water" and r["method"] == "wcsph_kdk")
    assert still["status"] == "stable", still


def test_wavesph_run_wave_option_warns_on_stderr(capsys):
    """`wavesph run SCENE --wave H T`: the plan's warning (shipped sweep data) for a flume ten
    wavelengths long all in SPH; nothing for the planned zone itself."""
    from wavesph.cli.run import _warn_if_expensive

    req = planning.PlanRequest(height=0.06, period=2.0, depth=0.3, duration=5.0)
    plan = planning.make_plan(req)
    planned = planning.zone_scene(req, plan.dp, plan.method)
    _warn_if_expensive(planned, 0.06, 2.0)
    assert "warning" not in capsys.readouterr().err
    x1 = 10 * planned.tank.x1
    long = planned.model_copy(update={
        "tank": planned.tank.model_copy(update={"x1": x1}),
        "water_blocks": [planned.water_blocks[0].model_copy(update={"x1": x1})]})
    _warn_if_expensive(long, 0.06, 2.0)
    assert "warning: this scene is predicted to cost" in capsys.readouterr().err


def test_a_failed_coupled_point_keeps_its_run_directory(monkeypatch):
    """The sweep runs a coupled point in a temporary directory: a failure keeps it (run dir,
    meta.json, gauges, saved states) and says where."""
    import wavesph.cases.coupled_flume as coupled_flume

    made = []

    def fake_run(c, dp, out, two_way=True, **kw):  # the run's files, then the outcome
        (out / "r1").mkdir()
        (out / "r1" / "meta.json").write_text("{}")
        made.append(out)
        print("coupled flume: coupling failed: connection lost", file=sys.stderr)
        return {"state": "failed", "status": "failed: client disconnected", "exit_code": 1,
                "wall_s": 1.0, "particles": 10, "steps": 0}

    monkeypatch.setattr(coupled_flume, "run_coupled", fake_run)
    rec = sweeps._coupled(Point("coupled", "coupled", 0.03))
    assert rec["status"] == "failed" and "client disconnected" in rec["reason"]
    assert "connection lost" in rec["reason"]
    assert rec["reason"].endswith(f"run data kept in {made[0]}")
    assert (made[0] / "r1" / "meta.json").exists()
    import shutil
    shutil.rmtree(made[0])


def test_plan_table_says_what_to_do_and_what_it_rests_on(tmp_path, capsys):
    import wavesph.cli

    data = _synthetic(tmp_path)
    assert wavesph.cli.main(["plan", str(ROOT / "examples/scenes/demo_beach_flume.toml"),
                             "--H", "0.04", "--T", "1.4", "--data", str(data)]) == 0
    out = capsys.readouterr().out
    assert not any(line.startswith("{") for line in out.splitlines())   # JSON only with --json
    assert "Rests on: error = 0.3 (H/dp)^-1.00 fitted to 3 flume points" in out
    assert "H/dp 2-8" in out and "c0 = 15.3 m/s" in out     # the scene's own c0
    # 0.24 m / 36 in the digits the scene accepts (0.006667 fills to 0.240012 m: refused)
    assert "To apply it, in the scene file:" in out and "    dp = 0.0066667\n" in out
    assert "flat + 3.4 structures" in out


def test_plan_refuses_a_3d_scene_in_one_line(tmp_path):
    scene = tmp_path / "basin.toml"
    scene.write_text((ROOT / "examples/scenes/tall_structure_3d.toml").read_text()
                     .replace("t_end = 1.5", "t_end = 1.5\nstill_water_level = 0.3"))
    res = subprocess.run([sys.executable, "-m", "wavesph", "plan", str(scene), "--H", "0.05",
                          "--T", "1.0"], cwd=ROOT, capture_output=True, text=True, timeout=300,
                         env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"})
    assert res.returncode == 2
    assert res.stderr.count("\n") == 1 and "3D scene" in res.stderr


def test_pareto_front_keeps_the_runs_worth_their_cost():
    # (wall s, error): the second refinement cost more and erred more (dominated), a tie in cost
    # keeps the more accurate run, the last one buys accuracy with time
    pts = [(10.0, 0.05), (30.0, 0.03), (90.0, 0.04), (30.0, 0.035), (200.0, 0.01)]
    assert sweeps.pareto_front(pts) == [(10.0, 0.05), (30.0, 0.03), (200.0, 0.01)]
    assert sweeps.pareto_front([]) == []


@pytest.mark.parametrize("case, flume_wavelengths", [("flume_IV", 1.0), ("flume_I", 0.5)])
def test_isph_waves_flume_points_get_zones_sized_to_the_flume_and_a_longer_ramp(
        monkeypatch, case, flume_wavelengths):
    """The method that carries waves under ISPH sizes its relaxation zones to each flume (a fifth
    of it at each end: the standing wave's flume is half a wavelength) and ramps over twice the
    preset's periods; the scene those settings make is valid. Other methods are passed as they
    are."""
    import wavesph.cases.wave_flume as wave_flume

    seen = []

    def fake_flume_case(model, **kw):
        seen.append((float(model.length), kw))
        return {"rmse_over_H": 0.01, "wall_s": 1.0, "particles": 1, "steps": 1,
                "reflection": None, "mean_level_m": 0.0}

    monkeypatch.setattr(wave_flume, "flume_case", fake_flume_case)
    opts = {"periods": 1.0, "ramp_periods": 1.0}
    sweeps._flume(Point(case, "isph_waves", 0.05, opts))
    sweeps._flume(Point(case, "wcsph_kdk_h2_wallav0", 0.05, opts))
    (wl, isph), (_, wcsph) = seen
    period = isph["period"]
    assert isph["ramp"] == pytest.approx(2.0 * period) and wcsph["ramp"] == pytest.approx(period)
    zone = isph["scheme"]["isph_relaxation_zone"]
    assert zone == pytest.approx(0.2 * flume_wavelengths * wl, abs=1e-4)
    assert isph["scheme"]["kind"] == "isph" and isph["h_over_dp"] == 1.2
    assert "scheme" not in wcsph
    assert sweeps.METHODS["isph_waves"]["scheme"].get("isph_relaxation_zone") is None  # untouched
    scene = wave_flume.wave_flume_scene(depth=isph["depth"], wavelength=wl, height=isph["height"],
                                        dp=0.05, t_end=0.1, probe_every=0.02,
                                        length=flume_wavelengths * wl,
                                        **{k: v for k, v in isph.items()
                                           if k in ("h_over_dp", "alpha_wall_factor", "scheme")})
    assert scene.scheme.isph_relaxation_zone == zone
