"""``device = "cuda"`` end to end: a Simulation, the CLI and the server step on the GPU and agree
with the CPU; a device that cannot run the scene is refused in one line.

Runs on a GPU when one is present, else under numba-cuda's simulator (cuda_support,
as test_cuda_step.py); the GPU runs are skipped without numba-cuda. The simulator
takes ~2 s per step of the tiny dam break below (322 particles), so the runs are a few steps.
"""

from __future__ import annotations

import json
import os
import sys

import numpy as np
import pytest
from cuda_support import device_session
from cuda_support import needs_numba_cuda as needs_cuda

pytestmark = pytest.mark.cuda

A, DP, WARM_STEPS = 0.05, 0.01, 15


def _scene(**kw):
    from wavesph.cases.dambreak import dambreak_scene
    # exclude_limit 0.1: the tests exclude one of the 50 fluid particles as a guard would
    kw.setdefault("exclude_limit", 0.1)
    return dambreak_scene(a=A, dp=DP, t_end=1.0, tank_length=2.0 * A, **kw)


@pytest.fixture(scope="module")
def gpu_here():
    with device_session():
        yield


def _scaled_diff(a: np.ndarray, b: np.ndarray) -> float:
    scale = max(float(np.abs(a).max()), 1e-30)
    return float(np.abs(a - b).max()) / scale


@needs_cuda
def test_simulation_on_cuda_matches_the_cpu_run(gpu_here, tmp_path):
    """The same run on both devices, through Simulation: restored from a checkpoint of moving
    fluid (so from_host is exercised), one fluid particle excluded as a guard does (the device
    keeps it in the inactive bin, the CPU drops it), then advance_to with probes (front, point,
    elevation) and snapshots on their cadence. Tolerance 1e-10 of each quantity's scale, as
    test_cuda_step.py's run: both devices sort identically, so they differ only by the last
    bits of reassociated sums and fused multiply-adds, grown by the dynamics (measured there:
    <= 1e-13 after 10 steps); a missed copy between host and device, a wrong dt or a lost
    exclusion is off by orders more."""
    from sph_core.cuda import simulated
    from sph_core.particles import FLUID, RHO, X, Z
    from sph_core.simulation import Simulation

    base = Simulation(_scene())
    base.advance_steps(WARM_STEPS)
    ck = base.checkpoint()
    steps = 6 if simulated() else 60
    probes = [{"kind": "point", "name": "pt", "x": 0.02, "z": 0.02},
              {"kind": "elevation", "name": "el", "x": 0.03}]
    scene = _scene(probe_every=2.0 * ck.dt, snapshot_every=3.0 * ck.dt, probes=probes)
    t1 = ck.t + steps * ck.dt
    runs = {}
    for device in ("cpu", "cuda"):
        sim = Simulation(scene, run_dir=tmp_path / device, device=device)
        sim.restore(ck)
        ps = sim.particles
        fluid = np.nonzero(ps.mask(FLUID))[0]
        ids = ps.ids[: ps.n][fluid]
        assert sim._exclude(np.array([0]), ids, ps.field(X)[fluid], ps.field(Z)[fluid],
                            ps.field(RHO)[fluid], "test")   # as a guard's exclusion does
        sim.advance_to(t1)
        sim.close()
        runs[device] = sim
    cpu, gpu = runs["cpu"], runs["cuda"]
    assert gpu.device == "cuda" and gpu.t == cpu.t == pytest.approx(t1)
    assert gpu.steps == cpu.steps and gpu.n_fluid == cpu.n_fluid == base.n_fluid - 1
    a, b = cpu.fluid_state(), gpu.fluid_state()
    np.testing.assert_array_equal(a["id"], b["id"])
    diffs = {key: _scaled_diff(a[key], b[key]) for key in ("x", "z", "vx", "vz", "rho", "p")}
    # probes: the same times, every column within the same bound of its scale
    assert [h["t"] for h in gpu.history] == [h["t"] for h in cpu.history]
    assert len(cpu.history) >= 3
    for col in cpu.probe_columns():
        ca = np.array([np.nan if h[col] is None else h[col] for h in cpu.history])
        cb = np.array([np.nan if h[col] is None else h[col] for h in gpu.history])
        np.testing.assert_array_equal(np.isnan(ca), np.isnan(cb), err_msg=col)
        if np.isfinite(ca).any():
            diffs[col] = _scaled_diff(ca[np.isfinite(ca)], cb[np.isfinite(cb)])
    print(f"{gpu.steps - ck.steps} steps, max |cuda - cpu| / scale:", diffs)
    assert all(d <= 1e-10 for d in diffs.values()), diffs
    assert np.abs(a["vz"]).max() > 0.01   # the column is falling: the comparison has content
    # snapshots on the same cadence, the run record says where it ran
    snaps = {d: sorted(p.name for p in (tmp_path / d / "snapshots").iterdir()) for d in runs}
    assert snaps["cuda"] == snaps["cpu"] and len(snaps["cpu"]) >= 2
    meta = json.loads((tmp_path / "cuda" / "meta.json").read_text())
    assert meta["device"] == "cuda" and meta["gpu"] and meta["config"]["run"]["device"] == "cuda"
    assert meta["steps"] == gpu.steps and meta["excluded"] == 1
    assert json.loads((tmp_path / "cpu" / "meta.json").read_text())["device"] == "cpu"


