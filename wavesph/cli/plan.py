"""`wavesph plan SCENE.toml --H H --T T`: the SPH zone, dp, coupling window and method
a scene needs, with the error and wall time predicted from the measured sweep (wavesph/studies/planning.py)."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from wavesph.studies.planning import (DEFAULT_TARGET, make_plan, request_from_scene, scene_cost,
                                      sweep_data)
from sph_core.scene import SceneError, load_scene


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("scene", type=Path, help="SPH scene (TOML) with a still_water_level")
    # --H/--T as in `wavesph couple`/`submit`, the HTTP source and a scene's [source] table;
    # --height/--period kept as the long spellings
    parser.add_argument("--H", "--height", dest="height", type=float, required=True,
                        help="wave height H [m]")
    parser.add_argument("--T", "--period", dest="period", type=float, required=True,
                        help="wave period T [s]")
    parser.add_argument("--target-error", type=float, default=DEFAULT_TARGET,
                        help=f"accepted RMSE/H against theory (default {DEFAULT_TARGET})")
    parser.add_argument("--data", type=Path, default=None,
                        help="accuracy.csv of a sweep (default: the one shipped in wavesph/cases/data)")
    parser.add_argument("--throughput", type=float, default=None,
                        help="particle-steps per second of this machine (default: the sweep's)")
    parser.add_argument("--json", action="store_true", help="print one JSON object only")


def main(args: argparse.Namespace) -> int:
    try:
        scene = load_scene(args.scene)
        req = request_from_scene(scene, args.height, args.period, args.target_error)
        data = sweep_data(args.data)
        plan = make_plan(req, data, throughput=args.throughput)
        own = scene_cost(scene, args.height, args.period, data)
    except (SceneError, ValueError, FileNotFoundError) as exc:
        print(f"wavesph plan: {exc}", file=sys.stderr)
        return 2
    out = {**plan.to_json(), "scene": {k: own[k] for k in ("method", "dp", "particles", "steps",
                                                          "expected_error", "expected_wall_s")}}
    if args.json:
        print(json.dumps(out))
        return 0
    rows = [("", "plan", "scene as written"),
            ("method", plan.method, own["method"]),
            ("dp [m]", f"{plan.dp:g}", f"{scene.dp:g}"),
            ("H/dp", f"{plan.H_over_dp:g}", f"{args.height / scene.dp:.3g}"),
            ("SPH zone [m]", f"{plan.zone_length_m:g}", f"{scene.tank.x1 - scene.tank.x0:g}"),
            ("window", f"{plan.window_s:.4g} s = {plan.window_steps} steps", ""),
            ("particles", f"{plan.particles}", f"{own['particles']}"),
            ("steps", f"{plan.steps}", f"{own['steps']}"),
            ("expected RMSE/H", f"{plan.expected_error:.3g}", _fmt(own["expected_error"])),
            ("expected wall [s]", f"{plan.expected_wall_s:.3g}", _fmt(own["expected_wall_s"]))]
    for a, b, c in rows:
        print(f"{a:<18} {b:<26} {c}")
    print(f"(fit error = {plan.fit['a']:.3g} (H/dp)^-{plan.fit['p']:.2f} over {plan.fit['n']} "
          f"sweep points, level of {plan.fit.get('case', 'all cases')}; throughput "
          f"{plan.throughput:.3g} particle-steps/s)")
    print(json.dumps(out))
    return 0


def _fmt(v: float | None) -> str:
    return "-" if v is None else f"{v:.3g}"
