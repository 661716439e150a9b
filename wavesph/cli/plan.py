"""`wavesph plan SCENE.toml --H H --T T`: the SPH zone, dp, coupling window and method
a scene needs, with the error and wall time predicted from the measured sweep (wavesph/studies/planning.py)."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from wavesph.studies.planning import (DEFAULT_TARGET, Plan, make_plan, request_from_scene,
                                      scene_cost, sweep_data)
from wavesph.studies.sweeps import METHODS
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
        if scene.dim == 3:
            raise ValueError("a 3D scene (dim = 3): the sweep the plan rests on is 2D flumes; "
                             "no 3D plan yet (docs/developer/three_dimensions.md has 3D costs)")
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
    # a table for a person; the JSON only with --json
    rows = [("", "plan", "scene as written"),
            ("method", plan.method, own["method"]),
            ("dp [m]", repr(plan.dp), f"{scene.dp:g}"),
            ("H/dp", f"{plan.H_over_dp:g}", f"{args.height / scene.dp:.3g}"),
            ("SPH zone [m]", f"{plan.zone_length_m:.3g} = {plan.flat_m:.3g} flat + "
                             f"{plan.structures_m:.3g} structures", f"{scene.tank.x1 - scene.tank.x0:g}"),
            ("window", f"{plan.window_s:.4g} s = {plan.window_steps} steps", ""),
            ("particles", f"{plan.particles}", f"{own['particles']}"),
            ("steps", f"{plan.steps}", f"{own['steps']}"),
            ("expected RMSE/H", f"{plan.expected_error:.3g}", _fmt(own["expected_error"])),
            ("expected wall [s]", f"{plan.expected_wall_s:.3g}", _fmt(own["expected_wall_s"]))]
    for a, b, c in rows:
        print(f"{a:<18} {b:<34} {c}")
    print()
    print(verdict(plan, own))
    print(f"SPH zone: {plan.flat_m:.3g} m of flat bed before the structure region (at most one "
          f"wavelength, {plan.wavelength_m:.3g} m: the inlet's wave settles and its absorber needs "
          f"room) + {plan.structures_m:.3g} m from the first bed or structure to the tank's end.")
    print(f"Rests on: error = {plan.fit['a']:.3g} (H/dp)^-{plan.fit['p']:.2f} fitted to "
          f"{plan.fit['n']} flume points (RMSE/H against theory) of {plan.method} measured at "
          f"H/dp {plan.fit['H_over_dp_min']:.3g}-{plan.fit['H_over_dp_max']:.3g} (level of "
          f"{plan.fit.get('case', 'all cases')}; {args.data or 'the shipped sweep, wavesph/cases/data/accuracy_sweep.csv'}); "
          f"steps of dt = cfl h / (c0 + orbital u) with the scene's c0 = {plan.c0:.3g} m/s; "
          f"wall = particles x steps / {plan.throughput:.3g} particle-steps/s "
          f"({'--throughput' if args.throughput else 'median of the sweep points, on the machine that measured them'}).")
    print("To apply it, in the scene file:")
    print(toml_snippet(plan))
    return 0


def verdict(plan: Plan, own: dict) -> str:
    """One sentence: keep the scene, or take the plan, and whether the target is met."""
    target = plan.target_error
    if not plan.meets_target:
        return (f"No measured resolution reaches RMSE/H {target:g}: the plan is the finest H/dp the "
                f"sweep measured ({plan.fit['H_over_dp_max']:.3g}); finer spacings need a sweep "
                "that covers them (`wavesph bench accuracy`).")
    err, wall = own["expected_error"], own["expected_wall_s"]
    if err is not None and wall is not None and err <= target and wall <= plan.expected_wall_s:
        return (f"The scene as written already meets RMSE/H {target:g} (expected {err:.3g}) at no "
                f"more cost than the plan: keep it.")
    return f"The plan is the cheapest measured way to RMSE/H {target:g}."


def toml_snippet(plan: Plan) -> str:
    """The scene-file lines that make a scene run the plan's dp and method."""
    opts = dict(METHODS[plan.method])
    scheme = opts.pop("scheme", None)
    lines = [f"dp = {plan.dp!r}"]   # the digits the scene needs (sph_core.scene.divisor_text)
    if scheme:
        lines += ["[scheme]"] + [f"{k} = {json.dumps(v)}" for k, v in scheme.items()]
    if opts:
        lines += ["[constants]"] + [f"{k} = {json.dumps(v)}" for k, v in opts.items()]
    return "\n".join("    " + ln for ln in lines)


def _fmt(v: float | None) -> str:
    return "-" if v is None else f"{v:.3g}"