@needs_cuda
@pytest.mark.parametrize("limit", [0.1, 0.0])
def test_a_guard_on_cuda_excludes_or_stops_as_on_the_cpu(gpu_here, tmp_path, limit):
    """One fluid particle put below the density band (0.65 rho0): with room under
    exclude_limit both devices exclude it after the first step and go on; without, both stop
    with the same UnstableError and meta.json says unstable. Same tolerance as above."""
    from sph_core.particles import FLUID, RHO
    from sph_core.simulation import Simulation, UnstableError

    base = Simulation(_scene())
    base.advance_steps(WARM_STEPS)
    ck = base.checkpoint()
    victim = np.nonzero(ck.kind == FLUID)[0][10]
    ck.f[RHO, victim] = 0.65 * base.scene.constants.rho0
    runs = {}
    for device in ("cpu", "cuda"):
        sim = Simulation(_scene(exclude_limit=limit), run_dir=tmp_path / device, device=device)
        sim.restore(ck)
        try:
            sim.advance_to(ck.t + 3.0 * ck.dt)
            runs[device] = (sim, None)
        except UnstableError as exc:
            runs[device] = (sim, exc)
    (cpu, cpu_exc), (gpu, gpu_exc) = runs["cpu"], runs["cuda"]
    assert gpu.steps == cpu.steps and gpu.t == cpu.t
    assert [(e["id"], e["step"]) for e in gpu.excluded] == [(e["id"], e["step"]) for e in cpu.excluded]
    meta = json.loads((tmp_path / "cuda" / "meta.json").read_text())
    if limit:
        assert cpu_exc is None and gpu_exc is None and len(gpu.excluded) == 1
        assert gpu.excluded[0]["id"] == ck.ids[victim] and gpu.t == pytest.approx(ck.t + 3.0 * ck.dt)
        a, b = cpu.fluid_state(), gpu.fluid_state()
        np.testing.assert_array_equal(a["id"], b["id"])
        diffs = {k: _scaled_diff(a[k], b[k]) for k in ("x", "z", "vx", "vz", "rho", "p")}
        assert all(d <= 1e-10 for d in diffs.values()), diffs
        assert meta["excluded"] == 1
    else:
        assert cpu_exc is not None and gpu_exc is not None and gpu.steps == ck.steps + 1
        assert (gpu_exc.step, gpu_exc.t) == (cpu_exc.step, cpu_exc.t)
        assert gpu_exc.cause.split(", e.g.")[0] == cpu_exc.cause.split(", e.g.")[0]
        assert f"id {ck.ids[victim]} " in gpu_exc.cause
        assert meta["status"] == "unstable" and meta["unstable_step"] == gpu.steps


@needs_cuda
def test_a_scene_the_gpu_step_lacks_is_refused_in_one_line(gpu_here, tmp_path):
    """ISPH (no GPU twin): DeviceError naming it, before the run directory exists."""
    from sph_core.simulation import DeviceError, Simulation

    with pytest.raises(DeviceError) as exc:
        Simulation(_scene(scheme={"kind": "isph"}), run_dir=tmp_path / "run", device="cuda")
    msg = str(exc.value)
    assert "ISPH" in msg and "\n" not in msg and msg.startswith("device cuda: not supported")
    assert not (tmp_path / "run").exists()


@needs_cuda
def test_cli_run_on_cuda_reports_the_device(gpu_here, tmp_path, capsys):
    import wavesph.cli

    path = tmp_path / "db.toml"
    path.write_text(_toml(_scene(probe_every=0.001)))
    out = tmp_path / "run"
    assert wavesph.cli.main(["run", str(path), "--device", "cuda", "--t-end", "0.001",
                             "--no-progress", "-o", str(out)]) == 0
    assert "device cuda" in capsys.readouterr().err
    meta = json.loads((out / "meta.json").read_text())
    assert meta["device"] == "cuda" and meta["status"] == "completed" and meta["steps"] > 0


@needs_cuda
def test_server_runs_a_scene_on_cuda_and_reports_it(gpu_here, tmp_path):
    """A server whose default device is cuda runs a POSTed scene there; GET /runs/{id} says so."""
    for module in ("fastapi", "uvicorn", "httpx"):   # the lent GPU machine's image lacks them
        pytest.importorskip(module)
    sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "test_server"))
    from server_harness import live_server

    scene = _scene(probe_every=0.001).model_dump(mode="json")
    scene["t_end"] = 0.001
    scene["output"]["snapshot_every"] = 0.0
    del scene["run"]   # no device of its own: the server's default
    with live_server(tmp_path, None, device="cuda") as srv:
        r = srv.http.post("/runs", json={"mode": "standalone", "scene": scene})
        assert r.status_code == 201, r.text
        info = srv.wait_state(r.json()["id"], "finished", "failed", "unstable", timeout=300)
        # a scene the GPU step lacks: the run fails with the one-line reason, never hangs running
        isph = {**scene, "scheme": {"kind": "isph"}}
        r = srv.http.post("/runs", json={"mode": "standalone", "scene": isph})
        assert r.status_code == 201, r.text
        failed = srv.wait_state(r.json()["id"], "finished", "failed", "unstable", timeout=300)
    assert failed["state"] == "failed" and failed["device"] == "cuda"
    assert failed["status"].startswith("failed: device cuda: not supported yet: ISPH")
    assert info["state"] == "finished", info["status"]
    assert info["device"] == "cuda" and info["steps"] > 0
    meta = json.loads((tmp_path / "runs" / info["id"] / "sph" / "meta.json").read_text())
    assert meta["device"] == "cuda"


def _toml(scene) -> str:
    """A scene as a TOML file (the few value types a scene has)."""
    def value(v):
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, str):
            return json.dumps(v)
        if isinstance(v, (list, tuple)):
            return "[" + ", ".join(value(x) for x in v) + "]"
        if isinstance(v, dict):
            return "{" + ", ".join(f"{k} = {value(x)}" for k, x in v.items() if x is not None) + "}"
        return repr(v)
    data = scene.model_dump(mode="json")
    return "\n".join(f"{k} = {value(v)}" for k, v in data.items() if v is not None) + "\n"
