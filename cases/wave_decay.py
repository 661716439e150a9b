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

from sph_core.scene import ElevationProbe

from .wave_analysis import group_velocity, harmonic_amplitude
from .wave_flume import run_wave_flume, wave_flume_scene


@dataclass(frozen=True)
class AmplitudeProfile:
    """First-harmonic amplitude of SPH over theory at gauges x [m from the inlet face]."""

    x: np.ndarray
    ratio: np.ndarray
    decay_per_m: float      # -d ln(ratio)/dx, least squares over the gauges
    intercept: float        # ln(ratio) of that fit at x = 0
    wall_s: float
    particles: int

    def ratio_at(self, x: float) -> float:
        """The fitted ratio at ``x`` [m] (the outlet's small reflection ripples the profile)."""
        return math.exp(self.intercept - self.decay_per_m * x)


def amplitude_profile(model: Any, *, ramp: float, height: float, period: float, depth: float,
                      dp: float, periods: float = 4.0, n_gauges: int = 12,
                      **constants: Any) -> AmplitudeProfile:
    """Run the flume driven by ``model`` (its start-up ramp lasting ``ramp`` s) and measure
    the amplitude ratio along it (``constants`` override the scene's, e.g. alpha)."""
    length = float(model.length)
    xs = np.round(np.linspace(2.0 * math.sqrt(2.0) * dp, 0.75 * length, n_gauges), 4)
    # the ramped front and one period past the last gauge
    t0 = ramp + xs[-1] / group_velocity(length, period, depth) + period
    scene = wave_flume_scene(depth=depth, wavelength=length, height=height, dp=dp,
                             t_end=t0 + periods * period, length=length, absorb=(True, True),
                             right_elevation="extrapolated", probe_every=period / 40,
                             name="wave_decay", **constants)
    probes = [ElevationProbe(kind="elevation", name=f"g{i}", x=float(x)) for i, x in enumerate(xs)]
    scene = scene.model_copy(update={"probes": probes})
    res = run_wave_flume(scene, model, window=period / 50)
    sel = np.nonzero(res.t >= t0 - 1e-9)[0]
    sel = sel[: int(round(periods * period / (res.t[1] - res.t[0])))]
    omega = 2.0 * math.pi / period
    ratio = np.array([abs(harmonic_amplitude(res.t[sel], res.eta[p.name][sel], omega))
                      / abs(harmonic_amplitude(res.t[sel], res.theory[p.name][sel], omega))
                      for p in probes])
    slope, icpt = np.polyfit(xs, np.log(ratio), 1)
    return AmplitudeProfile(xs, ratio, float(-slope), float(icpt), res.wall_s, res.particles)
