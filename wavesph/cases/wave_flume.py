"""A numerical wave flume: open ends driven by a wave model, gauges mid-flume, results vs theory.

    scene = wave_flume_scene(depth=0.3, wavelength=3.26, height=0.06, dp=0.01, t_end=10.0)
    run = run_wave_flume(scene, model, window=T / 50)     # model: WaveModel duck type
    run.eta["mid"], run.theory["mid"]                      # gauge records [m] vs the model
    run.velocity["p"], run.theory_velocity["p"]            # a point probe's (u, w) [m/s] vs the model

The model is any object with the WaveModel duck type of ``wave_client`` (passed in: this module
imports no wave model): the left face stands at the model's abscissa ``x_model_left``, the right face at
``x_model_left + tank length``; both ends sample the same model. The theory at the gauges is
read back from the model after the run, so the model must be analytic (it is rewound).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from sph_core.boundary_data import WaveModelBoundary
from sph_core.open_ends import flume_nodes, orbit_diameter
from sph_core.simulation import Simulation
from sph_core.scene import Scene, make_scene

from ..analysis import (group_velocity, reflection_coefficient, rmse_over_height,
                            separate_harmonics)

# gauges [wavelengths from mid-flume] of the reflection analysis: L/16 apart within L/4 of
# mid-flume (nine, for the decay-aware fit), among them refl_a, mid, refl_b at -L/8, 0, +L/8 (the
# classic three-gauge least squares, reported too)
GAUGE_OFFSETS = {"mid": 0.0, "refl_a": -0.125, "refl_b": 0.125,
                 **{f"refl_{j:+d}": j / 16.0 for j in (-4, -3, -1, 1, 3, 4)}}
REFLECTION_GAUGES = ["refl_-4", "refl_-3", "refl_a", "refl_-1", "mid", "refl_+1",
                     "refl_b", "refl_+3", "refl_+4"]


def buffer_width_for(height: float, period: float, depth: float, dp: float,
                     g: float = 9.81) -> float:
    """An open end's ``buffer_width`` [m] for a regular wave (a spectrum: its largest, ~2 Hs at
    Tp): the surface orbit's diameter plus the largest kernel support (4 dp at h/dp 2), in whole
    dp (sph_core.open_ends.buffer_widths)."""
    return dp * math.ceil(orbit_diameter(height, period, depth, g) / dp + 4.0 - 1e-9)


def wave_flume_scene(*, depth: float, wavelength: float, height: float, dp: float, t_end: float,
                     length: float | None = None, absorb: tuple[bool, bool] = (True, True),
                     right_elevation: str = "extrapolated", probe_every: float = 0.02,
                     c0: float | None = None, g: float = 9.81, name: str = "wave_flume",
                     left_pressure: str | None = None, scheme: dict | None = None,
                     period: float | None = None, **constants: Any) -> Scene:
    """A flat-bed flume [0, length] x [0, top] (floor z = 0, still water at z = depth) with open
    ends and elevation gauges mid-flume and L/16 apart within L/4 of it.

    length defaults to one wavelength; the tank top leaves 2H + 4dp above still water. c0
    defaults to 10 sqrt(g d): the shallow-water celerity bounds the orbital speeds, and the
    hydrostatic density variation g d / c0^2 stays at 1 %. ``scheme``: the scene's [scheme]
    table (default wcsph). ``period`` [s]: the buffers as wide as the wave's orbit plus 2h
    (``buffer_width_for``); None: the scene's default, 2h."""
    # whole number of particle spacings: the right buffer continues the fluid lattice
    length = dp * round((wavelength if length is None else length) / dp)
    top = depth + 2.0 * height + 4.0 * dp
    mid = 0.5 * length
    probes = [{"kind": "elevation", "name": nm, "x": mid + off * wavelength}
              for nm, off in GAUGE_OFFSETS.items() if 0.0 < mid + off * wavelength < length]
    cst = {"c0": c0 if c0 is not None else 10.0 * math.sqrt(g * depth), "g": g, **constants}
    width = None if period is None else buffer_width_for(height, period, depth, dp, g)
    return make_scene({
        "name": name, "dp": dp, "t_end": t_end, "still_water_level": depth,
        "tank": {"x0": 0.0, "x1": length, "z0": 0.0, "z1": top},
        "water_blocks": [{"x0": 0.0, "x1": length, "z0": 0.0, "z1": depth}],
        "constants": cst, "output": {"probe_every": probe_every},
        "probes": probes, "scheme": scheme or {},
        "open_boundaries": [
            {"side": "left", "elevation": "imposed", "absorb": absorb[0],
             "pressure": left_pressure, "buffer_width": width},
            {"side": "right", "elevation": right_elevation, "absorb": absorb[1],
             "buffer_width": width}],
    })


