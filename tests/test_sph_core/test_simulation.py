"""Run life: outputs on disk, checkpoint/restore, stability guard, CLI."""

import csv
import json
from pathlib import Path

import numpy as np
import pytest

import wavesph.cli
from wavesph.cases.dambreak import dambreak_scene
from sph_core.particles import FLUID, VZ, X, Z
from sph_core.scene import make_scene
from sph_core.simulation import Simulation, UnstableError

ROOT = Path(__file__).resolve().parents[2]


def small_dambreak(**kw):
    return dambreak_scene(a=0.05, dp=0.005, t_end=0.05, probe_every=0.01, **kw)


def test_run_directory_outputs(tmp_path):
    scene = dambreak_scene(a=0.05, dp=0.005, t_end=0.04, probe_every=0.01, snapshot_every=0.02)
    sim = Simulation(scene, run_dir=tmp_path)
    sim.advance_to(scene.t_end)
    sim.close()
    meta = json.loads((tmp_path / "meta.json").read_text())
    assert meta["status"] == "completed" and meta["steps"] == sim.steps > 0
    assert meta["config"]["dp"] == 0.005 and "numba" in meta["versions"]
    assert meta["passes_per_step"] == 1 and meta["wall_time_s"] > 0
    rows = list(csv.reader((tmp_path / "probes.csv").open()))
    assert rows[0] == ["t", "step", "front_x"]
    times = [float(r[0]) for r in rows[1:]]
    assert times == pytest.approx([0.0, 0.01, 0.02, 0.03, 0.04])
    snaps = sorted((tmp_path / "snapshots").glob("*.vtu"))
    assert len(snaps) == 3
    head = snaps[-1].read_bytes()[:200]
    assert b"VTKFile" in head and b"UnstructuredGrid" in head
    assert "particles_00002.vtu" in (tmp_path / "run.pvd").read_text()


def test_run_starting_later_keeps_its_clock(tmp_path):
    """t_start shifts the clock only: same particles and steps as from 0, probes from t_start."""
    scene = small_dambreak()
    later = scene.model_copy(update={"t_start": 2.0, "t_end": 2.0 + scene.t_end})
    a, b = Simulation(scene), Simulation(later, run_dir=tmp_path)
    a.advance_to(scene.t_end)
    b.advance_to(later.t_end)
    b.close()
    assert b.t == pytest.approx(later.t_end) and b.steps == a.steps
    np.testing.assert_allclose(b.particles.f[:, :b.particles.n], a.particles.f[:, :a.particles.n],
                               atol=1e-9)
    times = [float(r[0]) for r in list(csv.reader((tmp_path / "probes.csv").open()))[1:]]
    assert times == pytest.approx([2.0, 2.01, 2.02, 2.03, 2.04, 2.05])
    with pytest.raises(ValueError, match="t_end: must be after t_start"):
        make_scene({**scene.model_dump(), "t_start": 1.0, "t_end": 0.5})


@pytest.mark.parametrize("integrator", ["kdk", "symplectic_pc"])
def test_checkpoint_restore_is_exact(integrator):
    scene = small_dambreak(integrator=integrator)
    sim = Simulation(scene)
    sim.advance_to(0.01)
    cp = sim.checkpoint()
    sim.advance_to(0.03)
    first = sim.fluid_state()
    sim.restore(cp)
    assert sim.t == 0.01
    sim.advance_to(0.03)
    second = sim.fluid_state()
    for key in first:
        np.testing.assert_array_equal(first[key], second[key])


def test_kdk_and_predictor_corrector_agree():
    runs = []
    for integrator in ("kdk", "symplectic_pc"):
        sim = Simulation(small_dambreak(integrator=integrator))
        sim.advance_to(0.05)
        runs.append(sim.probe_values()["front_x"])
    assert runs[0] == pytest.approx(runs[1], abs=0.5 * 0.005)


def test_unstable_run_stops_with_cause_and_keeps_outputs(tmp_path):
    # c0 = 0.5 m/s is far below sqrt(2 g H) = 1.4 m/s: the column compresses beyond the band
    scene = small_dambreak(c0=0.5, density_band=(0.9, 1.1))
    sim = Simulation(scene, run_dir=tmp_path)
    with pytest.raises(UnstableError) as info:
        sim.advance_to(scene.t_end)
    err = info.value
    assert err.step > 0 and 0 < err.t < scene.t_end and "density" in err.cause
    meta = json.loads((tmp_path / "meta.json").read_text())
    assert meta["status"] == "unstable" and meta["unstable_step"] == err.step
    assert "density" in meta["cause"]
    text = (tmp_path / "probes.csv").read_text().lower()
    assert "nan" not in text and len(text.splitlines()) >= 2
    with pytest.raises(RuntimeError):
        sim.advance_to(scene.t_end)


