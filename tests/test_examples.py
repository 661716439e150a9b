"""Every shipped example runs to its end, in every mode its documentation gives, at a coarse dp.

The examples are the first thing a new user runs: each must survive its own run (issue 16 item 1).
The particle spacing is coarsened (named per case; the still-water depth stays a whole number of
rows) so the suite stays short; the physics checks live in the other tests. The long ones
(the case-V flume, 14 s; the coupled flume, 18 s of SPH; the Boussinesq examples) are slow.
"""

from __future__ import annotations

import csv
import json
import tomllib
from pathlib import Path

import numpy as np
import pytest

import wavesph.cli
from sph_core.scene import load_scene, make_scene, split_scene_file

ROOT = Path(__file__).resolve().parents[1]
SCENES = ROOT / "examples" / "scenes"

# example -> coarse dp [m] (the documented mode of the closed tanks is `wavesph run`)
RUN_DP = {"still_water_tank.toml": 0.05, "dambreak_martin_moyce.toml": 0.05,
          "floating_box_and_flap.toml": 0.0375,   # 8 rows of its 0.3 m (0.04 is refused: 7.5)
          "tall_structure_3d.toml": 0.05}


def test_every_example_is_covered():
    """A new example file must be added here (or this test says which one is not run)."""
    shipped = {p.name for p in SCENES.glob("*.toml")}
    assert shipped == set(RUN_DP) | {"demo_beach_flume.toml", "flume_case_V.toml",
                                     "seawall_overtopping.toml"}


def _meta(out: Path) -> dict:
    return json.loads((out / "meta.json").read_text())


@pytest.mark.parametrize("name", sorted(RUN_DP))
def test_closed_tank_examples_run_to_their_end(tmp_path, name):
    out = tmp_path / "run"
    code = wavesph.cli.main(["run", str(SCENES / name), "--dp", str(RUN_DP[name]), "-o", str(out),
                             "--no-progress"])
    meta = _meta(out)
    assert code == 0, meta.get("cause")
    assert meta["status"] == "completed" and meta["t"] == pytest.approx(load_scene(SCENES / name).t_end)
    assert meta["excluded"] <= 0.001 * meta["n_fluid"]


def _theory_run(scene_file: Path, dp: float, theory: str, t_end: float | None = None, **opts):
    """An open-boundary example driven by the built-in theory its comment documents, to its end
    or to ``t_end`` (the standalone path: the same Simulation the server's standalone runs
    solve)."""
    from wavesph.cases.wave_flume import run_wave_flume
    from wave_client.theories import build_theory

    data, _ = split_scene_file(tomllib.loads(scene_file.read_text()))
    scene = make_scene({**data, "dp": dp, **({"t_end": t_end} if t_end else {})})
    model = build_theory(theory, depth=scene.still_water_level, **opts)
    run = run_wave_flume(scene, model, window=opts["period"] / 50, keep_flume=True)
    return scene, run


def test_demo_beach_flume_with_its_stokes_source_runs_to_its_end():
    """examples/scenes/demo_beach_flume.toml with the source its comment documents (Stokes 2,
    H = 0.04 m, T = 1.4 s, 2 ramp periods) at dp = 0.04 m (6 rows of still water)."""
    scene, run = _theory_run(SCENES / "demo_beach_flume.toml", 0.04, "stokes", height=0.04,
                             period=1.4, order=2, ramp_time=2 * 1.4)
    sim = run.flume
    assert sim.t == pytest.approx(scene.t_end) and sim.status == "completed"
    assert len(sim.excluded) <= 0.001 * sim.n_fluid0


def test_seawall_overtopping_is_the_case_and_runs_with_its_irregular_source():
    """examples/scenes/seawall_overtopping.toml is wavesph.cases.seawall's scene at Hs/dp 4, and
    runs with its [source] (JONSWAP) at dp 0.0375 (8 rows) for 6 s: the first waves reach the
    slope, the toe gauge stays wet and nothing leaves the flume."""
    from wavesph.cases.seawall import HS, seawall_scene

    path = SCENES / "seawall_overtopping.toml"
    data, extra = split_scene_file(tomllib.loads(path.read_text()))
    scene = make_scene(data)
    assert scene == make_scene(seawall_scene(HS / 4, t_end=scene.t_end))
    src = {k: v for k, v in extra["source"].items() if k not in ("theory", "H", "T", "ramp_periods")}
    scene, run = _theory_run(path, 0.0375, "irregular", height=HS, period=1.4,
                             ramp_time=2 * 1.4, **src, t_end=6.0)
    sim = run.flume
    assert sim.status == "completed" and len(sim.excluded) == 0
    toe = [r["toe_eta"] for r in sim.history if r["t"] > 3.0]
    assert all(v is not None for v in toe) and max(toe) - min(toe) > 0.02


