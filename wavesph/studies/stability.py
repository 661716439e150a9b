"""The stability suite: where do the SPH methods fail? method x scenario -> status, time, reason.

    rows = run_stability(points, out)              # on dask, like the accuracy sweep
    write_stability_csv(rows, out / "stability.csv"); plot_stability(rows, out / "stability.png")

Each scenario is a small run of a scene where SPH methods are known to go wrong, with what it
measures. Status: ``stable`` (ran to the end, every measure within its bound), ``noisy`` (ran
to the end, a measure past its bound: the reason names it and its value), ``unstable`` (the
solver's guard stopped the run: non-finite values, density out of band, a particle through a wall;
``t_fail`` and the solver's cause), ``failed`` (the set-up raised, e.g. a wave theory that does
not converge). Every number written is finite (asserted): an unstable run ends as a status and a
reason, never as NaN in the outputs.

Scenarios (T_s: the run's simulated seconds; quick / full):
  still_water        a 1 m tank of still water d = 0.3 m for 40 / 200 sqrt(d/g): level drift,
                     surface noise (std of eta at mid-tank, second half), largest speed.
  shallow_water      still water only 5 dp deep in a 1 m tank, under the c0 of the 0.3 m tank (as over
                     a beach, whose c0 comes from its deepest water), dp 0.02 / 0.01, for 3 / 5 s:
                     largest speed at the end. It broke up (0.32 sqrt(g d) at 3 s, dp 0.02) when
                     kdk read its pressure half a step too early (wcsph.kdk_pressure,
                     docs/physics/wcsph.md).
  no_diffusion       the same with delta-SPH off (delta = 0) for 3 / 10 s: pressure noise, the
                     std over particles of (p - rho0 g (d - z)) / (rho0 g d) at the end.
  cfl_1.5            the dam break with cfl = 1.5, past the scene's limit 0.5: the scene validates
                     cfl <= 0.5, so the suite builds it through ``unchecked`` (pydantic
                     model_copy skips validation; nothing else in wavesph does this).
  low_c0             the dam break with c0 = 1 x sqrt(2 g H) (Mach ~ 1 instead of 0.1): largest
                     |rho/rho0 - 1| and Mach number.
  tensile            the dam break with neither artificial viscosity nor density diffusion
                     (alpha = delta = 0): lowest pressure / (rho0 g 2a) and the closest fluid
                     pair / dp (tensile clumping pairs particles up).
  violent_impact     the dam break in a tank 2a long (the surge hits the wall at T ~ 2), to T = 8:
                     highest wall-region pressure / (rho0 g 2a).
  steep_wave         a stream-function wave at 85 % of the Miche breaking height in the open flume.
  window_N           flume case V with a coupling window of N SPH steps (N = 1, 10, 100, 1000):
                     RMSE/H against the theory (the explicit staggered scheme of seed 001 holds
                     the boundary data linear over a window).
  still_water_3d     a 3D box 0.6 x 0.3 m of still water d = 0.3 m (dim = 3, h/dp 1.5) for
                     20 / 60 sqrt(d/g): largest speed, level drift at mid-tank.
  violent_impact_3d  the 3D dam break against the tall structure (wavesph.cases.tall_structure)
                     to 1 s, dp 0.04 / 0.02: the column's peak force against the measurement's.
  (A method the 3D step does not have, e.g. Riemann SPH or shifting, ends ``failed`` there with
  the scene's one-line refusal as the reason.)
"""

from __future__ import annotations

import math
import time
import traceback
from pathlib import Path
from typing import Any, Callable

import numpy as np

from wave_client import G

from .sweeps import METHODS, Point, run_sweep, warm_up_method, write_table

STATUSES = ("stable", "noisy", "unstable", "failed")
STATUS_COLOURS = {"stable": "#4caf50", "noisy": "#ffb300", "unstable": "#e53935", "failed": "#757575"}
STABILITY_COLUMNS = ["scenario", "method", "status", "t_fail", "reason", "measure", "value", "bound",
               "t_end", "wall_s"]
WINDOW_STEPS = (1, 10, 100, 1000)


def unchecked(scene: Any, **constants: Any) -> Any:
    """``scene`` with constants set WITHOUT validation: the suite's one way past the scene's
    limits (cfl <= 0.5). Pydantic's model_copy(update=...) does not validate."""
    return scene.model_copy(update={"constants": scene.constants.model_copy(update=constants)})


