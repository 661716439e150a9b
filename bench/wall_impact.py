"""Violent impact on a wall: do the walls hold, and how does the near-bed wall pressure compare
with the experiment?

Case: Lobovsky et al. (2014), H = 300 mm dam break (wavesph/cases/wall_impact.py): column 0.6 x 0.3 m,
tank 1.61 m, sensor 1 on the far wall 3 mm above the bed, measured at 20 kHz (one realisation,
tests/data/lobovsky_2014_h300_sensor1.csv). The sensors are sampled after every time step and
resampled at the experiment's 20 kHz.

Prints one JSON object:
- walls: ``excluded`` (fluid particles removed: through a wall, over the top, density band),
  each with where and why (the first 5), and ``status``;
- sensor 1: the first impact's peak [Pa] and its time, for the experiment and for SPH sampled
  two ways (``Sensors``: the fluid's pressure interpolated at the wall face, and the wall
  particles' own pressure), each raw and after a centred moving average of
  ``--average-ms`` (the experiment's trace too); ``arrival`` = first time p > 0.1 rho g H;
  ``dry_ms_first_100ms``: how long the fluid probe saw no fluid in the 0.1 s after arrival;
  ``mean_5_50ms_pa``: the mean load 5-50 ms after arrival (after the spike; dry counts as 0);
  ``noise_rms``: RMS of (raw - the 1 ms moving average) over the 0.25 s after arrival;
  ``sensor1_*_windows``: SPH / experiment ratios of the peak after 1-10 ms moving averages and
  of the impulse over 5-50 ms after arrival (docs/studies/wall_pressure.md, 2026-11-23);
- cost: steps, wall time (say whether the machine was loaded), particle-steps/s.

    python bench/wall_impact.py --dp 0.004 --t-end 2.0 [--h-over-dp 2] [--c0-factor 10]
                                [--alpha 0.1] [--delta 0.1] [--trace runs/wall_impact.npz]
                                [--figure docs/figures/wall_pressure.png]
    python bench/wall_impact.py --replot runs/wall_impact.npz --figure out.png --dp 0.004
"""

from __future__ import annotations

import argparse
import json
import sys
import time

import numba
import numpy as np

from wavesph.cases.wall_impact import COLUMN_HEIGHT, SENSOR_Z, lobovsky_scene, lobovsky_sensor1
from sph_core.particles import P, WALL, X, Z
from sph_core.probes import interpolate_points
from sph_core.simulation import Simulation, UnstableError

RHO_G_H = 1000.0 * 9.81 * COLUMN_HEIGHT


def moving_average(t: np.ndarray, p: np.ndarray, width: float) -> np.ndarray:
    """Centred moving average over ``width`` [s] of a uniformly sampled series (NaN as 0)."""
    if width <= 0:
        return p.copy()
    k = max(1, int(round(width / np.median(np.diff(t)))))
    q = np.nan_to_num(p)
    return np.convolve(q, np.ones(k) / k, mode="same")


def impact_figures(t: np.ndarray, p: np.ndarray, average: float) -> dict:
    """Arrival, first peak (raw and averaged) and high-passed noise of a sensor trace."""
    q = np.nan_to_num(p)
    above = np.nonzero(q > 0.1 * RHO_G_H)[0]
    if above.size == 0:
        return {"arrival_s": None}
    t_arr = t[above[0]]
    # first impact: the 0.1 s after arrival (the run-up and the plunging jet come later)
    win = (t >= t_arr) & (t <= t_arr + 0.1)
    k = np.nonzero(win)[0][np.argmax(q[win])]
    avg = moving_average(t, q, average)
    ka = np.nonzero(win)[0][np.argmax(avg[win])]
    hp = q - moving_average(t, q, 1e-3)
    nwin = (t >= t_arr) & (t <= t_arr + 0.25)
    # a dry sensor after the arrival: the fluid has left the corner (the experiment's never is)
    dry = float(np.isnan(p[win]).sum() * np.median(np.diff(t)))
    return {"arrival_s": round(float(t_arr), 5), "dry_ms_first_100ms": round(1e3 * dry, 2),
            "peak_pa": round(float(q[k]), 1), "peak_t_s": round(float(t[k]), 5),
            "peak_avg_pa": round(float(avg[ka]), 1), "peak_avg_t_s": round(float(t[ka]), 5),
            "noise_rms_pa": round(float(np.sqrt(np.mean(hp[nwin] ** 2))), 1),
            "mean_5_50ms_pa": round(float(np.mean(q[(t >= t_arr + 0.005) & (t <= t_arr + 0.05)])), 1)}


