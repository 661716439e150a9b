"""Still-water tank against hydrostatics (p = rho0 g (d - z)) for 20 sqrt(d/g), for every scheme
(SCHEMES: the scene's [scheme] tables; Riemann SPH as the chart's default variant)."""

import math

import numpy as np
import pytest

from sph_core.scene import make_scene
from sph_core.simulation import Simulation

D = 0.25          # still-water depth [m]
DP = D / 25       # 25 layers
PROBE_Z = [0.02, 0.05, 0.08, 0.11]   # all below half depth
SCHEMES = {"wcsph": {}, "riemann": {"kind": "riemann"}, "isph": {"kind": "isph"}}
# Riemann SPH needs h/dp 2 (the default): at h/dp sqrt 2 it measured bed pressure up to 9 % off and
# surface particles at 0.024 m/s (limit 0.0157) on this scene (docs/studies/schemes.md)


# ISPH's 3.2 s at d/dp 25 is slow (a sparse solve per step). It holds the tank that long since
# its corrector leaves the dry wall particles out (tests/test_sph_core/test_isph.py); its pressure
# is low by what p = 0 on the surface particles' centres costs
ISPH_PRESSURE = ("ISPH: 3.5 % below rho0 g (d - z) at z = 0.11 m over the second half: p = 0 sits "
                 "on the surface particles' centres, dp/2 below the surface, and the density "
                 "relaxation pulls the cut-support layers together (docs/studies/schemes.md "
                 "'## ISPH'); measured, not tuned")


# Riemann SPH's tank (h/dp 2) took 70 s (cold numba cache) and 108 s (warm) of the default run,
# against WCSPH's 35 s and 24 s (2 shared cores, load 4-6, 2026-11-26, `pytest --durations=0`):
# slow. The default run keeps Riemann's still-water checks at the same bounds (pressure 3 %,
# speed 1 % of sqrt(g d)) in the open-ended flume (6 s),
# tests/test_sph_core/test_open_boundary.py::test_still_water_with_open_ends_*[riemann]
@pytest.fixture(scope="module", params=["wcsph", pytest.param("riemann", marks=pytest.mark.slow),
                                        pytest.param("isph", marks=pytest.mark.slow)])
def still_run(request):
    scene = make_scene({
        "name": "still", "dp": DP, "t_end": 20 * math.sqrt(D / 9.81), "still_water_level": D,
        "tank": {"x0": 0.0, "x1": 2 * D, "z0": 0.0, "z1": 1.6 * D},
        "water_blocks": [{"x0": 0.0, "x1": 2 * D, "z0": 0.0, "z1": D}],
        "output": {"probe_every": 0.05},
        "probes": [{"kind": "point", "name": f"p{k}", "x": D, "z": z} for k, z in enumerate(PROBE_Z)]
                  + [{"kind": "elevation", "name": "g", "x": 0.6 * D}],
        "scheme": SCHEMES[request.param],
    })
    sim = Simulation(scene)
    m0, n0 = sim.fluid_state()["m"], sim.n_fluid
    speeds = []
    while sim.t < scene.t_end:
        sim.advance_to(min(sim.t + 0.1, scene.t_end))
        st = sim.fluid_state()
        speeds.append((sim.t, float(np.hypot(st["vx"], st["vz"]).max())))
    return sim, scene, m0, n0, np.array(speeds)


def test_pressure_stays_hydrostatic(still_run, request):
    if request.node.callspec.params["still_run"] == "isph":
        request.applymarker(pytest.mark.xfail(strict=True, reason=ISPH_PRESSURE))
    sim, scene, *_ = still_run
    rho0, g = scene.constants.rho0, scene.constants.g
    late = [r for r in sim.history if r["t"] >= 0.5 * scene.t_end]
    assert len(late) > 10
    for k, z in enumerate(PROBE_Z):
        exact = rho0 * g * (D - z)
        errors = [abs(r[f"p{k}_p"] / exact - 1) for r in late]
        assert max(errors) < 0.03, f"probe z={z}: pressure off by {100 * max(errors):.2f} %"


def test_spurious_speed_small(still_run):
    sim, scene, _, _, speeds = still_run
    limit = 0.01 * math.sqrt(scene.constants.g * D)
    late = speeds[speeds[:, 0] >= 0.5 * scene.t_end, 1]
    assert late.max() < limit, f"max speed {late.max():.4g} m/s >= 1 % of sqrt(g d)"


def test_mass_and_particles_conserved_and_in_tank(still_run):
    sim, scene, m0, n0, _ = still_run
    assert sim.n_fluid == n0
    # every particle keeps its exact mass (compared by id; a float sum would depend on the order)
    np.testing.assert_array_equal(sim.fluid_state()["m"], m0)
    st = sim.fluid_state()
    t = scene.tank
    assert np.all((st["x"] > t.x0) & (st["x"] < t.x1) & (st["z"] > t.z0))


def test_surface_gauge_reads_still_water_level(still_run):
    sim, scene, *_ = still_run
    eta = sim.probe_values()["g_eta"]
    assert abs(eta) < 0.25 * DP, f"still-water gauge reads eta = {eta:.4g} m"