def test_particles_out_of_band_are_excluded_within_the_limit(tmp_path):
    """A band so tight that the column's surface particles leave it: with a generous
    exclude_limit they are removed and logged and the run goes on; with none it stops."""
    band = {"c0": 0.5, "density_band": (0.9, 1.1)}
    scene = small_dambreak(**band, exclude_limit=1.0)
    sim = Simulation(scene, run_dir=tmp_path)
    n0 = sim.n_fluid
    sim.advance_to(scene.t_end)
    sim.close()
    assert sim.excluded and sim.n_fluid + len(sim.excluded) == n0
    assert all(not 900.0 <= e["rho"] <= 1100.0 for e in sim.excluded)
    assert len({e["id"] for e in sim.excluded}) == len(sim.excluded)
    meta = json.loads((tmp_path / "meta.json").read_text())
    assert meta["status"] == "completed" and meta["excluded"] == len(sim.excluded)
    with pytest.raises(UnstableError, match="density"):
        Simulation(small_dambreak(**band, exclude_limit=0.0)).advance_to(scene.t_end)


@pytest.mark.parametrize("integrator", ["kdk", "symplectic_pc"])
def test_particle_thrown_over_the_top_is_excluded(tmp_path, integrator):
    """A particle leaving the tank over its top is excluded and logged like one out of the
    density band (same exclude_limit); with a zero limit the run stops, naming it."""
    def thrown(limit):
        scene = make_scene({
            "dp": 0.02, "t_end": 0.2, "still_water_level": 0.1,
            "tank": {"x0": 0, "x1": 0.4, "z0": 0, "z1": 0.14},
            "water_blocks": [{"x0": 0, "x1": 0.4, "z0": 0, "z1": 0.1}],
            "constants": {"exclude_limit": limit, "integrator": integrator}})
        sim = Simulation(scene, run_dir=tmp_path / f"{limit}")
        ps = sim.particles
        # the top fluid row's slot nearest mid-tank, lifted to just below the tank top and
        # thrown up at 3 m/s (0.46 m ballistic rise). At h/dp 2 a particle thrown from inside the
        # surface row is held back by its ~30 neighbours (rises 1.6 cm at 3 m/s, 3 cm at 5 m/s);
        # one thrown beside a side wall stays in the tank (next test)
        z, x = ps.field(Z), ps.field(X)
        cand = np.nonzero(ps.mask(FLUID) & (z >= z[ps.mask(FLUID)].max() - 1e-9))[0]
        top = int(cand[np.argmin(np.abs(x[cand] - 0.2))])
        ps.f[Z, top] = 0.14 - 0.25 * 0.02
        ps.f[VZ, top] = 3.0
        return sim, int(ps.ids[top])

    sim, pid = thrown(0.5)
    n0 = sim.n_fluid
    sim.advance_to(0.2)
    sim.close()
    assert [e["id"] for e in sim.excluded] == [pid] and sim.excluded[0]["reason"] == "left the tank"
    assert sim.excluded[0]["z"] > 0.14 and sim.n_fluid == n0 - 1
    meta = json.loads((tmp_path / "0.5" / "meta.json").read_text())
    assert meta["status"] == "completed" and meta["excluded"] == 1
    sim, _ = thrown(0.0)
    with pytest.raises(UnstableError, match="left the tank"):
        sim.advance_to(0.2)


