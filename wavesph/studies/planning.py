"""`wavesph plan`: model no more than the scene needs, predicted from measured sweep data.

    req = PlanRequest(height=0.04, period=1.4, depth=0.24, structure_length=3.4, duration=8.0)
    plan = make_plan(req)              # -> Plan: dp, zone_length_m, window_steps, method, ...
    plan = make_plan(req, data=read_csv(path), throughput=2.0e6)

What is proposed and why:
  SPH zone   the structure region (beach, structures: what a wave model cannot do) plus at most
             one wavelength of flat bed before it (the inlet's wave settles and its absorber
             needs room: the demo's and the coupled flume's layout); the far field is the wave
             model's. From a scene, both parts are the scene's own, so the zone is never longer
             than the scene.
  dp, method for each method of the sweep data, error = a (H/dp)^-p fitted (least squares in
             log-log, one slope, a per case; a of the case nearest the waves in kd and H/L) to
             its flume-case points (RMSE/H against theory); the dp reaching ``target_error``
             within the H/dp range the sweep measured (no extrapolation: beyond it the plan
             proposes the finest measured H/dp and says the target is not met), at least 4 rows
             of the depth, then rounded down to a divisor of the depth (the particles must fill
             to the still-water level, sph_core.scene.datum_mismatch); then the method of the
             smallest predicted wall time. Methods of the pre-study defaults (h/dp sqrt 2 and
             artificial viscosity against walls, SUPERSEDED) and ISPH's wave settings (sized to
             each flume: NOT_PLANNED) are not proposed unless asked for.
  window     T/50 (what `wavesph couple` takes), in SPH steps of dt = cfl h / (c0 + u_orbital),
             c0 the scene's (c0_factor sqrt(2 g d) by default), else 10 sqrt(g d).
  wall       particles x steps / throughput: particles counted on the zone's own lattice
             (sph_core.geometry.build_layout, plus the inlet buffer), steps = duration / dt,
             throughput (particle-steps/s)
             the median of the sweep's points of that method, or given (calibrated on this
             machine by a short run: ``measure_throughput``).

The sweep data: wavesph/cases/data/accuracy_sweep.csv, written by `wavesph bench accuracy` (its command
in the header).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from sph_core.scene import divisor_text
from wave_client import G

from .sweeps import FLUME_WAVE_SETTINGS, METHODS, read_csv

SWEEP_CSV = "data/accuracy_sweep.csv"
WINDOWS_PER_PERIOD = 50
MIN_DEPTH_ROWS = 4
DEFAULT_TARGET = 0.05          # RMSE/H: seed 002's accuracy (<= 4.3 %), the project's goal (5 %)
EXPENSIVE_FACTOR = 3.0         # `wavesph run` warns past this cost ratio to the plan
# the pre-study defaults (sweeps.OLD_DEFAULTS: h/dp sqrt 2, wall artificial viscosity on), which
# the wave-decay study replaced (docs/studies/wave_decay_study.md): kept in the sweep data to
# compare against, never proposed by default
SUPERSEDED = tuple(m for m, o in METHODS.items() if o.get("alpha_wall_factor") == 1.0)
# methods whose flumes take settings sized to the wave (sweeps.FLUME_WAVE_SETTINGS: ISPH's
# relaxation zones, its ramp): the planned zone's scene does not apply them and the step
# estimate is WCSPH's (c0), so the plan does not propose them
NOT_PLANNED = SUPERSEDED + tuple(FLUME_WAVE_SETTINGS)


@dataclass(frozen=True)
class PlanRequest:
    """What the plan needs: the waves (height H [m], period T [s]), still-water depth d [m] in
    front of the structure, the length of the structure region [m] (beach, breakwater: what SPH
    must resolve; 0 for a plain flume), simulated seconds, and the accepted RMSE/H."""

    height: float
    period: float
    depth: float
    structure_length: float = 0.0
    duration: float = 10.0
    target_error: float = DEFAULT_TARGET
    beach_slope: float | None = None   # a beach (rising to 0.1 m above still water) or None
    flat_length: float | None = None   # flat bed before the structure region [m]: the zone keeps
    #                                    at most one wavelength of it (None: one wavelength)
    c0: float | None = None            # speed of sound [m/s] of the runs (None: 10 sqrt(g d))


@dataclass(frozen=True)
class Plan:
    method: str
    dp: float
    H_over_dp: float
    zone_length_m: float
    window_s: float
    window_steps: int
    particles: int
    steps: int
    expected_error: float
    expected_wall_s: float
    throughput: float
    fit: dict[str, Any]
    wavelength_m: float
    target_error: float
    flat_m: float = 0.0              # the zone's parts [m]: flat bed before the structure region
    structures_m: float = 0.0        # ... and the structure region (beach, structures)
    meets_target: bool = True        # False: the sweep's finest H/dp does not reach the target
    c0: float = 0.0                  # speed of sound [m/s] the steps were counted with

    def to_json(self) -> dict[str, Any]:
        return asdict(self)


def sweep_data(path: str | Path | None = None) -> list[dict[str, Any]]:
    """Rows of the shipped accuracy sweep (or of ``path``)."""
    if path is None:
        ref = resources.files("wavesph.cases").joinpath(SWEEP_CSV)
        path = Path(str(ref))
    return read_csv(Path(path))


def fit_error(rows: list[dict[str, Any]], method: str,
              wave: tuple[float, float, float] | None = None) -> dict[str, float] | None:
    """error = a (H/dp)^-p over the method's finished flume points: {a, p, n, case}; None if no
    case has two distinct H/dp. One slope p for all cases (least squares in log-log with one
    intercept per case: the waves differ in how hard they are, not in how the error converges);
    a of the case nearest ``wave`` = (H, T, d) in relative depth kd and steepness H/L (else the
    geometric mean of the cases' a)."""
    by_case: dict[str, list[tuple[float, float]]] = {}
    for r in rows:
        if (r["method"] == method and r["case"].startswith("flume_") and r["status"] == "ok"
                and r["error"] and r["H_over_dp"]):
            by_case.setdefault(r["case"], []).append((math.log(r["H_over_dp"]), math.log(r["error"])))
    by_case = {c: v for c, v in by_case.items() if len({x for x, _ in v}) >= 2}
    if not by_case:
        return None
    # common slope: pooled within-case regression
    sxy = sxx = 0.0
    for v in by_case.values():
        xm = sum(x for x, _ in v) / len(v)
        ym = sum(y for _, y in v) / len(v)
        sxy += sum((x - xm) * (y - ym) for x, y in v)
        sxx += sum((x - xm) ** 2 for x, _ in v)
    p = -sxy / sxx
    log_a = {c: sum(y + p * x for x, y in v) / len(v) for c, v in by_case.items()}
    case = None
    if wave is not None:
        case = min(log_a, key=lambda c: _wave_distance(c, wave))
        la = log_a[case]
    else:
        la = sum(log_a.values()) / len(log_a)
    xs = [x for v in by_case.values() for x, _ in v]
    return {"a": math.exp(la), "p": p, "n": sum(len(v) for v in by_case.values()),
            "H_over_dp_min": math.exp(min(xs)), "H_over_dp_max": math.exp(max(xs)),
            **({"case": case} if case else {})}


def _wave_distance(case: str, wave: tuple[float, float, float]) -> float:
    """Distance of a seed 002 flume case from the wave (H, T, d) in (log kd, log H/L)."""
    from ..cases.seed002_waves import read_cases

    row = read_cases().get(case.removeprefix("flume_"))
    if row is None:
        return math.inf

    def coords(h: float, t: float, d: float) -> tuple[float, float]:
        wl = wavelength(t, d)
        return math.log(2 * math.pi / wl * d), math.log(h / wl)

    a = coords(float(row["H"]), float(row["T"]), float(row["d"]))
    b = coords(*wave)
    return math.hypot(a[0] - b[0], a[1] - b[1])


def median_throughput(rows: list[dict[str, Any]], method: str) -> float | None:
    """Median particle-steps per wall second of the method's finished flume points."""
    v = [r["particles"] * r["steps"] / r["wall_s"] for r in rows
         if r["method"] == method and r["case"].startswith("flume_") and r["status"] == "ok"
         and r["wall_s"] and r["particles"] and r["steps"]]
    return float(np.median(v)) if v else None


def wavelength(period: float, depth: float) -> float:
    from wave_client.theories import wavenumber

    return 2 * math.pi / float(wavenumber(2 * math.pi / period, depth))


def step_estimate(dp: float, depth: float, height: float, period: float,
                  method: str, c0: float | None = None) -> float:
    """dt [s] of the adaptive step at the wave's largest orbital speed; ``c0`` [m/s] the runs'
    speed of sound (default 10 sqrt(g d); a scene's default c0_factor sqrt(2 g d) is sqrt 2
    larger, and its steps as many more: `plan` under-predicted them x1.5 before it used the
    scene's)."""
    c = METHODS[method]
    h = c["h_over_dp"] * dp
    k = 2 * math.pi / wavelength(period, depth)
    u = math.pi * height / period / math.tanh(k * depth)
    c0 = 10.0 * math.sqrt(G * depth) if c0 is None else c0
    return c.get("cfl", 0.25) * h / (c0 + u)


def depth_divisor(depth: float, dp: float) -> float:
    """The largest spacing <= ``dp`` that divides ``depth`` (whole rows of particles)."""
    return depth / math.ceil(depth / dp - 1e-9)


def zone_parts(req: PlanRequest) -> tuple[float, float]:
    """(flat bed before the structure region, structure region) of the planned zone [m]."""
    wl = wavelength(req.period, req.depth)
    flat = wl if req.flat_length is None else min(wl, req.flat_length)
    return flat, req.structure_length


def zone_scene(req: PlanRequest, dp: float, method: str = "wcsph_kdk_h2_wallav0") -> Any:
    """The planned SPH zone as a scene: one wavelength of flat bed from an open inlet, then the
    structure region (a beach of ``beach_slope`` or flat bed ending in an outlet)."""
    from sph_core.scene import make_scene

    from ..cases.coupled_flume import depth_for_case
    from ..cases.wave_flume import buffer_width_for

    d = depth_for_case(req.depth, dp)
    flat, structures = zone_parts(req)
    top = d + 2 * req.height + 4 * dp
    opts = dict(METHODS[method])
    scheme = opts.pop("scheme", None)          # a method's scheme is a scene table of its own
    cst = {"c0": req.c0 or 10.0 * math.sqrt(G * d), **opts}
    extra = {"scheme": scheme} if scheme else {}
    bw = buffer_width_for(req.height, req.period, d, dp)
    if req.beach_slope:
        x_toe = dp * round(flat / dp)
        run = structures if structures > 0 else (d + 0.1) / req.beach_slope   # a scene's own
        x1 = dp * round((x_toe + run) / dp)
        return make_scene({
            "name": "plan-zone", "dp": dp, "t_end": req.duration, "still_water_level": d,
            "tank": {"x0": 0.0, "x1": x1, "z0": 0.0, "z1": max(top, d + 0.1 + 2 * dp)},
            "water_blocks": [{"x0": 0.0, "x1": min(x1, x_toe + d / req.beach_slope), "z0": 0.0,
                              "z1": d}],
            "beds": [{"points": [[x_toe, 0.0], [x1, req.beach_slope * (x1 - x_toe)]]}],
            "constants": cst, **extra,
            "open_boundaries": [{"side": "left", "elevation": "imposed", "absorb": True,
                                 "buffer_width": bw}]})
    length = dp * round((flat + structures) / dp)
    return make_scene({
        "name": "plan-zone", "dp": dp, "t_end": req.duration, "still_water_level": d,
        "tank": {"x0": 0.0, "x1": length, "z0": 0.0, "z1": top},
        "water_blocks": [{"x0": 0.0, "x1": length, "z0": 0.0, "z1": d}], "constants": cst, **extra,
        "open_boundaries": [{"side": "left", "elevation": "imposed", "absorb": True,
                             "buffer_width": bw},
                            {"side": "right", "elevation": "extrapolated", "absorb": True,
                             "buffer_width": bw}]})


def count_particles(scene: Any) -> int:
    """Particles of a scene at its start: the lattice (fluid + walls) plus one buffer per open
    end of its columns (``buffer_width``, at least ceil(2h/dp)) over the depth, which replaces
    that end's wall."""
    from sph_core.geometry import buffer_layers, build_layout, wall_layers

    lay = build_layout(scene)
    n = lay.fluid_x.size + lay.wall_x.size
    wall_col = wall_layers(scene) * math.ceil((scene.tank.z1 - scene.tank.z0) / scene.dp)
    depth_rows = math.ceil((scene.still_water_level - scene.tank.z0) / scene.dp)
    for o in scene.open_boundaries:
        n += buffer_layers(scene, o.buffer_width) * depth_rows - wall_col
    return int(n)


MAX_PLAN_PARTICLES = 5e7   # beyond this a method cannot reach the target on any machine we plan for


def _unstable_flumes(rows: list[dict[str, Any]], method: str) -> bool:
    """A method whose flume points in the sweep data ended unstable is not planned for waves
    (ISPH's wave flume today, docs/studies/schemes.md)."""
    return any(r["method"] == method and r["case"].startswith("flume_") and r["status"] == "unstable"
               for r in rows)


def make_plan(req: PlanRequest, data: list[dict[str, Any]] | None = None,
              throughput: float | None = None, methods: list[str] | None = None,
              dp: float | None = None) -> Plan:
    """The cheapest (method, dp) predicted to reach ``req.target_error`` (or, given ``dp``, the
    cheapest method at that dp). Raises ValueError if the data fits no method."""
    rows = sweep_data() if data is None else data
    wl = wavelength(req.period, req.depth)
    flat, structures = zone_parts(req)
    c0 = req.c0 or 10.0 * math.sqrt(G * req.depth)
    best: Plan | None = None
    for m in methods or [m for m in METHODS if m not in NOT_PLANNED]:
        fit = fit_error(rows, m, (req.height, req.period, req.depth))
        tp = throughput or median_throughput(rows, m)
        if fit is None or tp is None or fit["p"] <= 0 or _unstable_flumes(rows, m):
            continue
        if dp is None:
            ratio = (fit["a"] / req.target_error) ** (1.0 / fit["p"])
            # inside the measured range: the fit says nothing about other resolutions
            ratio = min(max(ratio, fit["H_over_dp_min"]), fit["H_over_dp_max"])
            dp_m = min(req.height / ratio, req.depth / MIN_DEPTH_ROWS)
            # whole rows of the depth, in the fewest digits the scene accepts
            dp_m = float(divisor_text(req.depth, depth_divisor(req.depth, dp_m)))
        else:
            dp_m = dp
        # a fit that barely converges asks for a spacing no machine runs (p 0.04 gave dp 1e-5
        # m): judge it by the water's area before building its lattice
        if req.depth * (flat + structures) / dp_m ** 2 > MAX_PLAN_PARTICLES:
            continue
        scene = zone_scene(req, dp_m, m)
        n = count_particles(scene)
        dt = step_estimate(dp_m, req.depth, req.height, req.period, m, c0)
        steps = int(math.ceil(req.duration / dt))
        wall = n * steps / tp    # tp is per step of this method: two passes cost in it
        window = req.period / WINDOWS_PER_PERIOD
        err = fit["a"] * (req.height / dp_m) ** (-fit["p"])
        cand = Plan(method=m, dp=dp_m, H_over_dp=round(req.height / dp_m, 3),
                    zone_length_m=round(scene.tank.x1 - scene.tank.x0, 4), window_s=window,
                    window_steps=max(1, round(window / dt)), particles=n, steps=steps,
                    expected_error=round(err, 5), expected_wall_s=round(wall, 2),
                    throughput=round(tp), fit={k: (round(v, 4) if isinstance(v, float) else v) for k, v in fit.items()},
                    wavelength_m=round(wl, 4), target_error=req.target_error,
                    flat_m=round(flat, 4), structures_m=round(structures, 4),
                    meets_target=err <= req.target_error * 1.001, c0=round(c0, 4))
        # a method reaching the target beats one that does not, whatever their costs
        if (best is None or (cand.meets_target, -cand.expected_wall_s)
                > (best.meets_target, -best.expected_wall_s)):
            best = cand
    if best is None:
        raise ValueError("the sweep data has no method with >= 2 resolutions of flume points")
    return best


def request_from_scene(scene: Any, height: float, period: float,
                       target_error: float | None = None) -> PlanRequest:
    """A PlanRequest from an SPH scene and its waves: depth from the still-water level to the
    tank floor, the structure region from the first bed point or structure to the tank's end,
    a beach slope from the first bed, the duration from t_start to t_end."""
    if scene.still_water_level is None:
        raise ValueError("the scene has no still_water_level: plan needs waves on still water")
    t = scene.tank
    depth = scene.still_water_level - t.z0
    starts = [b.points[0][0] for b in scene.beds] + [s.x0 for s in scene.structures]
    x_s = min(starts) if starts else t.x1
    slope = None
    if scene.beds:
        (xa, za), (xb, zb) = scene.beds[0].points[0], scene.beds[0].points[-1]
        slope = (zb - za) / (xb - xa) if xb > xa and zb > za else None
    return PlanRequest(height=height, period=period, depth=depth, structure_length=t.x1 - x_s,
                       duration=scene.t_end - scene.t_start,
                       target_error=DEFAULT_TARGET if target_error is None else target_error,
                       beach_slope=slope, flat_length=x_s - t.x0, c0=scene.c0)


def scene_cost(scene: Any, height: float, period: float,
               data: list[dict[str, Any]] | None = None) -> dict[str, Any]:
    """The scene's own predicted error and wall time (its dp and method, its particles)."""
    rows = sweep_data() if data is None else data
    c = scene.constants
    method = next((m for m, o in METHODS.items()
                   if o.get("integrator", "kdk") == c.integrator
                   and abs(o["h_over_dp"] - c.h_over_dp) < 1e-3
                   and o["alpha_wall_factor"] == c.alpha_wall_factor), "wcsph_kdk")
    wave = (height, period, scene.still_water_level - scene.tank.z0)
    fit = fit_error(rows, method, wave) or fit_error(rows, "wcsph_kdk", wave)
    tp = median_throughput(rows, method) or median_throughput(rows, "wcsph_kdk")
    depth = scene.still_water_level - scene.tank.z0
    n = count_particles(scene)
    steps = math.ceil((scene.t_end - scene.t_start) / step_estimate(scene.dp, depth, height,
                                                                   period, method, scene.c0))
    err = fit["a"] * (height / scene.dp) ** (-fit["p"]) if fit else None
    return {"method": method, "dp": scene.dp, "particles": n, "steps": steps,
            "expected_error": err, "expected_wall_s": n * steps / tp if tp else None}


def expense_warning(scene: Any, height: float, period: float,
                    data: list[dict[str, Any]] | None = None) -> str | None:
    """A warning if ``scene`` is predicted to cost more than EXPENSIVE_FACTOR times the plan
    that reaches the same error; None otherwise."""
    own = scene_cost(scene, height, period, data)
    if own["expected_error"] is None or not own["expected_wall_s"]:
        return None
    req = request_from_scene(scene, height, period, target_error=own["expected_error"])
    plan = make_plan(req, data)
    ratio = own["expected_wall_s"] / max(plan.expected_wall_s, 1e-9)
    if ratio <= EXPENSIVE_FACTOR:
        return None
    return (f"this scene is predicted to cost {ratio:.1f}x the plan for the same accuracy "
            f"(expected RMSE/H {own['expected_error']:.3g}): {own['particles']} particles x "
            f"{own['steps']} steps against the plan's {plan.particles} x {plan.steps} "
            f"(dp {plan.dp} m, method {plan.method}, SPH zone {plan.zone_length_m} m); "
            "see `wavesph plan`")


def measure_throughput(method: str = "wcsph_kdk", seconds: float = 1.0) -> float:
    """Particle-steps per wall second of a short flume run (case V's wave at dp = 0.03 m, the
    first ``seconds`` simulated) here and now, same process, same load: the plan's wall
    prediction then compares like with like."""
    from wave_client.theories import build_theory

    from .sweeps import warm_up_method
    from ..cases.wave_flume import run_wave_flume, wave_flume_scene

    warm_up_method(method)
    model = build_theory("stream", height=0.06, period=2.0, depth=0.3, ramp_time=2.0,
                         n_fourier=16)
    scene = wave_flume_scene(depth=0.3, wavelength=float(model.length), height=0.06, dp=0.03,
                             t_end=seconds, probe_every=2.0 / 40, **METHODS[method])
    run = run_wave_flume(scene, model, window=2.0 / WINDOWS_PER_PERIOD)
    return run.particles * run.steps / run.wall_s
