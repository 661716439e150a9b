"""Where does the SPH wave's energy go? A standing wave in a closed tank, no open boundaries.

    python bench/standing_wave_decay.py [--dp 0.02] [--h-over-dp 2] [--alpha 0.01]
        [--slip no_slip|free_slip] [--delta 0.1] [--c0-factor 10] [--periods 6] [...]

The first sloshing mode of a tank half a wavelength long (walls at the antinodes), the wave of
bench/wave_decay.py (d 0.24, k = pi / L_tank, L_tank 1.0 m: T 1.42 s, kd 0.75), amplitude a
(default 0.02 m = H/2 of that bench), started at the phase of zero elevation from the linear
velocity field  u = -A k cosh(k(z - z_bed)) sin(kx),  w = A k sinh(k(z - z_bed)) cos(kx),
A = a g / (omega cosh(kd)), with hydrostatic pressure (exact at that phase).
Every T/40 the fluid velocity is projected on that mode (mass-weighted):
    c(t) = sum m u.U / sum m U.U     (c = 1 at the start)
    KE_wave = c^2 KE_0,   KE_noise = KE - KE of the projection on the first three modes
(modes n = 1, 2, 3: k_n = n pi / L_tank; the rest is particle-scale noise). c(t) is fitted by
exp(-beta t) cos(omega' t + phi): beta [1/s] is the wave's amplitude decay rate in time, and
beta / c_g [1/m] the decay over distance a progressive wave would have from the same losses
(c_g the linear group velocity) -- directly comparable with bench/wave_decay.py's decay_per_m,
without inlet, outlet or gauge. The elevation gauges near both walls (x = 0.1 m from each) give
a_gauge / a_velocity: the gauge's own bias against the velocity field's amplitude.
Prints one JSON line.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OMP_WAIT_POLICY", "passive")
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402
from scipy.optimize import curve_fit  # noqa: E402

from sph_core.particles import FLUID, M, VX, VZ, X, Z  # noqa: E402
from sph_core.scene import make_scene  # noqa: E402
from sph_core.simulation import Simulation  # noqa: E402
from sph_core.wave_analysis import group_velocity  # noqa: E402


def mode(x: np.ndarray, z: np.ndarray, k: float, z_bed: float) -> tuple[np.ndarray, np.ndarray]:
    """Velocity shape (U, W) of the standing mode of wavenumber k (unit potential amplitude)."""
    s = z - z_bed
    return -k * np.cosh(k * s) * np.sin(k * x), k * np.sinh(k * s) * np.cos(k * x)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--dp", type=float, default=0.02)
    ap.add_argument("--d", type=float, default=0.24, help="still-water depth [m]")
    ap.add_argument("--length", type=float, default=1.0, help="tank length = half wavelength [m]")
    ap.add_argument("--a", type=float, default=0.02, help="standing-wave amplitude [m]")
    ap.add_argument("--periods", type=float, default=6.0)
    ap.add_argument("--h-over-dp", type=float)
    ap.add_argument("--alpha", type=float)
    ap.add_argument("--slip", choices=["no_slip", "free_slip"])
    ap.add_argument("--delta", type=float)
    ap.add_argument("--cfl", type=float)
    ap.add_argument("--nu", type=float)
    ap.add_argument("--c0-factor", type=float, default=10.0, help="c0 = factor * sqrt(g d)")
    ap.add_argument("--shifting", choices=["none", "fickian"])
    ap.add_argument("--shift-a", type=float)
    ap.add_argument("--shift-fs-div", type=float)
    ap.add_argument("--alpha-wall", type=float)
    a = ap.parse_args(argv)
    g, d, L = 9.81, a.d, a.length
    k = math.pi / L
    omega = math.sqrt(g * k * math.tanh(k * d))
    period = 2.0 * math.pi / omega
    cst = {kk: v for kk, v in {"h_over_dp": a.h_over_dp, "alpha": a.alpha, "wall_slip": a.slip,
                               "delta": a.delta, "cfl": a.cfl, "nu": a.nu, "shifting": a.shifting,
                               "shift_a": a.shift_a, "shift_fs_div": a.shift_fs_div,
                               "alpha_wall_factor": a.alpha_wall}.items() if v is not None}
    scene = make_scene({
        "name": "standing_wave", "dp": a.dp, "t_end": a.periods * period, "still_water_level": d,
        "tank": {"x0": 0.0, "x1": L, "z0": 0.0, "z1": d + 4 * a.a + 4 * a.dp},
        "water_blocks": [{"x0": 0.0, "x1": L, "z0": 0.0, "z1": d}],
        "constants": {"c0": a.c0_factor * math.sqrt(g * d), **cst},
        "output": {"probe_every": period / 40},
        "probes": [{"kind": "elevation", "name": "left", "x": 0.1},
                   {"kind": "elevation", "name": "right", "x": L - 0.1}]})
    sim = Simulation(scene)
    ps = sim.particles
    fl = ps.kind[: ps.n] == FLUID
    amp_a = a.a * g / (omega * math.cosh(k * d))
    x, z = ps.f[X, : ps.n][fl], ps.f[Z, : ps.n][fl]
    u0, w0 = mode(x, z, k, 0.0)
    ps.f[VX, : ps.n][fl] = amp_a * u0
    ps.f[VZ, : ps.n][fl] = amp_a * w0
    ts, cs, ke, ke_noise, eta_l, eta_r = [], [], [], [], [], []
    dt_out = period / 40
    tic = time.perf_counter()
    n_out = int(round(a.periods * 40))
    for i in range(n_out + 1):
        if i:
            sim.advance_to(i * dt_out)
        fl = ps.kind[: ps.n] == FLUID
        x, z = ps.f[X, : ps.n][fl], ps.f[Z, : ps.n][fl]
        u, w, m = ps.f[VX, : ps.n][fl], ps.f[VZ, : ps.n][fl], ps.f[M, : ps.n][fl]
        ke_tot = 0.5 * np.sum(m * (u * u + w * w))
        # projection on modes 1..3 (near-orthogonal on the lattice); the rest is noise
        ke_modes = 0.0
        c1 = 0.0
        for n in (1, 2, 3):
            un, wn = mode(x, z, n * k, 0.0)
            norm = np.sum(m * (un * un + wn * wn))
            cn = np.sum(m * (u * un + w * wn)) / norm
            ke_modes += 0.5 * cn * cn * norm
            if n == 1:
                c1 = cn / amp_a
        pv = sim.probe_values()
        ts.append(sim.t)
        cs.append(c1)
        ke.append(ke_tot)
        ke_noise.append(max(ke_tot - ke_modes, 0.0))
        eta_l.append(pv["left_eta"] if pv["left_eta"] is not None else np.nan)
        eta_r.append(pv["right_eta"] if pv["right_eta"] is not None else np.nan)
    wall = time.perf_counter() - tic
    t = np.array(ts)
    c = np.array(cs)

    def damped(tt, amp, beta, om, ph):
        return amp * np.exp(-beta * tt) * np.cos(om * tt + ph)

    (amp, beta, om, ph), _ = curve_fit(damped, t, c, p0=(1.0, 0.05, omega, 0.0))
    ke0 = ke[0]
    # elevation: eta = a_e exp(-beta t) sin(omega' t + ph) near the left wall (cos(k 0.1) factor)
    el = np.array(eta_l) / math.cos(k * 0.1)
    ok = np.isfinite(el)
    (ae, be, oe, pe), _ = curve_fit(damped, t[ok], el[ok], p0=(a.a, beta, om, -0.5 * math.pi))
    cg = group_velocity(2.0 * L, period, d)
    half = t >= 0.5 * t[-1]
    print(json.dumps({
        "dp": a.dp, "a_over_dp": round(a.a / a.dp, 3), "constants": cst, "c0_factor": a.c0_factor,
        "period_theory_s": round(period, 4), "omega_error": round(om / omega - 1.0, 5),
        "beta_per_s": round(float(beta), 5),
        "equiv_decay_per_m": round(float(beta) / cg, 4),
        "equiv_loss_per_wavelength": round(1.0 - math.exp(-float(beta) / cg * 2.0 * L), 4),
        "beta_gauge_per_s": round(float(be), 5),
        "gauge_over_velocity_amplitude": round(abs(float(ae)) / (a.a * abs(float(amp))), 4),
        "ke_noise_over_ke0_mean_2nd_half": float(np.mean(np.array(ke_noise)[half]) / ke0),
        "ke_noise_over_ke0_max": float(np.max(ke_noise) / ke0),

        "particles": sim.n_particles, "steps": sim.steps, "wall_s": round(wall, 1),
        "particle_steps_per_s": round(sim.n_particles * sim.steps / max(sim.wall_time, 1e-9))}),
        flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
