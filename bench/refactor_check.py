"""Does a change to the solver's code change its results? (refactors must not, to round-off)

Runs a fixed set of small scenes a fixed number of steps and saves (``--save``) or compares
(``--compare``) the final particle state, ordered by particle id. Scenes cover every pass:
WCSPH with both integrators, Riemann SPH with MUSCL, Fickian and delta-plus shifting, a free
floating body, force and point probes, and a short flume with open ends driven by a linear wave
(imposed inlet, extrapolated outlet: buffers, ghost pressure, boundary gauges, absorption) whose
shifting stops beside the buffers (``shift_open_end = "none"``); ISPH closed, with open ends and with a prescribed body.

    python bench/refactor_check.py --save /tmp/ref.npz          # on the code before the change
    python bench/refactor_check.py --compare /tmp/ref.npz       # after it

Output: one JSON object per scene: ``bench``, ``scene``, ``steps``, ``particles``,
``max_abs_diff`` (over x, z, vx, vz, rho, p; 0.0 = bit-identical), ``probe_max_abs_diff``.
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

ROWS = ("x", "z", "vx", "vz", "rho", "p")


def _flume(shifting: str) -> tuple:
    """A 0.6 m flume, depth 0.2 m, open both ends, driven by an Airy wave (H 2 cm, T 1 s)."""
    from sph_core.boundary_data import WaveModelBoundary
    from sph_core.open_ends import flume_nodes
    from sph_core.scene import make_scene
    from wave_client.theories.linear import AiryWave

    d, dp = 0.2, 0.02
    scene = make_scene({
        "name": f"flume_open_{shifting}", "dp": dp, "t_end": 10.0, "still_water_level": d,
        "tank": {"x0": 0.0, "x1": 0.6, "z0": 0.0, "z1": d + 0.1},
        "water_blocks": [{"x0": 0.0, "x1": 0.6, "z0": 0.0, "z1": d}],
        "constants": {"c0": 10.0 * (9.81 * d) ** 0.5, "shifting": shifting,
                      "shift_open_end": "none"},
        "probes": [{"kind": "elevation", "name": "mid", "x": 0.3}],
        "open_boundaries": [{"side": "left", "elevation": "imposed"},
                            {"side": "right", "elevation": "extrapolated"}]})
    wave = AiryWave(0.02, 1.0, d, ramp_time=0.5)
    sources = {side: WaveModelBoundary(wave, nd, d, nd.x_face)
               for side, nd in flume_nodes(scene).items()}
    return scene, sources


def _scenes() -> dict:
    from wavesph.cases.dambreak import dambreak_scene
    from wavesph.cases.rigid_bodies import floating_box_scene

    force = {"kind": "force", "name": "wall", "x0": 0.75, "x1": 0.85, "z0": 0.0, "z1": 0.5}
    point = {"kind": "point", "name": "pt", "x": 0.1, "z": 0.05}
    db = dict(a=0.2, dp=0.01, t_end=1.0, tank_length=0.8, probes=[force, point])
    return {
        "wcsph_kdk": dambreak_scene(**db),
        "wcsph_pc": dambreak_scene(**db, integrator="symplectic_pc"),
        "riemann_muscl": dambreak_scene(**db, scheme={"kind": "riemann"}),
        "wcsph_fickian": dambreak_scene(**db, shifting="fickian"),
        "wcsph_dplus": dambreak_scene(**db, shifting="dplus"),
        "floating_box": floating_box_scene(dp=0.02, tank_length=0.8, t_end=1.0),
        "flume_open_dplus": _flume("dplus"),
        "flume_open_fickian": _flume("fickian"),
        **_isph_scenes(db),
    }


def _isph_scenes(db: dict) -> dict:
    """ISPH: the dam break, a still tank, a flume with open ends (no sources: the ends hold
    still water), a prescribed plate (a moving wall of the pressure equation)."""
    from wavesph.cases.dambreak import dambreak_scene
    from sph_core.scene import make_scene

    isph = {"kind": "isph"}
    d = 0.25
    still = {"name": "still", "dp": d / 10, "t_end": 1.0, "still_water_level": d,
             "tank": {"x0": 0.0, "x1": 2 * d, "z0": 0.0, "z1": 1.6 * d},
             "water_blocks": [{"x0": 0.0, "x1": 2 * d, "z0": 0.0, "z1": d}], "scheme": isph,
             "probes": [{"kind": "pressure_line", "name": "bed", "points": [[d, 0.0125]]}]}
    flume = {"dp": 0.02, "t_end": 10.0, "still_water_level": 0.3, "scheme": isph,
             "tank": {"x0": 0.0, "x1": 0.6, "z0": 0.0, "z1": 0.42},
             "water_blocks": [{"x0": 0.0, "x1": 0.6, "z0": 0.0, "z1": 0.3}],
             "open_boundaries": [{"side": "left", "elevation": "imposed"},
                                 {"side": "right", "elevation": "extrapolated"}]}
    plate = {"dp": 0.02, "t_end": 1.0, "scheme": isph,
             "tank": {"x0": 0, "x1": 1.0, "z0": 0, "z1": 0.6},
             "water_blocks": [{"x0": 0, "x1": 1.0, "z0": 0, "z1": 0.3}],
             "probes": [{"kind": "force", "name": "plate", "x0": 0.38, "x1": 0.62, "z0": 0.24,
                         "z1": 0.38}],
             "bodies": [{"name": "plate", "shape": "box", "x0": 0.4, "x1": 0.6, "z0": 0.26,
                         "z1": 0.36, "motion": "prescribed",
                         "series": [(0.0, 0.0, 0.0, 0.0), (1.0, 0.1, -0.05, 0.2)]}]}
    return {"isph_dambreak": dambreak_scene(**db, scheme=isph),
            "isph_still": make_scene(still),
            "isph_open": make_scene(flume),
            "isph_plate": make_scene(plate)}


def _run(scene, steps: int) -> tuple[dict, dict, int]:
    from sph_core.simulation import Simulation

    scene, sources = scene if isinstance(scene, tuple) else (scene, None)
    sim = Simulation(scene, sources=sources, window=0.02) if sources else Simulation(scene)
    sim.advance_steps(steps)
    ps = sim.particles
    n = ps.n
    view = ps.view
    order = np.argsort(view.ids[:n], kind="stable")
    state = {r: np.asarray(getattr(view, r)[:n])[order].copy() for r in ROWS}
    state["ids"] = view.ids[:n][order].copy()
    probes = {k: (np.nan if v is None else float(v)) for k, v in sim.probe_values().items()}
    sim.close()
    return state, probes, n


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    g = ap.add_mutually_exclusive_group(required=True)
    g.add_argument("--save", help="write the reference state to this .npz")
    g.add_argument("--compare", help="compare with the reference state in this .npz")
    ap.add_argument("--steps", type=int, default=400)
    ap.add_argument("--only", nargs="*", help="scene names (default: all)")
    args = ap.parse_args()
    ref = dict(np.load(args.compare)) if args.compare else {}
    out = {}
    for name, scene in _scenes().items():
        if args.only and name not in args.only:
            continue
        t0 = time.perf_counter()
        state, probes, n = _run(scene, args.steps)
        rec = {"bench": "refactor_check", "scene": name, "steps": args.steps, "particles": n,
               "wall_s": round(time.perf_counter() - t0, 2)}
        for k, v in state.items():
            out[f"{name}/{k}"] = v
        for k, v in probes.items():
            out[f"{name}/probe/{k}"] = np.array([v])
        if args.compare:
            same_ids = np.array_equal(ref[f"{name}/ids"], state["ids"])
            rec["same_particles"] = bool(same_ids)
            if same_ids:
                rec["max_abs_diff"] = max(float(np.max(np.abs(ref[f"{name}/{r}"] - state[r])))
                                          for r in ROWS)
            rec["probe_max_abs_diff"] = max(
                (float(np.nan_to_num(np.abs(ref[f"{name}/probe/{k}"][0] - v), nan=0.0))
                 for k, v in probes.items()), default=0.0)
        print(json.dumps(rec), flush=True)
    if args.save:
        np.savez(args.save, **out)


if __name__ == "__main__":
    main()
