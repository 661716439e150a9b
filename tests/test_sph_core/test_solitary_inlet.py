"""An SPH open inlet driven by the solitary-wave theory takes the wave in: the volume that
enters is the theory's, and the crest reaches a gauge at the theory's time with its height."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sph_core.boundary_data import WaveModelBoundary
from sph_core.open_ends import flume_nodes
from sph_core.scene import make_scene
from sph_core.simulation import Simulation
from wave_client.theories import SolitaryWave


def test_solitary_wave_enters_through_an_open_inlet():
    d, H, dp, x_g = 0.2, 0.06, 0.025, 0.8    # H/d 0.3, H/dp 2.4
    wave = SolitaryWave(H, depth=d)
    t_end = wave.t0 + 0.6
    scene = make_scene({
        "dp": dp, "t_end": t_end, "still_water_level": d,
        "tank": {"x0": 0.0, "x1": 2.0, "z0": 0.0, "z1": 0.4},
        "water_blocks": [{"x0": 0.0, "x1": 2.0, "z0": 0.0, "z1": d}],
        "open_boundaries": [{"side": "left", "elevation": "imposed"}],
        "output": {"probe_every": 0.02},
        "probes": [{"kind": "elevation", "name": "g", "x": x_g}]})
    src = WaveModelBoundary(wave, flume_nodes(scene)["left"], d, 0.0)
    sim = Simulation(scene, sources={"left": src})
    m0 = sim.fluid_mass()
    sim.advance_to(t_end)
    # volume in through the face: int (d + eta) u dt = c int eta(0, t) dt (u = c eta / (d + eta))
    ts = np.linspace(0.0, t_end, 20_001)
    eta0 = []
    for t in ts:
        wave.advance_to(t)
        eta0.append(wave.elevation([0.0])[0])
    volume = wave.c * np.trapezoid(eta0, ts)
    rho0 = scene.constants.rho0
    assert (sim.fluid_mass() - m0) / rho0 == pytest.approx(volume, rel=0.25)
    t = np.array([r["t"] for r in sim.history])
    eta = np.array([np.nan if r["g_eta"] is None else r["g_eta"] for r in sim.history])
    assert np.nanmax(np.abs(eta[t < 0.5 * wave.t0])) < 0.1 * H      # at rest before the wave
    k = int(np.nanargmax(eta))
    assert eta[k] == pytest.approx(H, rel=0.3)
    assert t[k] == pytest.approx(wave.t0 + x_g / math.sqrt(9.81 * (d + H)), abs=0.1)