def window_and_impulse(t: np.ndarray, p: np.ndarray, te: np.ndarray, pe: np.ndarray) -> dict:
    """SPH / experiment ratios of sensor 1's first peak after centred moving averages of 1, 2,
    5 and 10 ms (the SPH spike rings with a period ~4 d/c0; the experiment's event is a 2 ms
    rise and a slow decay) and of the pressure impulse from arrival over 5, 10, 20, 50 ms."""
    def impulse(tt: np.ndarray, pp: np.ndarray, span: float) -> float:
        ta = impact_figures(tt, pp, 0.0)["arrival_s"]
        sel = (tt >= ta) & (tt <= ta + span)
        return float(np.trapezoid(np.nan_to_num(pp[sel]), tt[sel]))
    if impact_figures(t, p, 0.0).get("arrival_s") is None:
        return {}
    return {"peak_ratio_window_ms": {f"{1e3 * w:g}": round(impact_figures(t, p, w)["peak_avg_pa"]
                                                          / impact_figures(te, pe, w)["peak_avg_pa"], 3)
                                     for w in (1e-3, 2e-3, 5e-3, 10e-3)},
            "impulse_ratio_ms": {f"{1e3 * w:g}": round(impulse(t, p, w) / impulse(te, pe, w), 3)
                                 for w in (5e-3, 10e-3, 20e-3, 50e-3)}}


