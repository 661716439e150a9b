"""`wavesph demo` end to end on a tiny configuration: server in-process, a real socket, the
wave client, the run directory and the plot."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

import wavesph.cli
from wavesph.cases.demo_flume import GAUGES, demo_scene
from server.schemas import RunRequest


@pytest.mark.parametrize("transport", ["ws", "tcp"])
def test_demo_writes_a_finished_run_with_gauges_and_plot(tmp_path, transport, capsys, monkeypatch):
    monkeypatch.setenv("OMP_WAIT_POLICY", "passive")  # the demo sets it; keep it out of other tests
    out = tmp_path / "demo"
    code = wavesph.cli.main(["demo", "--t-end", "0.4", "--dp", "0.04", "--transport", transport,
                             "--out", str(out)] + (["--no-plot"] if transport == "tcp" else []))
    assert code == 0
    (run_dir,) = [p for p in out.iterdir() if p.is_dir()]
    meta = json.loads((run_dir / "meta.json").read_text())
    assert meta["state"] == "finished" and meta["t"] == pytest.approx(0.4)
    with open(run_dir / "gauges.csv", newline="") as f:
        rows = list(csv.reader(f))
    cols = rows[0]
    assert [c for c in cols if c.endswith("_eta")] == ["left_boundary_eta"] + [f"{g}_eta" for g in GAUGES]
    values = np.array([[float(v) for v in r] for r in rows[1:]])  # 'dry' would not parse
    assert len(rows) - 1 == meta["windows"] >= 14 and np.all(np.isfinite(values))
    # still water ahead of the ramped wave: the flat-bed gauges read the scene's still-water
    # level (a depth of no whole number of dp rows would read up to dp/2 = 0.02 m low)
    flat = [cols.index("left_boundary_eta"), cols.index("flat_eta")]
    assert np.abs(values[:, flat]).max() < 0.25 * 0.04
    summary = json.loads((out / "summary.json").read_text())
    assert summary["particles"] == meta["particles"] > 500 and summary["windows"] == meta["windows"]
    assert summary["rmse_over_H_flat"] is None  # too short to reach full waves: said, not faked
    assert (out / "elevation.png").exists() == (transport == "ws")
    if transport == "ws":
        assert (out / "elevation.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    err = capsys.readouterr().err
    assert str(out.resolve()) in err and "None particles" not in err
    # the VTK snapshots it lists: the first and the last (t_end 0.4 s < 1 s apart)
    assert len(list((run_dir / "sph" / "snapshots").glob("*.vtu"))) == 2
    assert (run_dir / "sph" / "run.pvd").exists() and "sph/run.pvd" in err


def test_demo_with_a_body_in_the_sph_zone_writes_its_series(tmp_path, monkeypatch):
    """`wavesph demo --body box`: the coupled flume with a floating box (issue 14): the run
    finishes and its bodies.csv holds the box's motion and loads at every probe time."""
    monkeypatch.setenv("OMP_WAIT_POLICY", "passive")
    out = tmp_path / "demo"
    code = wavesph.cli.main(["demo", "--t-end", "0.3", "--dp", "0.04", "--transport", "tcp",
                             "--no-plot", "--body", "box", "--out", str(out)])
    assert code == 0
    (run_dir,) = [p for p in out.iterdir() if p.is_dir()]
    (path,) = list(run_dir.glob("sph*/bodies.csv"))
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) >= 4
    z = np.array([float(r["box_z"]) for r in rows])
    fz = np.array([float(r["box_fz"]) for r in rows])
    assert np.all(np.isfinite(z)) and np.all(fz > 0)          # buoyant, afloat
    assert abs(z[-1] - z[0]) < 0.05                           # still at its draft, roughly


def test_demo_scene_bodies_are_valid():
    for kind in ("box", "flap"):
        scene = RunRequest.model_validate({"scene": demo_scene(0.02, 8.0, kind)}).scene
        (body,) = scene.bodies
        assert body.name == kind and GAUGES["flat"] < 1.5 < GAUGES["toe"]


def test_demo_refuses_a_non_empty_out_dir(tmp_path, monkeypatch):
    monkeypatch.setenv("OMP_WAIT_POLICY", "passive")
    (tmp_path / "old.txt").write_text("a run's data")
    assert wavesph.cli.main(["demo", "--out", str(tmp_path), "--t-end", "0.1"]) == 2
    assert [p.name for p in tmp_path.iterdir()] == ["old.txt"]


def test_demo_scene_is_a_valid_flume_with_the_beach_inside():
    scene = RunRequest.model_validate({"scene": demo_scene(0.02, 8.0)}).scene
    (bed,) = scene.beds
    (x_toe, z_toe), (x_end, z_end) = bed.points
    assert scene.tank.x1 == pytest.approx(x_end) and z_end > scene.still_water_level  # dry top
    assert (z_end - z_toe) / (x_end - x_toe) == pytest.approx(0.1)
    assert [o.side for o in scene.open_boundaries] == ["left"]
    assert GAUGES["flat"] < x_toe < GAUGES["beach"] < x_end
    for dp in (0.02, 0.03, 0.05):  # whole particle rows below still water, at any dp
        rows = demo_scene(dp, 1.0)["still_water_level"] / dp
        assert rows == pytest.approx(round(rows), abs=1e-9) and rows >= 4


def test_example_scene_file_is_the_demo_scene():
    from pathlib import Path

    from sph_core.scene import load_scene, make_scene

    path = Path(__file__).resolve().parents[2] / "examples" / "scenes" / "demo_beach_flume.toml"
    a = load_scene(path).model_dump()
    b = make_scene(demo_scene(0.02, 8.0)).model_dump()
    assert _close(a, b)


def _close(a, b) -> bool:
    """Equal structures, floats to 1e-12 relative."""
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(_close(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)):
        return len(a) == len(b) and all(_close(x, y) for x, y in zip(a, b))
    if isinstance(a, float):
        return a == pytest.approx(b, rel=1e-12, abs=1e-15)
    return a == b
