"""What does each SPH scheme cost, and what does it get right, on the same scenes?

    python bench/schemes.py [--quick] [--only NAME ...] [--no-wave]

Every entry of ENTRIES (a name and its scene overrides: the [scheme] table and constants) runs
three scenes, all built by the cases' builders with ``scheme=`` (sph_core.scene.Scheme):

- still water (depth D = 0.25 m, tank 2D, 20 sqrt(D/g); quick: 10): pressure one dp above the
  bed at mid-tank over the second half: ``bed_p_error`` (mean / rho0 g (D - z) - 1) and
  ``bed_p_noise_pa`` (its standard deviation);
- Martin & Moyce's dam break (column a x 2a, a = 0.1 m, tank 4a, to T = t sqrt(2g/a) = 6; a/dp 20,
  quick 10): ``front_error`` (RMS relative error of the surge front for T <= 3, as
  wavesph.studies.sweeps), ``wall_pressure_noise_pa``: the standard deviation of the high-passed pressure
  on the right wall at z = 0.2a (impact and after; the signal minus its centred moving average
  over 0.1 sqrt(a/g), sampled every 0.01 sqrt(a/g)), ``left_wall_pressure_noise_pa`` likewise
  at the column's wall (no impact: the collapse's smooth decay plus noise), ``impact_p_max_pa``;
  the speed figures ``particle_steps_per_s``, ``wall_s_per_sim_s``, ``dt_mean_s`` come from this
  run (the jitted loop only; compiled beforehand);
- wave decay (bench/wave_decay.py's flume, H 0.04 m, T 1.4 s, d 0.24 m; H/dp 4, quick 2):
  ``loss_per_wavelength`` (1 - exp(-decay L)).

Prints one JSON object per entry. Wall times on a shared machine are "under load" unless said.
ISPH joins as more entries: ``(name, {"scheme": {...}, "constants": {...}})``.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from pathlib import Path
from typing import Any

os.environ.setdefault("OMP_WAIT_POLICY", "passive")  # before numba: shared, loaded cores
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402

from wavesph.cases.dambreak import dambreak_scene, front_errors  # noqa: E402
from wavesph.cases.schemes import RIEMANN_VARIANTS  # noqa: E402
from wavesph.studies.sweeps import OLD_DEFAULTS  # noqa: E402

# h/dp 2 without artificial viscosity against walls: the wave-decay study's best WCSPH options
# (docs/studies/wave_decay_study.md); every entry but the first uses them, so the schemes differ only in
# the scheme
BEST_WAVE = {"h_over_dp": 2.0, "alpha_wall_factor": 0.0}
ENTRIES: list[tuple[str, dict[str, Any]]] = [
    ("wcsph_hsqrt2_wallav1", {"constants": OLD_DEFAULTS}),  # the defaults before this session
    ("wcsph", {"constants": BEST_WAVE}),                   # = today's scene defaults
    *[(name, {"scheme": sch, "constants": BEST_WAVE}) for name, sch in RIEMANN_VARIANTS.items()],
    # ISPH runs at its own h/dp sqrt 2 (sph_core.scene.ISPH_H_OVER_DP); its wave flume is
    # unstable (docs/studies/schemes.md "ISPH with open ends and bodies"), so its wave line reports
    # wave_failed with the UnstableError
    ("isph_bicgstab", {"scheme": {"kind": "isph", "ppe_solver": "bicgstab"}}),  # the default
    ("isph_amg", {"scheme": {"kind": "isph", "ppe_solver": "amg"}}),
]

_G = 9.81
RHO0 = 1000.0


def high_passed_std(t: np.ndarray, p: np.ndarray, window: float) -> float:
    """Standard deviation of p minus its centred moving average over ``window`` [s] (uniform
    samples t); NaN with fewer than 3 windows of signal."""
    if p.size < 3:
        return float("nan")
    k = max(int(round(window / (t[1] - t[0]))), 1) | 1          # odd
    if p.size < 3 * k:
        return float("nan")
    smooth = np.convolve(p, np.ones(k) / k, mode="valid")
    h = k // 2
    return float(np.std(p[h: h + smooth.size] - smooth))


def still_water(overrides: dict[str, Any], quick: bool) -> dict[str, Any]:
    from sph_core.scene import make_scene
    from sph_core.simulation import Simulation

    d = 0.25
    dp = d / (10 if quick else 25)
    t_end = (10.0 if quick else 20.0) * math.sqrt(d / _G)
    z = dp
    scene = make_scene({
        "name": "still", "dp": dp, "t_end": t_end, "still_water_level": d,
        "tank": {"x0": 0.0, "x1": 2 * d, "z0": 0.0, "z1": 1.6 * d},
        "water_blocks": [{"x0": 0.0, "x1": 2 * d, "z0": 0.0, "z1": d}],
        "constants": overrides.get("constants", {}), "scheme": overrides.get("scheme", {}),
        "output": {"probe_every": 0.01},
        "probes": [{"kind": "point", "name": "bed", "x": d, "z": z}]})
    sim = Simulation(scene)
    sim.advance_to(t_end)
    p = np.array([r["bed_p"] for r in sim.history if r["t"] >= 0.5 * t_end])
    exact = RHO0 * _G * (d - z)
    st = sim.fluid_state()
    return {"still_dp": dp, "bed_p_error": round(float(p.mean() / exact - 1.0), 5),
            "bed_p_noise_pa": round(float(p.std()), 3),
            "still_v_max_m_s": round(float(np.hypot(st["vx"], st["vz"]).max()), 6)}


def dambreak(overrides: dict[str, Any], quick: bool) -> dict[str, Any]:
    from sph_core.simulation import Simulation

    a = 0.1
    dp = a / (10 if quick else 20)
    scale = math.sqrt(2 * _G / a)               # T = t scale
    t_end = 6.0 / scale
    every = 0.01 * math.sqrt(a / _G)
    zp = 0.2 * a
    scene = dambreak_scene(a=a, dp=dp, t_end=t_end, probe_every=every,
                           scheme=overrides.get("scheme"),
                           probes=[{"kind": "pressure_line", "name": "right", "points": [(4 * a, zp)]},
                                   {"kind": "pressure_line", "name": "left", "points": [(0.0, zp)]}],
                           **overrides.get("constants", {}))
    sim = Simulation(scene)
    sim.advance_to(t_end)
    hist = sim.history
    t = np.array([r["t"] for r in hist])
    front = np.array([r["front_x"] if r["front_x"] is not None else np.nan for r in hist])
    ok = np.isfinite(front)
    fe = front_errors(t[ok], front[ok], a, t_max=3.0)

    def wall(name: str) -> np.ndarray:
        return np.array([r[f"{name}_p0"] if r[f"{name}_p0"] is not None else np.nan for r in hist])

    pr, pl = wall("right"), wall("left")
    wet = np.nonzero(np.isfinite(pr))[0]
    pr_wet = pr[wet[0]:] if wet.size else np.array([])
    pr_wet = np.nan_to_num(pr_wet)      # a dry sample after the impact: no pressure
    window = 0.1 * math.sqrt(a / _G)
    return {"dambreak_dp": dp, "a_over_dp": round(a / dp, 3),
            "front_error": round(fe["rms_rel_error"], 5),
            "front_max_error": round(fe["max_rel_error"], 5),
            "wall_pressure_noise_pa": round(high_passed_std(t[wet[0]:] if wet.size else t[:0],
                                                            pr_wet, window), 3),
            "left_wall_pressure_noise_pa": round(high_passed_std(t, np.nan_to_num(pl), window), 3),
            "impact_p_max_pa": round(float(np.nanmax(pr)) if wet.size else float("nan"), 1),
            "particles": sim.n_particles, "steps": sim.steps,
            "dt_mean_s": t_end / max(sim.steps, 1),
            "particle_steps_per_s": round(sim.n_particles * sim.steps / max(sim.wall_time, 1e-9)),
            "wall_s_per_sim_s": round(sim.wall_time / t_end, 2)}


def wave(overrides: dict[str, Any], quick: bool) -> dict[str, Any]:
    from wavesph.cases.wave_decay import amplitude_profile
    from wave_client.theories import build_theory

    height, period, depth = 0.04, 1.4, 0.24
    dp = height / (2.0 if quick else 4.0)
    model = build_theory("stokes", height=height, period=period, depth=depth, ramp_time=period,
                         order=2)
    cst = {**overrides.get("constants", {})}
    prof = amplitude_profile(model, ramp=period, height=height, period=period, depth=depth, dp=dp,
                             periods=2.0 if quick else 4.0, c0=10.0 * math.sqrt(_G * depth),
                             scheme=overrides.get("scheme"), **cst)
    length = float(model.length)
    return {"wave_dp": dp, "H_over_dp": round(height / dp, 3),
            "loss_per_wavelength": round(1.0 - math.exp(-prof.decay_per_m * length), 4),
            "wave_wall_s": round(prof.wall_s, 1)}


def _warm_up(overrides: dict[str, Any]) -> float:
    """Compile (or load) the step before the timed runs; returns its seconds."""
    from sph_core.simulation import Simulation

    tic = time.perf_counter()
    sim = Simulation(dambreak_scene(a=0.1, dp=0.05, t_end=0.01, scheme=overrides.get("scheme"),
                                    **overrides.get("constants", {})))
    sim.advance_to(0.005)
    return time.perf_counter() - tic


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="coarse: a/dp 10, D/dp 10, H/dp 2")
    ap.add_argument("--only", nargs="+", help=f"entries to run (of {[n for n, _ in ENTRIES]})")
    ap.add_argument("--no-wave", action="store_true", help="skip the wave-decay flume")
    a = ap.parse_args(argv)
    names = [n for n, _ in ENTRIES]
    unknown = set(a.only or []) - set(names)
    if unknown:
        ap.error(f"unknown entries {sorted(unknown)}; known: {names}")
    for name, ov in ENTRIES:
        if a.only and name not in a.only:
            continue
        rec: dict[str, Any] = {"scheme": ov.get("scheme", {}).get("kind", "wcsph"), "name": name,
                               "options": ov, "quick": a.quick,
                               "warmup_s": round(_warm_up(ov), 1)}
        rec["dp"] = None
        for part in (dambreak, still_water) + (() if a.no_wave else (wave,)):
            try:
                rec.update(part(ov, a.quick))
            except Exception as exc:   # an unstable scheme is a result, not the end of the bench
                rec[f"{part.__name__}_failed"] = f"{type(exc).__name__}: {exc}"
        rec["dp"] = rec.get("dambreak_dp")
        print(json.dumps(rec, default=float), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