@dataclass
class FlumeRun:
    """Records of one flume run: gauge x [m], times [s], measured and model elevation [m];
    per point probe, measured and model velocity [m/s] (rows u, w)."""

    gauge_x: dict[str, float]
    t: np.ndarray
    eta: dict[str, np.ndarray]
    theory: dict[str, np.ndarray]
    wall_s: float
    steps: int
    particles: int
    n_fluid: np.ndarray
    counts: dict[str, dict[str, int]] = field(default_factory=dict)
    flume: Simulation | None = None
    velocity: dict[str, np.ndarray] = field(default_factory=dict)
    theory_velocity: dict[str, np.ndarray] = field(default_factory=dict)


def run_wave_flume(scene: Scene, model: Any, *, window: float, x_model_left: float = 0.0,
                   run_dir: str | Path | None = None, t_end: float | None = None,
                   keep_flume: bool = False,
                   sample: Callable[[Simulation], None] | None = None,
                   device: str | None = None) -> FlumeRun:
    """Run ``scene`` driven at both ends by ``model``; return gauge records and model values.
    ``device``: where the steps run (None: the scene's ``[run] device``).
    ``sample(flume)``, if given, is called at the start and every 10 windows (a diagnostic's
    hook; its time is not in ``wall_s``)."""
    nodes_x0 = scene.tank.x0
    flume_probe = {p.name: p.x for p in scene.probes if p.kind == "elevation"}
    points = {p.name: (p.x, p.z) for p in scene.probes if p.kind == "point"}
    nodes = flume_nodes(scene)
    sources = {side: WaveModelBoundary(model, nd, scene.still_water_level,
                                       x_model_left + (nd.x_face - nodes_x0))
               for side, nd in nodes.items()}
    flume = Simulation(scene, sources=sources, run_dir=run_dir, window=window, device=device)
    t_end = scene.t_end if t_end is None else t_end
    n_fluid = [(flume.t, flume.n_fluid)]
    if sample is not None:
        sample(flume)
    wall = 0.0
    while flume.t < t_end - 1e-9 * window:
        tic = time.perf_counter()
        flume.advance_to(min(flume.t + 10 * window, t_end))
        wall += time.perf_counter() - tic
        n_fluid.append((flume.t, flume.n_fluid))
        if sample is not None:
            sample(flume)
    hist = flume.history
    t = np.array([row["t"] for row in hist])

    def column(key: str) -> np.ndarray:   # a probe's record; None (no fluid there) -> nan
        return np.array([np.nan if row[key] is None else row[key] for row in hist])

    eta = {nm: column(f"{nm}_eta") for nm in flume_probe}
    theory = {nm: np.empty(t.size) for nm in flume_probe}
    vel = {nm: np.array([column(f"{nm}_u"), column(f"{nm}_w")]) for nm in points}
    theory_vel = {nm: np.empty((2, t.size)) for nm in points}
    xm = np.array([x_model_left + (x - nodes_x0) for x in flume_probe.values()])
    xp = np.array([x_model_left + (x - nodes_x0) for x, _ in points.values()])
    zp = np.array([z - scene.still_water_level for _, z in points.values()])  # model: z from SWL
    for k, tk in enumerate(t):
        model.advance_to(float(tk))
        vals = np.asarray(model.elevation(xm), dtype=float)
        for j, nm in enumerate(flume_probe):
            theory[nm][k] = vals[j]
        if points:
            u, w = model.velocity(xp, zp)
            for j, nm in enumerate(points):
                theory_vel[nm][:, k] = u[j], w[j]
    run = FlumeRun(flume_probe, t, eta, theory, wall, flume.steps, flume.n_particles,
                   np.array(n_fluid), flume.boundary_counts(), flume if keep_flume else None,
                   vel, theory_vel)
    flume.close()
    return run


