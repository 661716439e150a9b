"""The SPH wave's own losses without open ends: a standing wave in a closed tank.

    res = standing_wave_decay(dp=0.02, h_over_dp=2.0, alpha_wall_factor=0.0)
    res.equiv_decay_per_m      # comparable with wavesph.cases.wave_decay's decay_per_m

The first sloshing mode of a tank half a wavelength long (walls at the antinodes; by default the
wave of bench/wave_decay.py: d 0.24 m, tank 1.0 m, T 1.42 s, kd 0.75), amplitude a, started at
the phase of zero elevation from the linear velocity field (bed at z = 0, still water at z = d)
    u = -A k cosh(kz) sin(kx),  w = A k sinh(kz) cos(kx),  A = a g / (omega cosh(kd)),
with hydrostatic pressure (exact at that phase). Every T/40 the fluid velocity is projected on
the mode (mass-weighted), c(t) = sum m u.U / sum m U.U (1 at the start), and on modes 1-3: the
kinetic energy outside them is particle-scale noise. c(t) is fitted by
exp(-beta t) cos(omega' t + phi): beta [1/s] is the amplitude decay rate in time and beta / c_g
[1/m] the decay over distance that a progressive wave of the same frequency would have from the
same losses (c_g the linear group velocity). An elevation gauge 0.1 m from the left wall gives
the same fit from the surface: its amplitude over the velocity field's is the gauge's bias.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.optimize import curve_fit

from sph_core.particles import FLUID, M, VX, VZ, X, Z
from sph_core.scene import make_scene
from sph_core.simulation import Simulation
from .particle_noise import noise_energy
from ..analysis import group_velocity


@dataclass(frozen=True)
class StandingWaveDecay:
    """Fitted losses of the standing wave (see the module docstring)."""

    omega_error: float            # omega' / omega_linear - 1
    beta_per_s: float             # amplitude decay rate in time [1/s], from the velocity field
    equiv_decay_per_m: float      # beta / c_g [1/m]
    beta_gauge_per_s: float       # the same from the elevation gauge
    gauge_over_velocity: float    # gauge amplitude / velocity-field amplitude (linear theory)
    noise_ke_fraction: float      # KE outside modes 1-3 / KE_0, mean over the second half
    noise_ke_fraction_max: float
    particles: int
    steps: int
    wall_s: float                 # the jitted loop's wall time [s]
    # wavesph.cases.particle_noise's local measure (velocity minus a local quadratic fit) over KE_0, mean
    # over the second half, sampled every T/10: comparable with an open flume's noise_fraction
    local_noise_fraction: float = 0.0

    def loss_per_wavelength(self, wavelength: float) -> float:
        return 1.0 - math.exp(-self.equiv_decay_per_m * wavelength)


def _mode(x: np.ndarray, z: np.ndarray, k: float) -> tuple[np.ndarray, np.ndarray]:
    """Velocity shape (U, W) of the standing mode of wavenumber k over a bed at z = 0."""
    return -k * np.cosh(k * z) * np.sin(k * x), k * np.sinh(k * z) * np.cos(k * x)


def standing_wave_decay(*, dp: float, depth: float = 0.24, length: float = 1.0,
                        amplitude: float = 0.02, periods: float = 6.0, c0_factor: float = 10.0,
                        g: float = 9.81, scheme: dict | None = None,
                        **constants: Any) -> StandingWaveDecay:
    """Run the closed tank (``constants`` override the scene's, e.g. h_over_dp, alpha;
    c0 = c0_factor sqrt(g d); ``scheme`` the scene's [scheme] table) and fit its losses. The
    depth is rounded to whole rows of dp (the particles fill whole rows: at dp 0.025 the water of
    0.24 m stood at 0.25 m, and the wave's frequency must use the water's depth)."""
    depth = dp * round(depth / dp)
    k = math.pi / length
    omega = math.sqrt(g * k * math.tanh(k * depth))
    period = 2.0 * math.pi / omega
    scene = make_scene({
        "name": "standing_wave", "dp": dp, "t_end": periods * period, "still_water_level": depth,
        "tank": {"x0": 0.0, "x1": length, "z0": 0.0, "z1": depth + 4 * amplitude + 4 * dp},
        "water_blocks": [{"x0": 0.0, "x1": length, "z0": 0.0, "z1": depth}],
        "constants": {"c0": c0_factor * math.sqrt(g * depth), "g": g, **constants},
        "output": {"probe_every": period / 40}, "scheme": scheme or {},
        "probes": [{"kind": "elevation", "name": "gauge", "x": 0.1 * length}]})
    sim = Simulation(scene)
    ps = sim.particles
    fl = ps.kind[: ps.n] == FLUID
    amp_a = amplitude * g / (omega * math.cosh(k * depth))
    u0, w0 = _mode(ps.f[X, : ps.n][fl], ps.f[Z, : ps.n][fl], k)
    ps.f[VX, : ps.n][fl] = amp_a * u0
    ps.f[VZ, : ps.n][fl] = amp_a * w0
    ts, cs, ke, noise, eta, local = [], [], [], [], [], []
    n_out = int(round(periods * 40))
    for i in range(n_out + 1):
        if i:
            sim.advance_to(i * period / 40)
        fl = ps.kind[: ps.n] == FLUID
        x, z = ps.f[X, : ps.n][fl], ps.f[Z, : ps.n][fl]
        u, w, m = ps.f[VX, : ps.n][fl], ps.f[VZ, : ps.n][fl], ps.f[M, : ps.n][fl]
        ke_tot = 0.5 * np.sum(m * (u * u + w * w))
        ke_modes = 0.0
        for n in (1, 2, 3):  # near-orthogonal on the lattice; the rest is noise
            un, wn = _mode(x, z, n * k)
            norm = np.sum(m * (un * un + wn * wn))
            cn = np.sum(m * (u * un + w * wn)) / norm
            ke_modes += 0.5 * cn * cn * norm
            if n == 1:
                cs.append(cn / amp_a)
        if i % 4 == 0:
            local.append((sim.t, float(np.sum(noise_energy(x, z, u, w, m, dp)))))
        ts.append(sim.t)
        ke.append(ke_tot)
        noise.append(max(ke_tot - ke_modes, 0.0))
        e = sim.probe_values()["gauge_eta"]
        eta.append(np.nan if e is None else e)
    t, c = np.array(ts), np.array(cs)

    def damped(tt, amp, beta, om, ph):
        return amp * np.exp(-beta * tt) * np.cos(om * tt + ph)

    (amp, beta, om, _), _ = curve_fit(damped, t, c, p0=(1.0, 0.05, omega, 0.0))
    el = np.array(eta) / math.cos(0.1 * math.pi)
    ok = np.isfinite(el)
    (ae, be, _, _), _ = curve_fit(damped, t[ok], el[ok], p0=(amplitude, beta, om, -0.5 * math.pi))
    cg = group_velocity(2.0 * length, period, depth)
    late = t >= 0.5 * t[-1]
    return StandingWaveDecay(
        float(om / omega - 1.0), float(beta), float(beta) / cg, float(be),
        abs(float(ae)) / (amplitude * abs(float(amp))),
        float(np.mean(np.array(noise)[late]) / ke[0]), float(np.max(noise) / ke[0]),
        sim.n_particles, sim.steps, sim.wall_time,
        float(np.mean([e for tt, e in local if tt >= 0.5 * t[-1]]) / ke[0]))
