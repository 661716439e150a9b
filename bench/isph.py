"""ISPH against WCSPH at the same dp: one JSON object per line.

    PYTHONPATH=. NUMBA_NUM_THREADS=1 python bench/isph.py [--quick] [--solvers bicgstab,amg]
        [--cases still,dambreak,obstacle] [--schemes wcsph,isph] [--t-still 1.0]
        [--variants '[{"isph_wall_stop": 0.5}, {"ppe_solver": "bicgstab"}]']

``--variants``: ISPH [scheme] options, one run of each case per variant (in this one process,
so the kernels compile once); each line then carries its ``variant``.

Cases (coarse; every wall time is of this process on whatever load the machine has):
- still: still water d = 0.25 m, d/dp = 25 (tests/test_sph_core/test_hydrostatic.py's tank) for
  ``T_STILL`` s: bed pressure (pressure-line point dp/2 above the bed, mid-tank) over the second
  half: mean error against rho g d and std (noise); one line per PPE solver, PPE iterations per
  step, mean dt, wall s per simulated s;
- dambreak: Martin & Moyce column a = 0.1 m, a/dp = 20, tank 5a (tests/test_cases/test_dambreak.py)
  to T = t sqrt(2g/a) = 6 (the surge hits the right wall at T ~ 3.6): front error up to T = 3
  against Martin & Moyce and Koshizuka & Oka, the pressure noise at the right wall (1 cm above
  the bed; std after a 10 Hz high-pass, wavesph.cases.dambreak_obstacle.pressure_noise), mean dt, wall s
  per simulated s;
- obstacle: seed 004's dam break on a tall structure in 2D (wavesph.cases.dambreak_obstacle), dp 0.01 m:
  0.5 s (the impact peaks at ~0.33 s): peak force, its time, force noise; the traces go to
  runs/bench_isph/obstacle_<scheme>.csv.
The first runs compile (numba); a warm-up scene runs first so wall times are of cached code.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np

from wavesph.cases.dambreak import dambreak_scene, front_errors, martin_moyce_table
from wavesph.cases.dambreak_obstacle import pressure_noise, run_obstacle
from sph_core.scene import make_scene
from sph_core.simulation import Simulation

D = 0.25
T_STILL = 1.0
A = 0.1
CUTOFF_HZ = 10.0
OUT = Path("runs/bench_isph")


def still_scene(scheme: dict, t_end: float, res: int = 25):
    dp = D / res
    return make_scene({
        "name": "still", "dp": dp, "t_end": t_end, "still_water_level": D,
        "tank": {"x0": 0.0, "x1": 2 * D, "z0": 0.0, "z1": 1.6 * D},
        "water_blocks": [{"x0": 0.0, "x1": 2 * D, "z0": 0.0, "z1": D}],
        "scheme": scheme, "output": {"probe_every": 0.005},
        "probes": [{"kind": "pressure_line", "name": "bed", "points": [[D, 0.5 * dp]]},
                   {"kind": "elevation", "name": "g", "x": 0.6 * D}]})


def _ppe(sim: Simulation) -> dict:
    return sim.stepper.stats() if sim.stepper else {}


def still(scheme: dict, t_end: float) -> dict:
    sim = Simulation(still_scene(scheme, t_end))
    tic = time.perf_counter()
    sim.advance_to(t_end)
    wall = time.perf_counter() - tic
    t = np.array([r["t"] for r in sim.history])
    p = np.array([r["bed_p0"] for r in sim.history], dtype=float)
    eta = np.array([r["g_eta"] for r in sim.history], dtype=float)
    late = t >= 0.5 * t_end
    z = 0.5 * sim.scene.dp
    exact = 1000.0 * 9.81 * (D - z)
    return {"case": "still", "scheme": sim.scene.scheme.kind, "dp": sim.scene.dp,
            "bed_p_error": float(np.mean(p[late]) / exact - 1.0),
            "bed_p_noise_pa": float(np.std(p[late])), "bed_p_noise_rel": float(np.std(p[late]) / exact),
            "eta_drift_m": float(eta[-1] - eta[0]), "steps": sim.steps,
            "v_max_end": float(np.hypot(sim.fluid_state()["vx"], sim.fluid_state()["vz"]).max()),
            "mean_dt": t_end / sim.steps, "wall_s_per_sim_s": wall / t_end,
            "particle_steps_per_s": sim.n_particles * sim.steps / wall, **_ppe(sim)}


def dambreak_run(scheme: dict, res: int = 20, tag: str = "") -> dict:
    t_end = 6.0 / math.sqrt(2 * 9.81 / A)
    dp = A / res
    base = dambreak_scene(a=A, dp=dp, t_end=t_end, tank_length=5 * A,
                          probe_every=0.001).model_dump()
    base["scheme"] = scheme
    # the run-up jet on the right wall throws drops over the tank top (z = 5a) after T ~ 5 (ISPH:
    # 5 % of the fluid by T = 7): excluded and counted (``excluded``) rather than ending the run
    base["constants"]["exclude_limit"] = 0.2
    base["probes"].append({"kind": "pressure_line", "name": "wall",
                           "points": [[5 * A - 0.5 * dp, 0.01]]})
    sim = Simulation(make_scene(base))
    tic = time.perf_counter()
    sim.advance_to(t_end)
    wall = time.perf_counter() - tic
    h = [r for r in sim.history if r["front_x"] is not None]
    t = np.array([r["t"] for r in h])
    x = np.array([r["front_x"] for r in h])
    mm = front_errors(t, x, A, t_max=3.0)
    ko = martin_moyce_table(Path("tests/data/dambreak_koshizuka_oka_1996.csv"))
    keep = ko[0] > 0
    ko_err = front_errors(t, x, A, t_max=3.0, table=(ko[0][keep], ko[1][keep]))
    tp = np.array([r["t"] for r in sim.history])
    pw = np.array([np.nan if r["wall_p0"] is None else r["wall_p0"] for r in sim.history])
    OUT.mkdir(parents=True, exist_ok=True)
    np.savetxt(OUT / f"dambreak_{sim.scene.scheme.kind}{tag}.csv", np.column_stack([tp, pw]),
               delimiter=",", header="t,p_wall_Pa", comments="")
    return {"case": "dambreak", "scheme": sim.scene.scheme.kind, "dp": dp,
            "front_error_mm": mm["max_rel_error"], "front_rms_mm": mm["rms_rel_error"],
            "front_error_ko": ko_err["max_rel_error"],
            "wall_pressure_noise_pa": pressure_noise(tp, pw, CUTOFF_HZ),
            "wall_pressure_max_pa": float(np.nanmax(pw)), "steps": sim.steps,
            "mean_dt": t_end / sim.steps, "wall_s_per_sim_s": wall / t_end,
            "particle_steps_per_s": sim.n_particles * sim.steps / wall,
            "excluded": len(sim.excluded), **_ppe(sim)}


def obstacle(scheme: dict, t_end: float) -> dict:
    # splash over the structure's top (ISPH: > 1 % of the fluid by 0.54 s) is excluded and counted
    r = run_obstacle(dp=0.01, t_end=t_end, scheme=scheme, cutoff=CUTOFF_HZ, exclude_limit=0.2)
    OUT.mkdir(parents=True, exist_ok=True)
    np.savetxt(OUT / f"obstacle_{r['scheme']}.csv", np.column_stack([r["t"], r["fx"], r["p_face"]]),
               delimiter=",", header="t,fx_N_per_m,p_face_Pa", comments="")
    return {"case": "obstacle", **{k: v for k, v in r.items() if k not in ("t", "fx", "p_face")}}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="still water only, 0.3 s")
    ap.add_argument("--solvers", default="bicgstab,amg")
    ap.add_argument("--cases", default="still,dambreak,obstacle")
    ap.add_argument("--schemes", default="wcsph,isph")
    ap.add_argument("--solver", default=None, help="ISPH solver of dambreak/obstacle (default: the scene's)")
    ap.add_argument("--variants", default=None,
                    help="JSON list of ISPH [scheme] option sets; replaces --solvers/--solver")
    ap.add_argument("--t-still", type=float, default=None, help=f"still-water duration (default {T_STILL} s)")
    a = ap.parse_args()
    t_still = a.t_still or (0.3 if a.quick else T_STILL)
    if a.variants:
        variants = json.loads(a.variants)
        cases = a.cases.split(",")
        for sch in ({"kind": "wcsph"}, {"kind": "isph"}):
            Simulation(still_scene(sch, 0.01, res=5)).advance_to(0.01)
        runs = {"still": lambda s: still(s, t_still),
                "dambreak": lambda s: dambreak_run(s, tag="_" + "_".join(
                    f"{k}{v}" for k, v in s.items() if k != "kind")),
                "obstacle": lambda s: obstacle(s, 0.5)}
        for case in cases:
            if "wcsph" in a.schemes.split(","):
                print(json.dumps(runs[case]({"kind": "wcsph"})), flush=True)
            for v in variants:
                try:
                    out = runs[case]({"kind": "isph", **v})
                except Exception as e:  # an unstable variant: say so and go on with the next
                    out = {"case": case, "scheme": "isph", "error": f"{type(e).__name__}: {e}"}
                print(json.dumps({**out, "variant": v}), flush=True)
        return
    # warm-up: compile both schemes' kernels on a tiny tank
    for sch in ({"kind": "wcsph"}, {"kind": "isph"}):
        Simulation(still_scene(sch, 0.01, res=5)).advance_to(0.01)
    cases = a.cases.split(",")
    isph = {"kind": "isph", **({"ppe_solver": a.solver} if a.solver else {})}
    if "still" in cases:
        print(json.dumps(still({"kind": "wcsph"}, t_still)), flush=True)
        for s in a.solvers.split(","):
            print(json.dumps(still({"kind": "isph", "ppe_solver": s}, t_still)), flush=True)
    if a.quick:
        return
    schemes = [s for s in ({"kind": "wcsph"}, isph) if s["kind"] in a.schemes.split(",")]
    if "dambreak" in cases:
        for sch in schemes:
            print(json.dumps(dambreak_run(sch)), flush=True)
    if "obstacle" in cases:
        for sch in schemes:
            print(json.dumps(obstacle(sch, 0.5)), flush=True)


if __name__ == "__main__":
    main()