class Sensors:
    """The sensors' pressure after every step, sampled two ways: ``probe`` = the fluid's
    Shepard-interpolated pressure at the wall face (as the scene's pressure_line probe), ``wall``
    = the Adami pressure of the first column of wall particles behind the far wall, linear in z
    at the sensor heights (the wall particles' own pressure)."""

    def __init__(self, sim: Simulation) -> None:
        tank, dp = sim.scene.tank, sim.scene.dp
        self.x_col = tank.x1 + 0.5 * dp
        self.dp = dp
        self.z = np.array(SENSOR_Z)
        self.x = np.full(self.z.size, tank.x1)
        self.out = np.zeros((self.z.size, 4))
        self.t: list[float] = []
        self.probe: list[np.ndarray] = []
        self.wall: list[np.ndarray] = []
        self.u: list[float] = []   # the fluid's horizontal velocity at sensor 1

    def sample(self, sim: Simulation) -> None:
        ps = sim.particles
        interpolate_points(ps.view, sim.cells, self.x, np.zeros_like(self.x), self.z, sim.h,
                           sim.prm.alpha_w, self.out)
        self.probe.append(np.where(self.out[:, 3] > 0.05, self.out[:, 2], np.nan))
        self.u.append(self.out[0, 0] if self.out[0, 3] > 0.05 else np.nan)
        n = ps.n
        x, z = ps.f[X, :n], ps.f[Z, :n]
        sel = (ps.kind[:n] == WALL) & (np.abs(x - self.x_col) < 0.25 * self.dp) & (z < 0.12)
        order = np.argsort(z[sel])
        self.wall.append(np.interp(self.z, z[sel][order], ps.f[P, :n][sel][order]))
        self.t.append(sim.t)

    def series(self, rate: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(t, probe, wall) resampled linearly onto a uniform grid at ``rate`` [Hz]."""
        t = np.array(self.t)
        tu = np.arange(t[0], t[-1], 1.0 / rate)
        probe, wall = np.array(self.probe), np.array(self.wall)
        pu = np.column_stack([np.interp(tu, t, probe[:, k]) for k in range(self.z.size)])
        wu = np.column_stack([np.interp(tu, t, wall[:, k]) for k in range(self.z.size)])
        return tu, pu, wu


def plot_sensor1(t: np.ndarray, probe: np.ndarray, wall: np.ndarray, average: float, label: str,
                 path: str) -> None:
    """Sensor 1: the experiment and SPH (fluid probe, wall particles), raw and averaged, each
    against the time since its own arrival (the arrival times are in the JSON)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    te, pe = lobovsky_sensor1()
    fig, ax = plt.subplots(figsize=(9, 4.5))
    for tt, pp, name, style in ((te, pe, "experiment (Lobovsky et al. 2014)", "k-"),
                                (t, probe[:, 0], f"SPH fluid probe at the wall, {label}", "C0-"),
                                (t, wall[:, 0], f"SPH wall particles, {label}", "C1-")):
        f = impact_figures(tt, pp, average)
        if f.get("arrival_s") is None:
            continue
        ms = 1e3 * (tt - f["arrival_s"])
        ax.plot(ms, np.nan_to_num(pp) / RHO_G_H, style, lw=0.6, alpha=0.5)
        ax.plot(ms, moving_average(tt, pp, average) / RHO_G_H, style, lw=1.6,
                label=f"{name} (arrival {f['arrival_s']:.3f} s)")
    ax.set(xlim=(-5, 60), xlabel="time since arrival [ms]", ylabel="p / (rho g H)",
           title=f"far wall, 3 mm above the bed (thin: raw; thick: {1e3 * average:g} ms average)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dp", type=float, default=0.004)
    ap.add_argument("--t-end", type=float, default=2.0)
    ap.add_argument("--h-over-dp", type=float, default=None)
    ap.add_argument("--c0-factor", type=float, default=None)
    ap.add_argument("--alpha", type=float, default=None)
    ap.add_argument("--delta", type=float, default=None)
    ap.add_argument("--wall-height", type=float, default=None,
                    help="[m] model walls (default wavesph.cases.wall_impact.WALL_HEIGHT; "
                         "the tank: 0.6)")
    ap.add_argument("--alpha-wall", type=float, default=None, help="alpha_wall_factor")
    ap.add_argument("--wall-slip", choices=["no_slip", "free_slip"], default=None)
    ap.add_argument("--integrator", choices=["kdk", "symplectic_pc"], default=None)
    ap.add_argument("--rate", type=float, default=20e3, help="[Hz] resampling of the per-step sensor series "
                    "(20 kHz: the experiment's)")
    ap.add_argument("--average-ms", type=float, default=1.0, help="moving-average width for the peaks")
    ap.add_argument("--trace", default=None, help="write t, probe and wall pressures to this .npz")
    ap.add_argument("--figure", default=None, help="plot sensor 1 against the experiment (.png)")
    ap.add_argument("--replot", default=None, help="no run: plot --figure from this --trace file")
    args = ap.parse_args()
    avg = 1e-3 * args.average_ms
    if args.replot:
        d = np.load(args.replot)
        plot_sensor1(d["t"], d["probe"], d["wall"], avg, f"dp {args.dp:g}", args.figure)
        return
    consts = {k: v for k, v in (("h_over_dp", args.h_over_dp), ("c0_factor", args.c0_factor),
                                ("alpha", args.alpha), ("delta", args.delta),
                                ("alpha_wall_factor", args.alpha_wall),
                                ("wall_slip", args.wall_slip),
                                ("integrator", args.integrator)) if v is not None}
    # the bench samples the sensors itself after every step (no output cadence that would cut
    # the time steps to hit record times)
    if args.wall_height is not None:
        consts["wall_height"] = args.wall_height
    scene = lobovsky_scene(dp=args.dp, t_end=args.t_end, probe_every=0.0, **consts)
    t0 = time.perf_counter()
    sim = Simulation(scene)
    sensors = Sensors(sim)
    sensors.sample(sim)
    status, cause = "completed", None
    last = time.perf_counter()
    try:
        while sim.t < args.t_end:
            sim.advance_steps(1)
            sensors.sample(sim)
            if time.perf_counter() - last > 30.0:  # a line for long runs (stderr, not the JSON)
                last = time.perf_counter()
                print(f"t = {sim.t:.4f} s, steps {sim.steps}, excluded {len(sim.excluded)}",
                      file=sys.stderr, flush=True)
    except UnstableError as exc:
        status, cause = "unstable", str(exc)
    wall_s = time.perf_counter() - t0
    t, probe, wall = sensors.series(args.rate)
    # the impact speed: the fluid's largest u at sensor 1 before its first peak
    ts, us = np.array(sensors.t), np.array(sensors.u)
    te, pe = lobovsky_sensor1()
    out = {"bench": "wall_impact", "case": "lobovsky_2014_h300", "dp": args.dp, "t_end": args.t_end,
           "wall_height": scene.tank.z1,
           "h_over_dp": scene.constants.h_over_dp, "c0": round(sim.c0, 3),
           "alpha": scene.constants.alpha, "delta": scene.constants.delta,
           "alpha_wall_factor": scene.constants.alpha_wall_factor,
           "wall_slip": scene.constants.wall_slip,
           "integrator": scene.constants.integrator, "status": status,
           "t": round(sim.t, 5), "excluded": len(sim.excluded),
           "excluded_first": [{k: (round(v, 5) if isinstance(v, float) else v) for k, v in e.items()}
                              for e in sim.excluded[:5]],
           "fluid_particles": sim.n_fluid, "particles": sim.n_particles, "steps": sim.steps,
           "wall_s": round(wall_s, 1), "step_wall_s": round(sim.wall_time, 1),
           "particle_steps_per_s": round(sim.n_particles * sim.steps / max(sim.wall_time, 1e-9)),
           "threads": numba.get_num_threads(), "average_ms": args.average_ms,
           "sensor1_experiment": impact_figures(te, pe, avg),
           "sensor1_probe": impact_figures(t, probe[:, 0], avg),
           "sensor1_wall": impact_figures(t, wall[:, 0], avg)}
    out["sensor1_probe_windows"] = window_and_impulse(t, probe[:, 0], te, pe)
    out["sensor1_wall_windows"] = window_and_impulse(t, wall[:, 0], te, pe)
    e, s = out["sensor1_experiment"], out["sensor1_probe"]
    if e.get("peak_pa") and s.get("peak_pa"):
        out["peak_ratio_probe"] = round(s["peak_pa"] / e["peak_pa"], 3)
        out["peak_avg_ratio_probe"] = round(s["peak_avg_pa"] / e["peak_avg_pa"], 3)
        out["arrival_lag_s"] = round(s["arrival_s"] - e["arrival_s"], 4)
    if s.get("peak_pa"):
        before = (ts >= s["arrival_s"] - 0.01) & (ts <= s["peak_t_s"])
        if np.isfinite(us[before]).any():
            u_imp = float(np.nanmax(us[before]))
            # a water-hammer bound rho c0 u against the incompressible stagnation rho u^2
            out["impact_u_m_s"] = round(u_imp, 3)
            out["rho_c0_u_pa"] = round(1000.0 * sim.c0 * u_imp, 1)
            out["rho_u2_pa"] = round(1000.0 * u_imp**2, 1)
    if cause:
        out["cause"] = cause
    if args.trace:
        np.savez(args.trace, t=t, probe=probe, wall=wall, sensor_z=np.array(SENSOR_Z))
    if args.figure:
        plot_sensor1(t, probe, wall, avg, f"dp {args.dp:g}", args.figure)
    print(json.dumps(out), flush=True)
    sys.exit(0 if status == "completed" and not sim.excluded else 1)


if __name__ == "__main__":
    main()