def stability_points(quick: bool = False, methods: list[str] | None = None) -> list[Point]:
    methods = methods or (["wcsph_kdk", "wcsph_symplectic"] if quick else list(METHODS))
    scen = (["still_water", "shallow_water", "no_diffusion", "cfl_1.5", "low_c0", "tensile",
             "violent_impact", "steep_wave"] + [f"window_{n}" for n in WINDOW_STEPS]
            + ["still_water_3d", "violent_impact_3d"])
    return [Point(f"stability_{s}", m, 0.0, {"quick": quick}) for s in scen for m in methods]


# ---------------------------------------------------------------------------- runs
def _advance(sim: Any, t_end: float) -> tuple[str, float | None, str]:
    from sph_core.simulation import UnstableError

    try:
        sim.advance_to(t_end)
    except UnstableError as exc:
        return "unstable", exc.t, exc.cause
    return "completed", None, ""


def _still_tank(dp: float, t_end: float, scheme: dict | None = None, d: float = 0.3,
                **constants: Any) -> Any:
    from sph_core.scene import make_scene

    return make_scene({
        "name": "still_water", "dp": dp, "t_end": t_end, "still_water_level": d,
        "tank": {"x0": 0.0, "x1": 1.0, "z0": 0.0, "z1": d + 0.1},
        "water_blocks": [{"x0": 0.0, "x1": 1.0, "z0": 0.0, "z1": d}],
        "constants": constants, "output": {"probe_every": 0.05}, "scheme": scheme or {},
        "probes": [{"kind": "elevation", "name": "mid", "x": 0.5}]})