def flume_length(wavelength: float, standing: bool = False) -> float:
    """The length [m] of flume_case's flume: one wavelength, half for a standing wave (its faces
    at the nodes of eta)."""
    return 0.5 * wavelength if standing else wavelength


def flume_case(model: Any, *, height: float, period: float, depth: float, wavelength: float,
               dp: float, periods: float, ramp: float, standing: bool = False,
               absorb: tuple[bool, bool] = (True, True), window_per_period: int = 50,
               regular: bool = True, name: str = "wave_flume", steady: bool = False,
               device: str | None = None, **constants: Any) -> dict[str, Any]:
    """Run one wave case and score it: the figures of ``bench/flume_accuracy.py``.

    Flume one wavelength long (standing wave: half, faces at the nodes of eta, antinode
    mid-flume); ``model`` must carry the start-up ramp of duration ``ramp``. rmse_over_H: the
    mid-flume gauge vs the model over the ``periods`` after the ramped wave reached mid-flume
    (at the linear group velocity); reflection: least squares over the nine gauges within L/4
    of mid-flume with a fitted spatial decay (``wave_analysis``: the coarse flume damps its
    waves, and the plain fit reads that as reflection); reflection_3g: the plain least squares
    over mid-flume and L/8 either side. Both None for a standing wave or an irregular sea
    (``regular=False``, whose ``wavelength`` and ``period`` are those of the peak).
    mean_level_m: mean of the mid-flume gauge minus the model's over the scored periods;
    level_drift_m: change of the flume's water volume per length since the start (fluid
    particles x dp^2 / length; None unless a regular progressive wave); level_last_period_m:
    the reflection gauges' (else mid) time mean over the last period minus the model's.
    speed_max_m_s: the fastest fluid particle within 4h of each face ("left", "right") and within
    L/4 of mid-flume ("mid"), sampled every 10 coupling windows: an end whose near-face fluid
    runs many times faster than mid-flume's is disordered (its gauge then reads glitches).
    ``steady`` (progressive regular waves): run on until ``periods`` more have passed after the
    outlet's start-up has gone by the gauges and score reflection_steady (nine gauges, decay)
    there. The model starts everywhere at once, so until SPH's ramped wave reaches the outlet
    the outlet is told a wave that is not there: its correction answers a mismatch of the whole
    wave, and what it emits then crosses the gauges during the standard window (at kd 2, H/dp 4:
    6.2 % there, 0.5-2 % once it has passed; docs/studies/absorption.md, 2026-11-23)."""
    length = flume_length(wavelength, standing)
    # the ramp starts the model everywhere at once, SPH's wave front travels from the inlet:
    # compare once the fully ramped wave has reached mid-flume at the (linear) group velocity
    k = 2.0 * math.pi / wavelength
    kd = k * depth
    cg = group_velocity(wavelength, period, depth)
    t_start = ramp + (0.0 if standing else 0.5 * length / cg)
    t_end = t_start + periods * period
    steady = steady and regular and not standing
    if steady:
        # the ramped wave reaches the outlet at ramp + length/cg; what the outlet emitted
        # until then has passed the far gauge (L/4 short of mid-flume) (length/2 + L/4)/cg later
        t_steady = ramp + (1.5 * length + 0.25 * wavelength) / cg
        t_end = max(t_end, t_steady + periods * period)
    scene = wave_flume_scene(depth=depth, wavelength=wavelength, height=height, dp=dp,
                             t_end=t_end, length=length, absorb=absorb,
                             right_elevation="imposed" if standing else "extrapolated",
                             probe_every=period / 40, name=name, period=period,
                             **constants)
    x_left = -0.5 * scene.tank.x1 if standing else 0.0
    speed_max = {"left": 0.0, "right": 0.0, "mid": 0.0}

    def watch(flume: Simulation) -> None:
        # the fastest fluid particle within 4h of each face (the boundary gauge's support
        # reaches 2h inside) and within L/4 of mid-flume: a blow-up at an open end shows as a
        # face speed many times the wave's own (docs/studies/absorption.md, "Case III at H/dp 6")
        fl = flume.fluid_state()
        speed = np.hypot(fl["vx"], fl["vz"])
        zones = {side: np.abs(fl["x"] - nd.x_face) < 4.0 * scene.h
                 for side, nd in flume.nodes.items()}
        zones["mid"] = np.abs(fl["x"] - 0.5 * scene.tank.x1) < 0.25 * wavelength
        for zone, m in zones.items():
            if m.any():
                speed_max[zone] = max(speed_max[zone], float(speed[m].max()))

    res = run_wave_flume(scene, model, window=period / window_per_period, x_model_left=x_left,
                         device=device, sample=watch)
    sel = (res.t >= t_start - 1e-9) & (res.t <= t_start + periods * period + 1e-9)
    refl = refl_3g = refl_steady = None
    refl_h: list[float] | None = None
    if regular and not standing:
        def kr(names: list[str], decay: bool) -> float:
            return reflection_coefficient(
                res.t[sel], np.array([res.eta[n][sel] for n in names]),
                np.array([res.gauge_x[n] for n in names]), period, k, decay=decay)[0]
        refl = kr(REFLECTION_GAUGES, True)
        refl_3g = kr(["refl_a", "mid", "refl_b"], False)
        if steady:
            late = res.t >= t_steady - 1e-9
            refl_steady = reflection_coefficient(
                res.t[late], np.array([res.eta[n][late] for n in REFLECTION_GAUGES]),
                np.array([res.gauge_x[n] for n in REFLECTION_GAUGES]), period, k, decay=True)[0]
        # per harmonic (bound harmonics: wavenumber n k), nine gauges, fitted decay
        refl_h = [round(s.kr, 5) for s in separate_harmonics(
            res.t[sel], np.array([res.eta[n][sel] for n in REFLECTION_GAUGES]),
            np.array([res.gauge_x[n] for n in REFLECTION_GAUGES]), period, [k, 2 * k],
            decay=True)]
    nf = res.n_fluid
    # water level drift: a flume one wavelength long holds the volume of still water at any
    # phase of a regular progressive wave; each fluid particle carries dp^2 of the initial lattice
    level_drift = ((nf[-1, 1] - nf[0, 1]) * dp * dp / scene.tank.x1
                   if regular and not standing else None)
    # and the gauges' time-mean over the last whole period, minus the model's
    last = res.t >= res.t[-1] - period + 1e-9
    gauges = REFLECTION_GAUGES if regular and not standing else ["mid"]
    level_last = float(np.mean([np.mean(res.eta[n][last]) - np.mean(res.theory[n][last])
                                for n in gauges]))
    return {"H": height, "T": period, "d": depth, "dp": dp, "H_over_dp": round(height / dp, 3),
            "periods": periods,
            "rmse_over_H": rmse_over_height(res.eta["mid"][sel], res.theory["mid"][sel], height),
            "reflection": refl, "reflection_3g": refl_3g, "reflection_harmonics": refl_h,
            "reflection_steady": refl_steady,
            "absorb": list(absorb), "kd": round(kd, 4),
            "wall_s": round(res.wall_s, 2),
            "wall_s_per_sim_s": round(res.wall_s / max(float(res.t[-1]) - scene.t_start, 1e-9), 3),
            "particles": res.particles, "steps": res.steps,
            "particle_steps_per_s": round(res.particles * res.steps / max(res.wall_s, 1e-9)),
            "fluid_change": int(nf[-1, 1] - nf[0, 1]), "boundary_counts": res.counts,
            "mean_level_m": float(np.mean(res.eta["mid"][sel]) - np.mean(res.theory["mid"][sel])),
            "level_drift_m": level_drift, "level_last_period_m": level_last,
            "speed_max_m_s": {k: round(v, 3) for k, v in speed_max.items()}}
