"""The SPH flume's own amplitude loss over distance for a progressive wave driven by theory.

    model = build_theory("stokes", height=0.04, period=1.4, depth=0.24, ramp_time=1.4, order=2)
    prof = amplitude_profile(model, ramp=1.4, height=0.04, period=1.4, depth=0.24, dp=0.02)
    prof.ratio_at(0.8)           # SPH / theory first-harmonic amplitude 0.8 m past the inlet

A flume one wavelength long with open ends driven by a wave theory (any object with the
WaveModel duck type and a ``length``, wave_client's theories, passed in), elevation
gauges from 2h past the inlet to 3/4 of the flume. No coupling and no wave model but the theory:
what it measures is SPH's own loss (viscosity, kernel smoothing of the surface, particle noise),
the floor under any coupled flume's error at that dp. `bench/wave_decay.py` prints it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.optimize import minimize

from sph_core.absorption import linear_wavenumber
from sph_core.scene import ElevationProbe, PointProbe

from .particle_noise import binned_noise, noise_energy
from ..analysis import group_velocity, harmonic_amplitude
from .wave_flume import run_wave_flume, wave_flume_scene


NOISE_BIN_M = 0.25   # x bins of the particle-noise profile [m]


@dataclass(frozen=True)
class AmplitudeProfile:
    """First-harmonic amplitude of SPH over theory at gauges x [m from the inlet face]."""

    x: np.ndarray
    ratio: np.ndarray
    decay_per_m: float      # -d ln(ratio)/dx, least squares over the gauges
    intercept: float        # ln(ratio) of that fit at x = 0
    wall_s: float
    particles: int
    steps: int = 0
    amp: np.ndarray | None = None   # complex first-harmonic amplitudes of SPH at x [m]
    k: float = 0.0                  # the theory's wavenumber [1/m]
    # diagnostics: first and second half of the window's ratio; time-mean eta of SPH minus
    # theory [m] per gauge; the flume's mean level change [m] from its fluid particle count
    ratio_first_half: np.ndarray | None = None
    ratio_second_half: np.ndarray | None = None
    mean_eta_error: np.ndarray | None = None
    level_drift_m: float = 0.0
    # second harmonic (2 omega) of SPH over the theory's per gauge: a free second harmonic
    # emitted by the inlet beats along x against the bound one
    ratio_2nd: np.ndarray | None = None
    # with noise=True (wavesph.cases.particle_noise): bin centres [m], the particle-noise kinetic energy
    # per bin over the wave's energy 0.5 rho0 g a^2 per bin, mean over the window; sample times
    # [s] and the noise over the gauged span's wave energy at each
    noise_x: np.ndarray | None = None
    noise_fraction: np.ndarray | None = None
    noise_t: np.ndarray | None = None
    noise_fraction_t: np.ndarray | None = None
    # per end (left, right): particles in / out / created / removed over the run
    counts: dict | None = None
    # modulated_decay's fit: decay [1/m] with the outlet's reflection ripple (period L/2) and
    # the free second harmonic's beat (period 2 pi / (k(2 omega) - 2k)) fitted beside it, and
    # the two modulations' amplitudes (in ln ratio)
    modulated_decay_per_m: float = 0.0
    reflection_ripple: float = 0.0
    beat_modulation: float = 0.0
    # the same fit over each whole period of the window in turn: a decay that changes with
    # the run's time shows here
    decay_per_period: np.ndarray | None = None
    # the fit along the wave groups (group_decays): each period of the window followed down the
    # flume, each gauge x / c_g later; an envelope the inlet sends does not read as decay
    group_decay_per_period: np.ndarray | None = None
    # the gauge records, for a re-analysis without re-running (bench/wave_decay.py --records):
    # t [s], eta and theory [m] (rows: gauges at x), t0 the window's start [s], cg [m/s]
    records: dict[str, Any] | None = None
    # with velocity_z: per height above the floor [m], group_decays of the horizontal velocity's
    # first harmonic at the gauges' x (the wave's own loss, without the elevation gauge); its
    # records: velocity_z [m], u and u_theory [m/s] (height, gauge, time at records' t)
    velocity_group_decay_per_period: dict[float, np.ndarray] | None = None
    velocity_records: dict[str, np.ndarray] | None = None

    def ratio_at(self, x: float) -> float:
        """The fitted ratio at ``x`` [m] (the outlet's small reflection ripples the profile)."""
        return math.exp(self.intercept - self.decay_per_m * x)


def amplitude_profile(model: Any, *, ramp: float, height: float, period: float, depth: float,
                      dp: float, periods: float = 4.0, n_gauges: int = 12,
                      flume_wavelengths: float = 1.0, inlet_pressure: str | None = None,
                      settle_periods: float = 0.0, outlet_absorb: bool = True,
                      gauge_wavelengths: float = 0.75, wait_reflection: bool = False,
                      noise: bool = False, device: str | None = None,
                      velocity_z: tuple[float, ...] = (), **constants: Any) -> AmplitudeProfile:
    """Run the flume driven by ``model`` (its start-up ramp lasting ``ramp`` s) and measure
    the amplitude ratio along it (``constants`` override the scene's, e.g. alpha). The flume is
    ``flume_wavelengths`` long; the gauges stay within ``gauge_wavelengths`` of the inlet
    (3/4 by default: a one-wavelength flume). The window starts ``settle_periods`` periods
    after the front has passed the last gauge, or with ``wait_reflection`` after the front's
    reflection from the outlet has come back to the inlet (the separated fit assumes a steady
    reflected wave). ``noise``: sample the particle-noise energy along x every period / 5
    (wavesph.cases.particle_noise; about 1 s of numpy per sample at dp 0.02, outside ``wall_s``).
    ``velocity_z``: heights above the floor [m] of velocity probes at every gauge's x, whose
    horizontal velocity is fitted along the wave groups as the gauges are: a loss the velocity
    field shows too is the wave's, not the elevation gauge's."""
    length = float(model.length)
    if not 0.0 < gauge_wavelengths < flume_wavelengths:
        raise ValueError(f"gauge_wavelengths ({gauge_wavelengths}) must lie inside the flume "
                         f"({flume_wavelengths} wavelengths)")
    last = round(gauge_wavelengths * length, 4)
    # the ramped front and one period past the last gauge
    cg = group_velocity(length, period, depth)
    travel = 2.0 * flume_wavelengths * length if wait_reflection else last
    t0 = ramp + travel / cg + (1.0 + settle_periods) * period
    scene = wave_flume_scene(depth=depth, wavelength=length, height=height, dp=dp,
                             t_end=t0 + periods * period, length=flume_wavelengths * length,
                             absorb=(True, outlet_absorb),
                             right_elevation="extrapolated", probe_every=period / 40,
                             name="wave_decay", left_pressure=inlet_pressure, period=period,
                             **constants)
    # the first gauge 2h past the inlet, or past an ISPH relaxation zone (inside it the velocity
    # is pulled towards the theory's: not the SPH wave's own)
    first = 2.0 * math.sqrt(2.0) * dp
    if scene.scheme.kind == "isph":
        first = max(first, scene.scheme.isph_relaxation_zone)
    if first >= last:
        raise ValueError(f"the gauges' span ends at {last} m, inside the first gauge's {first} m "
                         "(an ISPH relaxation zone longer than the span)")
    xs = np.round(np.linspace(first, last, n_gauges), 4)
    for z in velocity_z:
        if not 0.0 < z < depth:
            raise ValueError(f"velocity_z: {z} m must lie between the floor (0) and the still "
                             f"water level ({depth} m)")
    probes = [ElevationProbe(kind="elevation", name=f"g{i}", x=float(x)) for i, x in enumerate(xs)]
    vnames = [[f"v{j}_{i}" for i in range(xs.size)] for j in range(len(velocity_z))]
    points = [PointProbe(kind="point", name=vnames[j][i], x=float(x), z=float(z))
              for j, z in enumerate(velocity_z) for i, x in enumerate(xs)]
    scene = scene.model_copy(update={"probes": probes + points})
    edges = np.arange(0.0, scene.tank.x1 + 1e-9, NOISE_BIN_M)
    noise_rec: list[tuple[float, np.ndarray]] = []

    def sample(sim: Any) -> None:
        st = sim.fluid_state()
        dke = noise_energy(st["x"], st["z"], st["vx"], st["vz"], st["m"], dp)
        noise_rec.append((sim.t, binned_noise(st["x"], dke, edges)))

    res = run_wave_flume(scene, model, window=period / 50, sample=sample if noise else None,
                         device=device)
    sel = np.nonzero(res.t >= t0 - 1e-9)[0]
    sel = sel[: int(round(periods * period / (res.t[1] - res.t[0])))]
    omega = 2.0 * math.pi / period
    amp = np.array([harmonic_amplitude(res.t[sel], res.eta[p.name][sel], omega) for p in probes])
    etas = np.array([res.eta[p.name] for p in probes])
    theories = np.array([res.theory[p.name] for p in probes])

    def window_ratio(part: np.ndarray) -> np.ndarray:   # part: contiguous indices
        return harmonic_ratios(res.t, etas, theories, omega, np.full(len(probes), part[0]),
                               part.size)

    ratio = window_ratio(sel)
    slope, icpt = np.polyfit(xs, np.log(ratio), 1)

    nh = sel.size // 2
    mean_err = np.array([np.mean(res.eta[p.name][sel]) - np.mean(res.theory[p.name][sel])
                         for p in probes])
    nf = res.n_fluid
    drift = float((nf[-1, 1] - nf[0, 1]) * dp * dp / scene.tank.x1)
    ratio2 = np.array([abs(harmonic_amplitude(res.t[sel], res.eta[p.name][sel], 2.0 * omega))
                       / abs(harmonic_amplitude(res.t[sel], res.theory[p.name][sel], 2.0 * omega))
                       for p in probes])
    nx = nfr = nt = nft = None
    if noise_rec:
        e_bin = 0.5 * scene.constants.rho0 * scene.constants.g * (0.5 * height) ** 2 * NOISE_BIN_M
        nt = np.array([t for t, _ in noise_rec])
        nb = np.array([b for _, b in noise_rec])
        win = (nt >= t0 - 1e-9) & (nt <= t0 + periods * period + 1e-9)
        nx = 0.5 * (edges[1:] + edges[:-1])
        nfr = nb[win].mean(axis=0) / e_bin
        span = edges[1:] <= xs[-1] + 1e-9
        nft = nb[:, span].sum(axis=1) / (e_bin * np.count_nonzero(span))
    k = 2.0 * math.pi / length
    kb = beat_wavenumber(k, period, depth)
    mod = modulated_decay(xs, ratio, k, kb)
    per = int(round(period / (res.t[1] - res.t[0])))
    by_period = np.array([modulated_decay(xs, window_ratio(sel[j:j + per]), k, kb)[0]
                          for j in range(0, sel.size - per + 1, per)])
    along = group_decays(res.t, etas, theories, xs, t0=t0, period=period, cg=cg, k=k, k_beat=kb)
    records = {"t": res.t, "x": xs, "eta": etas, "theory": theories, "t0": t0,
               "period": period, "cg": cg, "k": k, "k_beat": kb}
    vel_along = vel_records = None
    if velocity_z:
        u = np.array([[res.velocity[nm][0] for nm in row] for row in vnames])
        u_th = np.array([[res.theory_velocity[nm][0] for nm in row] for row in vnames])
        vel_along = {float(z): group_decays(res.t, u[j], u_th[j], xs, t0=t0, period=period,
                                            cg=cg, k=k, k_beat=kb)
                     for j, z in enumerate(velocity_z)}
        vel_records = {"velocity_z": np.array(velocity_z, dtype=float), "u": u, "u_theory": u_th}
    return AmplitudeProfile(xs, ratio, float(-slope), float(icpt), res.wall_s, res.particles,
                            res.steps, amp, k, window_ratio(sel[:nh]),
                            window_ratio(sel[nh:]), mean_err, drift, ratio2, nx, nfr, nt, nft,
                            res.counts, *mod, by_period, along, records, vel_along, vel_records)


def group_decays(t: np.ndarray, eta: np.ndarray, theory: np.ndarray, x: np.ndarray, *,
                 t0: float, period: float, cg: float, k: float, k_beat: float) -> np.ndarray:
    """modulated_decay [1/m] of each period that leaves the inlet from ``t0`` on, followed down
    the flume: gauge i (``x[i]``, records ``eta[i]`` and ``theory[i]`` at uniform ``t``) is read
    over the period x[i] / cg later, as far as the records reach. Read at one time instead, an
    amplitude the inlet changes over time reads as decay along x (the far gauges still see the
    older waves): the long flume's inlet falls 2.5 % as the outlet's reflection returns, and the
    fixed-time fit reads 0.3 %/m where the wave loses 0.9 (docs/studies/wave_decay_study.md)."""
    t0, period, cg, k, k_beat = map(float, (t0, period, cg, k, k_beat))  # an npz's 0-d arrays
    dt = float(t[1] - t[0])
    per = int(round(period / dt))
    lag = np.rint(x / cg / dt).astype(int)
    start = int(np.searchsorted(t, t0 - 1e-9))
    omega = 2.0 * math.pi / period
    out = []
    while start + lag.max() + per <= t.size:
        out.append(modulated_decay(x, harmonic_ratios(t, eta, theory, omega, start + lag, per),
                                   k, k_beat)[0])
        start += per
    return np.array(out)


def harmonic_ratios(t: np.ndarray, eta: np.ndarray, theory: np.ndarray, omega: float,
                    starts: np.ndarray, n: int) -> np.ndarray:
    """|first harmonic| of ``eta[i]`` over that of ``theory[i]`` (rows: gauges, at uniform
    ``t``), each over its own ``n`` samples from ``starts[i]``."""
    return np.array([abs(harmonic_amplitude(t[a:a + n], e[a:a + n], omega))
                     / abs(harmonic_amplitude(t[a:a + n], th[a:a + n], omega))
                     for a, e, th in zip(starts, eta, theory)])


def beat_wavenumber(k: float, period: float, depth: float) -> float:
    """Wavenumber [1/m] of the beat between a free second harmonic (linear dispersion at
    2 omega) and the bound one (2k): the first harmonic's third-order modulation along x."""
    return linear_wavenumber(4.0 * math.pi / period, depth) - 2.0 * k


def modulated_decay(x: np.ndarray, ratio: np.ndarray, k: float,
                    k_beat: float) -> tuple[float, float, float]:
    """(decay [1/m], reflection ripple, beat modulation) of the amplitude ratio at ``x`` by
    linear least squares, ln ratio = c - decay x + ripple cos(2k x + .) + beat cos(k_beat x + .).
    A plain log-linear fit over a span that is not whole periods of both modulations reads them
    partly as decay: on the long flume a 0.5 % beat of period ~3 m moves the fit over half the
    gauges between 0.2 and 0.8 %/m (docs/studies/wave_decay_study.md). A modulation whose
    period the gauges' span does not cover is left out (it and the slope are one there) and
    its amplitude is nan."""
    span = float(x.max() - x.min())
    waves = [kk for kk in (2.0 * k, k_beat) if 2.0 * math.pi / kk <= span]
    cols = [np.ones_like(x), -x]
    for kk in waves:
        cols += [np.cos(kk * x), np.sin(kk * x)]
    coef, *_ = np.linalg.lstsq(np.stack(cols, axis=1), np.log(ratio), rcond=None)
    amps = {kk: math.hypot(coef[2 + 2 * i], coef[3 + 2 * i]) for i, kk in enumerate(waves)}
    return float(coef[1]), amps.get(2.0 * k, math.nan), amps.get(k_beat, math.nan)


def separated_decay(x: np.ndarray, amp: np.ndarray, k: float) -> tuple[float, float, float]:
    """(decay [1/m], wavenumber [1/m], |a_R|/|a_I|) of complex amplitudes ``amp`` at ``x`` fitted
    by an incident and a reflected wave decaying along their travel at one rate,
        A_j = a_I exp(-(i k' + delta) x_j) + a_R exp((i k' + delta) x_j),
    delta and k' (started at the theory's k) by least squares: the outlet's reflection ripples
    |A_j| with period L/2, which the plain log fit of the profile reads partly as decay.
    TODO(lead): move onto helper D's Mansard-Funke separation in wave_analysis once it lands."""
    xc = x - 0.5 * (x.min() + x.max())

    def resid(par: np.ndarray) -> float:
        dl, kk = par
        a = np.stack([np.exp(-(1j * kk + dl) * xc), np.exp((1j * kk + dl) * xc)], axis=1)
        c, *_ = np.linalg.lstsq(a, amp, rcond=None)
        return float(np.linalg.norm(a @ c - amp))

    best = min((minimize(resid, np.array([d0, k]), method="Nelder-Mead",
                         options={"xatol": 1e-6, "fatol": 1e-12}) for d0 in (0.0, 0.05, 0.15)),
               key=lambda r: r.fun)
    dl, kk = best.x
    a = np.stack([np.exp(-(1j * kk + dl) * xc), np.exp((1j * kk + dl) * xc)], axis=1)
    (a_i, a_r), *_ = np.linalg.lstsq(a, amp, rcond=None)
    return float(dl), float(kk), float(abs(a_r) / abs(a_i))


def convergence_orders(dps: list[float], decays: list[float]) -> list[float | None]:
    """Observed order of the decay between successive resolutions,
    log(decay_1 / decay_2) / log(dp_1 / dp_2) (None where a decay is <= 0)."""
    out: list[float | None] = []
    for (d1, k1), (d2, k2) in zip(zip(dps, decays), zip(dps[1:], decays[1:])):
        out.append(round(math.log(k1 / k2) / math.log(d1 / d2), 3) if k1 > 0 and k2 > 0 else None)
    return out


def convergence_record(dps: list[float], decays: list[float], key: str) -> dict[str, Any]:
    """A dp sweep's summary line: the spacings, each one's decay [1/m] under ``key`` (4
    decimals), and the observed orders between successive spacings."""
    return {"dp": dps, key: [round(k, 4) for k in decays],
            "convergence_order": convergence_orders(dps, decays)}