@pytest.mark.parametrize("integrator", ["kdk", "symplectic_pc"])
@pytest.mark.parametrize("h_over_dp", [2.0, 1.4142])
@pytest.mark.parametrize("x_throw", [0.01, 0.39])
def test_particle_thrown_beside_a_side_wall_stays_in_the_tank(integrator, h_over_dp, x_throw):
    """The surface-row particle next to a side wall, thrown up at 3 m/s, is held back by the
    fluid's tension and must not be pulled through the wall (issue 11 item 5). It was, at h/dp 2:
    in tension (p ~ -16 kPa) its pressure term attracted it to the wall particles as to fluid, and
    it left at x = x0 - dp/2, z 0.12 m after 0.021 s (docs/studies/wall_pressure.md, 2026-11-23)."""
    dp = 0.02
    scene = make_scene({
        "dp": dp, "t_end": 0.1, "still_water_level": 0.1,
        "tank": {"x0": 0, "x1": 0.4, "z0": 0, "z1": 0.3},
        "water_blocks": [{"x0": 0, "x1": 0.4, "z0": 0, "z1": 0.1}],
        "constants": {"exclude_limit": 0.0, "integrator": integrator, "h_over_dp": h_over_dp}})
    sim = Simulation(scene)
    ps = sim.particles
    z, x = ps.field(Z), ps.field(X)
    fluid = ps.mask(FLUID)
    cand = np.nonzero(fluid & (z >= z[fluid].max() - 1e-9))[0]
    k = int(cand[np.argmin(np.abs(x[cand] - x_throw))])
    assert min(x[k], 0.4 - x[k]) == pytest.approx(0.5 * dp)   # the column beside the wall
    ps.f[VZ, k] = 3.0
    pid, z0 = int(ps.ids[k]), float(z[k])
    z_max, gap_min = 0.0, np.inf
    while sim.t < scene.t_end:   # exclude_limit 0: a particle through a wall stops the run
        sim.advance_steps(1)
        f = ps.mask(FLUID)
        xf = ps.field(X)[f]
        gap_min = min(gap_min, xf.min(), 0.4 - xf.max())
        z_max = max(z_max, float(ps.field(Z)[np.nonzero(ps.ids[: ps.n] == pid)[0][0]]))
    assert not sim.excluded
    assert z_max > z0 + 0.5 * dp           # it did leave the surface row (by 1.9-2.5 cm)
    assert gap_min > 0.0                   # no fluid centre behind a wall face


@pytest.mark.parametrize("integrator", ["kdk", "symplectic_pc"])
def test_thin_front_on_a_dry_bed_does_not_sink_through_it(integrator):
    """A dam break (h0 0.1 m, 0.5 m long) running over a dry free-slip bed, dp 0.02, h/dp 2: the
    bottom particles of the thin, stretching front approach the bed at ~h du/dx to keep their
    density and sank between the wall particles (main befe411, kdk: one centre reached the first
    dummy row, z = -dp/2, at 0.443 s and the run, exclude_limit 0, stopped). With the
    no-penetration correction (sph_core.wall_contact) no centre passes the bed's face
    (docs/studies/wall_pressure.md, 2026-11-23 "the dry-bed front")."""
    dp = 0.02
    scene = make_scene({
        "dp": dp, "t_end": 0.6,
        "tank": {"x0": 0, "x1": 3.0, "z0": 0, "z1": 0.3},
        "water_blocks": [{"x0": 0, "x1": 0.5, "z0": 0, "z1": 0.1}],
        "constants": {"wall_slip": "free_slip", "exclude_limit": 0.0, "integrator": integrator}})
    sim = Simulation(scene)
    ps = sim.particles
    z_min, x_front = np.inf, 0.0
    while sim.t < scene.t_end:   # exclude_limit 0: a particle through the bed stops the run
        sim.advance_to(min(sim.t + 0.01, scene.t_end))
        f = ps.mask(FLUID)
        z_min = min(z_min, float(ps.field(Z)[f].min()))
        x_front = max(x_front, float(ps.field(X)[f].max()))
    assert not sim.excluded
    assert z_min > 0.0                     # no fluid centre behind the bed's face
    assert x_front > 1.2                   # the front did run out over the dry bed


def test_dry_gauge_reports_dry(tmp_path):
    scene = make_scene({
        "dp": 0.01, "t_end": 0.01, "still_water_level": 0.1,
        "tank": {"x0": 0, "x1": 0.6, "z0": 0, "z1": 0.3},
        "water_blocks": [{"x0": 0, "x1": 0.2, "z0": 0, "z1": 0.1}],
        "output": {"probe_every": 0.01},
        "probes": [{"kind": "elevation", "name": "dry", "x": 0.5},
                   {"kind": "elevation", "name": "wet", "x": 0.1},
                   {"kind": "point", "name": "air", "x": 0.5, "z": 0.2}],
    })
    sim = Simulation(scene, run_dir=tmp_path)
    v = sim.probe_values()
    assert v["dry_z_surface"] is None and v["dry_eta"] is None and v["air_p"] is None
    assert v["wet_z_surface"] == pytest.approx(0.1, abs=0.25 * scene.dp)
    sim.close()
    row = list(csv.DictReader((tmp_path / "probes.csv").open()))[0]
    assert row["dry_z_surface"] == "" and row["air_u"] == ""   # empty: NaN to pandas, no word
    frame = __import__("wavesph").read_gauges(tmp_path / "probes.csv")
    assert frame["dry_eta"].isna().all() and frame["wet_z_surface"].notna().all()