def _still_water(consts: dict, quick: bool) -> dict[str, Any]:
    from sph_core.simulation import Simulation

    d, dp = 0.3, 0.03 if quick else 0.02
    t_end = (40.0 if quick else 200.0) * math.sqrt(d / G)
    sim = Simulation(_still_tank(dp, t_end, **consts))
    status, t_fail, reason = _advance(sim, t_end)
    eta = np.array([r["mid_eta"] for r in sim.history if r["mid_eta"] is not None])
    v = np.hypot(*[sim.fluid_state()[k] for k in ("vx", "vz")])
    half = eta[eta.size // 2:] if eta.size > 4 else eta
    measures = {"level_drift_over_dp": (abs(float(np.mean(eta[-5:]) - np.mean(eta[:5]))) / dp
                                        if eta.size >= 10 else None, 0.5),
                "surface_noise_over_dp": (float(np.std(half)) / dp if half.size else None, 0.1),
                "max_speed_over_sqrt_gd": (float(v.max()) / math.sqrt(G * d), 0.02)}
    return _verdict(sim, status, t_fail, reason, t_end, measures)


def _shallow_water(consts: dict, quick: bool) -> dict[str, Any]:
    from sph_core.simulation import Simulation

    dp = 0.02 if quick else 0.01
    d, t_end = 5 * dp, 3.0 if quick else 5.0
    # the c0 of the 0.3 m tank: a beach's shallows step under the c0 of its deepest water
    c0 = consts.get("c0_factor", 10.0) * math.sqrt(2.0 * G * 0.3)
    sim = Simulation(_still_tank(dp, t_end, d=d, **{"c0": c0, **consts}))
    status, t_fail, reason = _advance(sim, t_end)
    v = np.hypot(*[sim.fluid_state()[k] for k in ("vx", "vz")])
    return _verdict(sim, status, t_fail, reason, t_end,
                    {"max_speed_over_sqrt_gd": (float(v.max()) / math.sqrt(G * d), 0.02)})


def _no_diffusion(consts: dict, quick: bool) -> dict[str, Any]:
    from sph_core.simulation import Simulation

    d, dp = 0.3, 0.03 if quick else 0.02
    t_end = 3.0 if quick else 10.0
    sim = Simulation(_still_tank(dp, t_end, **{**consts, "delta": 0.0}))
    status, t_fail, reason = _advance(sim, t_end)
    f = sim.fluid_state()
    dev = (f["p"] - 1000.0 * G * (d - f["z"])) / (1000.0 * G * d)
    return _verdict(sim, status, t_fail, reason, t_end,
                    {"pressure_noise": (float(np.std(dev)), 0.05)})


def _dambreak(consts: dict, quick: bool, t_star: float = 3.0, length: float | None = None,
              override: dict | None = None) -> tuple[Any, str, float | None, str, float, float]:
    from sph_core.simulation import Simulation

    from ..cases.dambreak import dambreak_scene

    a = 0.25
    dp = a / (5 if quick else 10)
    t_end = t_star * math.sqrt(a / (2 * G))
    scene = dambreak_scene(a=a, dp=dp, t_end=t_end, tank_length=length, **consts)
    if override:
        scene = unchecked(scene, **override)
    sim = Simulation(scene)
    status, t_fail, reason = _advance(sim, t_end)
    return sim, status, t_fail, reason, t_end, a


def _cfl(consts: dict, quick: bool) -> dict[str, Any]:
    sim, status, t_fail, reason, t_end, a = _dambreak(consts, quick, override={"cfl": 1.5})
    return _verdict(sim, status, t_fail, reason, t_end, _density_measure(sim))


def _low_c0(consts: dict, quick: bool) -> dict[str, Any]:
    sim, status, t_fail, reason, t_end, a = _dambreak({**consts, "c0_factor": 1.0}, quick)
    m = _density_measure(sim)
    m["mach"] = (sim.v_max / sim.c0, 0.1)
    return _verdict(sim, status, t_fail, reason, t_end, m)


def _density_measure(sim: Any) -> dict[str, tuple[float | None, float]]:
    f = sim.fluid_state()
    return {"max_density_error": (float(np.max(np.abs(f["rho"] / 1000.0 - 1.0))), 0.05)}


def _tensile(consts: dict, quick: bool) -> dict[str, Any]:
    from scipy.spatial import cKDTree

    sim, status, t_fail, reason, t_end, a = _dambreak({**consts, "alpha": 0.0, "delta": 0.0},
                                                       quick, t_star=6.0, length=2.5 * 0.25)
    f = sim.fluid_state()
    pts = np.column_stack([f["x"], f["z"]])
    dist = cKDTree(pts).query(pts, k=2)[0][:, 1] if len(pts) > 1 else np.array([sim.scene.dp])
    return _verdict(sim, status, t_fail, reason, t_end, {
        "min_pair_distance_over_dp": (float(dist.min()) / sim.scene.dp, 0.5, "min"),
        "min_pressure_over_rho_g_2a": (float(f["p"].min()) / (1000.0 * G * 2 * a), -0.5, "min")})


def _violent(consts: dict, quick: bool) -> dict[str, Any]:
    sim, status, t_fail, reason, t_end, a = _dambreak(consts, quick, t_star=8.0, length=2 * 0.25)
    f = sim.fluid_state()
    m = _density_measure(sim)
    m["max_pressure_over_rho_g_2a"] = (float(f["p"].max()) / (1000.0 * G * 2 * a), 5.0)
    return _verdict(sim, status, t_fail, reason, t_end, m)


def _flume_run(consts: dict, *, theory: str, height: float, period: float, depth: float,
               dp: float, periods: float, window_steps: int | None = None,
               opts: dict | None = None) -> dict[str, Any]:
    """A flume case; window: ``window_steps`` SPH steps of the initial dt (else T/50)."""
    from wave_client.theories import build_theory

    from ..cases.wave_flume import flume_case

    ramp = period
    model = build_theory(theory, height=height, period=period, depth=depth, ramp_time=ramp,
                         **(opts or {}))
    per_period = 50
    if window_steps is not None:
        c0 = 10.0 * math.sqrt(G * depth)
        h = consts["h_over_dp"] * dp          # every METHODS entry names it
        dt0 = consts.get("cfl", 0.25) * h / c0          # the adaptive step's bound at rest
        per_period = max(1, round(period / (window_steps * dt0)))
    tic = time.perf_counter()
    res = flume_case(model, height=height, period=period, depth=depth,
                     wavelength=float(model.length), dp=dp, periods=periods, ramp=ramp,
                     window_per_period=per_period, name="stability_flume", **consts)
    res["wall_total_s"] = time.perf_counter() - tic
    res["window_s"] = period / per_period
    return res


def _flume_verdict(res: dict[str, Any], t_end: float, bound: float) -> dict[str, Any]:
    err = res["rmse_over_H"]
    ok = err is not None and math.isfinite(err)
    status = "stable" if ok and err <= bound else "noisy"
    reason = "" if status == "stable" else (
        f"rmse_over_H = {err:.3g} > {bound}" if ok else "rmse_over_H not finite")
    return {"status": status, "t_fail": None, "reason": reason, "measure": "rmse_over_H",
            "value": err if ok else None, "bound": bound, "t_end": t_end, "wall_s": res["wall_s"],
            "extra": {"window_s": res["window_s"], "steps": res["steps"],
                      "particles": res["particles"]}}


def _steep(consts: dict, quick: bool) -> dict[str, Any]:
    from wave_client.theories import wavenumber

    d, T = 0.3, 1.5
    k = float(wavenumber(2 * math.pi / T, d))
    L = 2 * math.pi / k
    H = round(0.85 * 0.142 * L * math.tanh(k * d), 4)   # Miche's limit, 85 %
    dp = H / (3 if quick else 6)
    res = _flume_run(consts, theory="stream", height=H, period=T, depth=d, dp=dp,
                     periods=1.0 if quick else 3.0, opts={"n_fourier": 24})
    return _flume_verdict(res, res["T"] * (res["periods"] + 2), 0.15)


def _window(steps: int) -> Callable[[dict, bool], dict[str, Any]]:
    def run(consts: dict, quick: bool) -> dict[str, Any]:
        res = _flume_run(consts, theory="stream", height=0.06, period=2.0, depth=0.3,
                         dp=0.03 if quick else 0.015, periods=1.0 if quick else 3.0,
                         window_steps=steps, opts={"n_fourier": 16})
        return _flume_verdict(res, None, 0.10)  # type: ignore[arg-type]
    return run


def _verdict(sim: Any, status: str, t_fail: float | None, reason: str, t_end: float,
             measures: dict[str, tuple]) -> dict[str, Any]:
    """Status from the run and its measures: the first measure past its bound makes a completed
    run ``noisy`` (bounds are upper unless the tuple's third item says "min")."""
    first = next(iter(measures.items()))
    name, (value, bound, *kind) = first
    out = {"status": "stable", "t_fail": t_fail, "reason": reason, "measure": name,
           "value": value, "bound": bound, "t_end": t_end, "wall_s": sim.wall_time,
           "extra": {k: v[0] for k, v in measures.items()}}
    if status == "unstable":
        out["status"] = "unstable"
        return out
    for name, (value, bound, *kind) in measures.items():
        lower = bool(kind) and kind[0] == "min"
        bad = value is None or not math.isfinite(value) or (value < bound if lower else value > bound)
        if bad:
            out.update(status="noisy", measure=name, value=value, bound=bound,
                       reason=f"{name} = {value:.3g} {'<' if lower else '>'} {bound}"
                       if value is not None and math.isfinite(value) else f"{name} not finite")
            break
    return out


def _still_water_3d(consts: dict, quick: bool) -> dict[str, Any]:
    from sph_core.scene import make_scene
    from sph_core.simulation import Simulation

    d, dp = 0.3, 0.05 if quick else 0.03
    t_end = (20.0 if quick else 60.0) * math.sqrt(d / G)
    scheme = consts.pop("scheme", {})
    sim = Simulation(make_scene({
        "name": "still_water_3d", "dim": 3, "dp": dp, "t_end": t_end, "still_water_level": d,
        "tank": {"x0": 0.0, "x1": 0.6, "y0": 0.0, "y1": 0.3, "z0": 0.0, "z1": d + 0.1},
        "water_blocks": [{"x0": 0.0, "x1": 0.6, "z0": 0.0, "z1": d}],
        "constants": {**consts, "h_over_dp": 1.5}, "scheme": scheme,
        "output": {"probe_every": 0.05},
        "probes": [{"kind": "elevation", "name": "mid", "x": 0.3, "y": 0.15}]}))
    status, t_fail, reason = _advance(sim, t_end)
    eta = np.array([r["mid_eta"] for r in sim.history if r["mid_eta"] is not None])
    f = sim.fluid_state()
    v = np.sqrt(f["vx"] ** 2 + f["vy"] ** 2 + f["vz"] ** 2)
    return _verdict(sim, status, t_fail, reason, t_end, {
        "max_speed_over_sqrt_gd": (float(v.max()) / math.sqrt(G * d), 0.02),
        "level_drift_over_dp": (abs(float(np.mean(eta[-3:]) - np.mean(eta[:3]))) / dp
                                if eta.size >= 6 else None, 0.5)})


def _violent_3d(consts: dict, quick: bool) -> dict[str, Any]:
    from sph_core.simulation import Simulation

    from ..cases.tall_structure import TALL_H_OVER_DP, force_errors, tall_structure_scene

    t_end = 1.0
    consts = {**consts, "h_over_dp": TALL_H_OVER_DP}
    sim = Simulation(tall_structure_scene(dp=0.04 if quick else 0.02, t_end=t_end, **consts))
    status, t_fail, reason = _advance(sim, t_end)
    t = np.array([r["t"] for r in sim.history])
    fx = np.array([r["column_fx"] for r in sim.history])
    err = force_errors(t, fx, 0.0, t_end) if t.size > 2 else {"peak_force_error": None}
    e = err["peak_force_error"]
    return _verdict(sim, status, t_fail, reason, t_end, {
        "abs_peak_force_error": (abs(e) if e is not None else None, 0.5), **_density_measure(sim)})


SCENARIOS: dict[str, Callable[[dict, bool], dict[str, Any]]] = {
    "still_water": _still_water, "shallow_water": _shallow_water, "no_diffusion": _no_diffusion,
    "cfl_1.5": _cfl,
    "low_c0": _low_c0, "tensile": _tensile, "violent_impact": _violent, "steep_wave": _steep,
    **{f"window_{n}": _window(n) for n in WINDOW_STEPS},
    "still_water_3d": _still_water_3d, "violent_impact_3d": _violent_3d}


def run_scenario(point: Point) -> dict[str, Any]:
    """One scenario x method (dask task); never raises, every number finite."""
    from .sweeps import _threads

    _threads(1)
    scenario = point.case.removeprefix("stability_")
    rec: dict[str, Any] = {"key": point.key, "case": point.case, "scenario": scenario,
                           "method": point.method, "dp": point.dp, "options": point.options}
    try:
        warm_up_method(point.method)
        rec.update(SCENARIOS[scenario](dict(METHODS[point.method]),
                                       bool(point.options.get("quick"))))
    except Exception as exc:
        rec.update(status="failed", reason=f"{type(exc).__name__}: {exc}",
                   traceback=traceback.format_exc(limit=5))
    for k in ("t_fail", "value", "wall_s", "t_end"):
        v = rec.get(k)
        if v is not None and not math.isfinite(v):
            rec[k] = None
    assert_finite(rec)
    return rec


def assert_finite(obj: Any) -> None:
    """No NaN or inf anywhere in a record (nested dicts and lists included)."""
    if isinstance(obj, float):
        assert math.isfinite(obj), "non-finite number in a stability record"
    elif isinstance(obj, dict):
        for k, v in obj.items():
            if k == "extra" and isinstance(v, dict):   # measures: NaN becomes None
                for kk, vv in v.items():
                    if isinstance(vv, float) and not math.isfinite(vv):
                        v[kk] = None
            assert_finite(v)
    elif isinstance(obj, (list, tuple)):
        for v in obj:
            assert_finite(v)


def run_stability(points: list[Point], out: Path, **kw: Any) -> list[dict[str, Any]]:
    """The points on dask (wavesph.studies.sweeps.run_sweep: store, resume, progress bar)."""
    rows = run_sweep(points, out, runner=run_scenario, desc="stability", **kw)
    for r in rows:   # a record made client-side for a dead worker has no scenario field
        r.setdefault("scenario", r["case"].removeprefix("stability_"))
    return rows


def write_stability_csv(rows: list[dict[str, Any]], path: Path, command: str = "") -> None:
    write_table(rows, path, STABILITY_COLUMNS,
                {k: ".4g" for k in ("t_fail", "value", "t_end", "wall_s")}, command)


def plot_stability(rows: list[dict[str, Any]], path: Path, title: str = "") -> None:
    """method x scenario grid coloured by status, each cell with its measure's value."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Patch

    scen = list(dict.fromkeys(r["scenario"] for r in rows))
    meth = list(dict.fromkeys(r["method"] for r in rows))
    fig, ax = plt.subplots(figsize=(1.1 * len(scen) + 2.5, 0.6 * len(meth) + 2.2))
    for r in rows:
        i, j = meth.index(r["method"]), scen.index(r["scenario"])
        ax.add_patch(plt.Rectangle((j, i), 1, 1, color=STATUS_COLOURS.get(r["status"], "white"),
                                   ec="white"))
        v = r.get("value")
        txt = r["status"] if v is None else f"{v:.2g}"
        if r["status"] == "unstable" and r.get("t_fail") is not None:
            txt = f"t={r['t_fail']:.2g}s"
        ax.text(j + 0.5, i + 0.5, txt, ha="center", va="center", fontsize=7)
    ax.set_xlim(0, len(scen))
    ax.set_ylim(0, len(meth))
    ax.set_xticks(np.arange(len(scen)) + 0.5, scen, rotation=40, ha="right", fontsize=8)
    ax.set_yticks(np.arange(len(meth)) + 0.5, meth, fontsize=8)
    ax.legend(handles=[Patch(color=c, label=s) for s, c in STATUS_COLOURS.items()],
              loc="upper left", bbox_to_anchor=(1.01, 1), fontsize=7)
    ax.set_title(title or "stability: status (cell: the measure's value, or the failure time)",
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