@pytest.mark.slow
def test_flume_case_V_with_its_stream_function_source_runs_to_its_end():
    """examples/scenes/flume_case_V.toml (seed 002 case V: stream function H = 0.06 m, T = 2 s)
    at dp = 0.02 m (15 rows; the flume 166 dp long)."""
    scene, run = _theory_run(SCENES / "flume_case_V.toml", 0.02, "stream", height=0.06,
                             period=2.0, n_fourier=16, ramp_time=2.0)
    sim = run.flume
    assert sim.t == pytest.approx(scene.t_end) and sim.status == "completed"
    assert len(sim.excluded) <= 0.001 * sim.n_fluid0


@pytest.mark.slow
@pytest.mark.parametrize("config", ["beji_battjes.toml", "dingemans.toml"])
def test_wave_examples_run_to_their_end(tmp_path, config):
    """`wavesph waves examples/waves/<config> -o CSV` as their comments give it."""
    out = tmp_path / "gauges.csv"
    assert wavesph.cli.main(["waves", str(ROOT / "examples" / "waves" / config), "-o", str(out),
                             "--no-progress"]) == 0
    rows = list(csv.reader(line for line in out.open() if not line.startswith("#")))
    end = tomllib.loads((ROOT / "examples" / "waves" / config).read_text())["grid"]["t_end"]
    assert float(rows[-1][0]) == pytest.approx(end, abs=0.1)


@pytest.mark.slow
@pytest.mark.parametrize("two_way", [True, False], ids=["two_way", "absorption_only"])
def test_coupled_examples_run_to_their_end(tmp_path, two_way):
    """examples/coupled: the SPH zone coupled over a socket to the Boussinesq model, both modes
    its README gives, at dp = 0.04 m (the files are generated from wavesph.cases.coupled_flume at 0.02)."""
    from wavesph.cases.coupled_flume import FlumeCase, run_coupled

    res = run_coupled(FlumeCase(), 0.04, tmp_path, two_way=two_way)
    assert res["exit_code"] == 0 and res["state"] == "finished", res["status"]


@pytest.mark.parametrize("name", sorted(p.name for p in SCENES.glob("*.toml")))
def test_every_example_previews_without_solving(tmp_path, name):
    """`wavesph run SCENE --preview`: the initial particles and the outlines as VTK, no step."""
    import re

    def piece(path: Path, what: str) -> int:  # from the XML header (the data are appended binary)
        head = path.read_bytes().split(b"<AppendedData")[0].decode()
        return int(re.search(rf'{what}="(\d+)"', head).group(1))

    out = tmp_path / "preview"
    assert wavesph.cli.main(["run", str(SCENES / name), "--preview", "-o", str(out)]) == 0
    meta = _meta(out)
    assert meta["status"] == "preview" and meta["steps"] == 0
    scene = load_scene(SCENES / name)
    points = piece(out / "snapshots" / "particles_00000.vtu", "NumberOfPoints")
    last = np.load(out / "snapshots" / "last.npz")
    assert last["kind"].size == points and last["kind"].max() <= 3
    # idle open-end buffer particles (above the surface, in no pass) are not written
    assert points == meta["n_particles"] if not scene.open_boundaries else points < meta["n_particles"]
    # one line cell per segment (3D: a box's 12 edges, the tank's included; beds on both walls)
    cells = (12 * (1 + len(scene.structures))
             + sum(3 * len(b.points) - 2 for b in scene.beds) if scene.dim == 3
             else 3 + sum(len(b.points) - 1 for b in scene.beds) + 4 * len(scene.structures))
    assert piece(out / "geometry.vtu", "NumberOfCells") == cells + len(scene.open_boundaries)