def test_cli_run(tmp_path, capsys):
    scene = ROOT / "examples" / "scenes" / "still_water_tank.toml"
    out = tmp_path / "run"
    code = wavesph.cli.main(["run", str(scene), "--t-end", "0.005", "--out", str(out)])
    assert code == 0
    meta = json.loads((out / "meta.json").read_text())
    assert meta["status"] == "completed" and meta["t"] == pytest.approx(0.005)


def test_cli_run_bad_scene(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text("dp = -1\nt_end = 1\n")
    assert wavesph.cli.main(["run", str(bad)]) == 2
    assert "dp:" in capsys.readouterr().err


def test_demo_writes_run_and_figure(tmp_path):
    out = tmp_path / "demo"
    # `wavesph demo` is the coupled flume now; the dam break is `wavesph demo --dambreak`
    from wavesph.cases.dambreak_demo import run_dambreak_demo

    code = run_dambreak_demo(out, resolution=10, T_end=1.0)
    assert code == 0
    assert (out / "dambreak.png").stat().st_size > 10_000
    meta = json.loads((out / "meta.json").read_text())
    assert meta["status"] == "completed"
    assert len(list((out / "snapshots").glob("*.vtu"))) >= 2


def test_outputs_follow_the_documented_convention(tmp_path):
    """probes.csv: short times, read back by load_gauges (dry -> NaN); snapshots carry a
    velocity vector, mass, h and kind (README "Outputs")."""
    from sph_core.output import load_gauges

    scene = dambreak_scene(a=0.05, dp=0.005, t_end=0.03, probe_every=0.01, snapshot_every=0.03)
    sim = Simulation(scene, run_dir=tmp_path)
    sim.advance_to(scene.t_end)
    sim.close()
    text = (tmp_path / "probes.csv").read_text()
    assert [r.split(",")[0] for r in text.splitlines()[1:]] == ["0", "0.01", "0.02", "0.03"]
    cols = load_gauges(tmp_path / "probes.csv")
    assert list(cols) == ["t", "step", "front_x"]
    np.testing.assert_allclose(cols["front_x"], [r["front_x"] for r in sim.history], rtol=1e-11)
    (tmp_path / "g.csv").write_text("# a comment\nt,a\n0.5,dry\n1,2.5\n1.5,\n")
    g = load_gauges(tmp_path / "g.csv")
    assert np.isnan(g["a"][0]) and g["a"][1] == 2.5 and np.isnan(g["a"][2])
    vtu = sorted((tmp_path / "snapshots").glob("*.vtu"))[-1].read_bytes()
    for name in (b'Name="velocity" NumberOfComponents="3"', b'Name="mass"', b'Name="h"',
                 b'Name="kind"', b'Name="pressure"'):
        assert name in vtu, name


def test_float32_storage_tracks_float64():
    """precision = "float32" stores the fields in float32 (twin buffers too) and the same kernels
    run on them: a short dam break ends where the float64 run ends, to float32 round-off grown
    over the steps (far below dp), and the surge front agrees."""
    runs = {}
    for prec in ("float64", "float32"):
        sim = Simulation(small_dambreak(precision=prec))
        sim.advance_to(0.05)
        ps = sim.particles
        assert ps.f.dtype == ps.f2.dtype == np.dtype(prec)
        order = np.argsort(ps.ids[: ps.n])
        runs[prec] = (ps.f[X, : ps.n][order].astype(float), ps.f[Z, : ps.n][order].astype(float),
                      sim.steps, sim.history[-1]["front_x"])
    x64, z64, steps64, front64 = runs["float64"]
    x32, z32, steps32, front32 = runs["float32"]
    assert abs(steps32 - steps64) <= 2
    dmax = max(np.abs(x32 - x64).max(), np.abs(z32 - z64).max())
    assert 0.0 < dmax < 1e-3 * 0.005          # not the float64 run, and 0.1 % of dp of it
    assert abs(front32 - front64) < 0.1 * 0.005
