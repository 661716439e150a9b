"""Rigid bodies in the SPH zone (issue 14): loads, conservation, hinge dynamics, outputs."""

from __future__ import annotations

import csv
import math

import numpy as np
import pytest

from wavesph.cases.rigid_bodies import (archimedes_draft, box_draft, flap_hydrodynamics,
                                floating_box_scene, hinged_flap_scene, spring_flap_in_water,
                                spring_flap_period, zero_crossing_period, zero_gravity)
from sph_core.particles import FLUID, M, VX, VZ
from sph_core.scene import SceneError, make_scene
from sph_core.simulation import Simulation


def _momentum(sim: Simulation) -> np.ndarray:
    ps = sim.particles
    fl = ps.mask(FLUID)
    m = ps.field(M)[fl]
    bd = sim.bodies.state
    return np.array([np.sum(m * ps.field(VX)[fl]) + np.sum(bd.mass * bd.qd[:, 0]),
                     np.sum(m * ps.field(VZ)[fl]) + np.sum(bd.mass * bd.qd[:, 1])])


def test_scene_bodies_are_validated() -> None:
    base = {"dp": 0.02, "t_end": 1.0, "tank": {"x0": 0, "x1": 1, "z0": 0, "z1": 1},
            "water_blocks": [{"x0": 0, "x1": 1, "z0": 0, "z1": 0.5}]}
    with pytest.raises(SceneError, match="mass"):
        make_scene({**base, "bodies": [{"name": "b", "shape": "box", "x0": 0.4, "x1": 0.6,
                                        "z0": 0.4, "z1": 0.6}]})
    with pytest.raises(SceneError, match="pivot"):
        make_scene({**base, "bodies": [{"name": "b", "shape": "wedge", "apex": (0.5, 0.6),
                                        "breadth": 0.2, "deadrise_deg": 30, "mass": 1.0,
                                        "motion": "hinged"}]})
    s = make_scene({**base, "bodies": [{"name": "w", "shape": "wedge", "apex": (0.5, 0.6),
                                        "breadth": 0.2, "deadrise_deg": 30, "mass": 1.0}]})
    assert s.bodies[0].motion == "free"


def test_box_mass_inertia_and_particles_from_shape() -> None:
    sim = Simulation(floating_box_scene(dp=0.02, breadth=0.4, height=0.2, density=500.0))
    p = sim.bodies.properties[0]
    assert p["mass"] == pytest.approx(500.0 * 0.4 * 0.2)
    assert p["inertia_com"] == pytest.approx(p["mass"] * (0.4 ** 2 + 0.2 ** 2) / 12.0)
    # no fluid particle inside the box, and no body particle outside it
    ps = sim.particles
    fl = ps.mask(FLUID)
    x, z = ps.field(0)[fl], ps.field(1)[fl]
    b = sim.scene.bodies[0]
    assert not np.any((x > b.x0) & (x < b.x1) & (z > b.z0) & (z < b.z1))
    assert np.all((sim.bodies.x > b.x0) & (sim.bodies.x < b.x1))


def test_hydrostatic_load_on_a_box_is_archimedes() -> None:
    """At t = 0 (hydrostatic fluid) the summed particle loads on a box at its draft d equal
    rho0 g B d, and no horizontal force or moment (symmetry)."""
    sim = Simulation(floating_box_scene(dp=0.02, breadth=0.4, height=0.2, density=500.0))
    fx, fz, my = sim.bodies.state.load[0]
    ref = 1000.0 * 9.81 * 0.4 * archimedes_draft(500.0, 0.2)
    assert fz == pytest.approx(ref, rel=0.02)
    assert abs(fx) < 1e-6 * ref and abs(my) < 1e-6 * ref * 0.4


@pytest.mark.parametrize("integrator,wall_av", [("kdk", 1.0), ("symplectic_pc", 1.0),
                                               ("kdk", 0.0)])
def test_fluid_plus_body_momentum_is_conserved_without_gravity(integrator: str,
                                                               wall_av: float) -> None:
    """A free box thrown through a blob of water in zero gravity, away from every wall: the
    pair forces on the body are minus those on the fluid, so the total momentum keeps to
    round-off while the body's own momentum changes by orders of magnitude more. With the wall
    artificial viscosity off (alpha_wall_factor 0) the body's loads must drop it too."""
    scene = make_scene({
        "dp": 0.02, "t_end": 1.0, "tank": {"x0": 0, "x1": 1.2, "z0": 0, "z1": 1.2},
        "water_blocks": [{"x0": 0.3, "x1": 0.9, "z0": 0.3, "z1": 0.9}],
        "constants": {"integrator": integrator, "alpha_wall_factor": wall_av},
        "bodies": [{"name": "box", "shape": "box", "x0": 0.52, "x1": 0.68, "z0": 0.52,
                    "z1": 0.6, "density": 800.0, "velocity": (0.5, -0.3, 1.0)}]})
    sim = Simulation(scene)
    zero_gravity(sim)
    p0 = _momentum(sim)
    body0 = sim.bodies.state.mass[0] * sim.bodies.state.qd[0, :2].copy()
    sim.advance_steps(150)
    p1 = _momentum(sim)
    body1 = sim.bodies.state.mass[0] * sim.bodies.state.qd[0, :2]
    scale = np.linalg.norm(body0)
    assert np.linalg.norm(body1 - body0) > 1e-2 * scale   # the fluid did push the body
    assert np.linalg.norm(p1 - p0) < 1e-10 * scale


@pytest.mark.parametrize("integrator", ["kdk", "symplectic_pc"])
def test_spring_flap_in_air_oscillates_at_the_hinge_period(integrator: str) -> None:
    """Hinge dynamics (inertia about the pivot, gravity moment, spring) with no fluid on the flap:
    period within 0.5 % of 2 pi sqrt(I_p / (k - m g h_c))."""
    k = 40.0
    ref = spring_flap_period(0.04, 0.4, 500.0, k)
    sim = Simulation(hinged_flap_scene(dp=0.02, spring=k, omega0=0.05, in_water=False,
                                       t_end=2.2 * ref, integrator=integrator,
                                       probe_every=ref / 100))
    sim.advance_to(sim.scene.t_end)
    t = np.array([r["t"] for r in sim.body_history])
    th = np.array([r["flap_theta"] for r in sim.body_history])
    assert zero_crossing_period(t, th) == pytest.approx(ref, rel=0.005)
    assert np.max(np.abs(sim.bodies.state.load)) == 0.0   # no fluid reached it


def test_flap_added_inertia_and_radiation_damping() -> None:
    """Linear wavemaker theory of a bottom-hinged flap: at high frequency the added inertia tends
    to the free-surface-rigid (phi = 0) limit 4 rho sum_n C_n^2 / (k_n h), k_n = (2n+1) pi / 2h,
    and the radiation damping carries exactly the energy flux of the two radiated waves,
    <P> = b omega^2 Theta^2 / 2 = 2 * rho g |eta|^2 c_g / 2, |eta| = omega |A_0| cosh(k0 h) / g."""
    h, rho, g = 0.3, 1000.0, 9.81
    k = (2 * np.arange(4000) + 1) * np.pi / (2 * h)
    c = h * (-1.0) ** np.arange(4000) / k - 1 / k ** 2
    a_inf = 4 * rho * np.sum(c ** 2 / (k * h))
    a_hi, _ = flap_hydrodynamics(200.0, h)
    assert a_hi == pytest.approx(a_inf, rel=0.01)
    omega = 8.0
    a, b = flap_hydrodynamics(omega, h)
    from scipy.optimize import brentq
    k0 = brentq(lambda kk: kk * math.tanh(kk * h) - omega ** 2 / g, 1e-6, 100.0)
    c0 = h * math.sinh(k0 * h) / k0 - (math.cosh(k0 * h) - 1) / k0 ** 2
    n0 = h / 2 + math.sinh(2 * k0 * h) / (4 * k0)
    amp = omega * c0 / (k0 * n0)                          # |A_0| per unit Theta
    eta = omega * amp * math.cosh(k0 * h) / g
    cg = 0.5 * omega / k0 * (1 + 2 * k0 * h / math.sinh(2 * k0 * h))
    assert 0.5 * b * omega ** 2 == pytest.approx(rho * g * eta ** 2 * cg, rel=1e-9)
    assert 0 < a < a_inf
    ref = spring_flap_in_water(0.04, 0.4, 500.0, 600.0, h)
    assert ref["zeta"] < 0.1 and ref["added_inertia"] > ref["inertia"]   # a real hydro test


@pytest.mark.parametrize("period", [0.8, 1.4, 3.0])
def test_flap_excitation_and_damping_obey_the_half_absorption_limit(period: float) -> None:
    """Haskind, by energy: a 2D body radiating equally to both sides absorbs at best half the
    incident wave power, |X|^2 / (8 b) = (rho g A^2 c_g / 2) / 2, so b = |X|^2 / (2 rho g A^2
    c_g): the excitation (flap held fixed, total reflection) and the radiation damping
    (eigenfunction expansion) are computed independently and must agree."""
    from wavesph.cases.rigid_bodies import _flap_wavenumbers, flap_wave_response

    h, g, rho, amp = 0.3, 9.81, 1000.0, 0.05
    r = flap_wave_response(0.04, 0.4, 500.0, 0.0, h, 2 * amp, period)
    w = 2 * math.pi / period
    k0, _ = _flap_wavenumbers(w, h, g, 1)
    cg = 0.5 * w / k0 * (1 + 2 * k0 * h / math.sinh(2 * k0 * h))
    assert r["damping"] == pytest.approx(r["excitation"] ** 2 / (2 * rho * g * amp ** 2 * cg),
                                         rel=1e-9)


def test_hinged_flap_in_still_water_stays_at_rest() -> None:
    """A buoyant flap (density 500) through the still-water surface: hydrostatic moments on both
    sides cancel; it may not drift from upright by more than 1e-3 rad in 1 s."""
    sim = Simulation(hinged_flap_scene(dp=0.02, t_end=1.0))
    sim.advance_to(1.0)
    th = np.array([r["flap_theta"] for r in sim.body_history])
    assert np.max(np.abs(th)) < 1e-3


def test_prescribed_body_follows_its_series_and_checkpoint_restores_it(tmp_path) -> None:
    scene = make_scene({
        "dp": 0.02, "t_end": 0.2, "tank": {"x0": 0, "x1": 1.0, "z0": 0, "z1": 0.6},
        "water_blocks": [{"x0": 0, "x1": 1.0, "z0": 0, "z1": 0.3}],
        "output": {"probe_every": 0.02, "snapshot_every": 0.1},
        "bodies": [{"name": "plate", "shape": "box", "x0": 0.4, "x1": 0.6, "z0": 0.26,
                    "z1": 0.36, "motion": "prescribed",
                    "series": [(0.0, 0.0, 0.0, 0.0), (0.2, 0.02, -0.01, 0.05)]}]})
    sim = Simulation(scene, run_dir=tmp_path)
    sim.advance_to(0.1)
    c = sim.checkpoint()
    sim.advance_to(0.2)
    q_end = sim.bodies.state.q[0].copy()
    ref = np.array([0.5 + 0.02, 0.31 - 0.01, 0.05])
    assert q_end == pytest.approx(ref, abs=1e-12)
    sim.restore(c)
    sim.advance_to(0.2)
    assert np.array_equal(sim.bodies.state.q[0], q_end)
    sim.close()
    rows = list(csv.DictReader(open(tmp_path / "bodies.csv")))
    assert float(rows[-1]["plate_x"]) == pytest.approx(0.52, abs=1e-12)
    assert math.isfinite(float(rows[-1]["plate_fz"]))
    from pyevtk.vtk import VtkFile  # noqa: F401  (pyevtk present: snapshots were written)
    vtu = sorted((tmp_path / "snapshots").glob("*.vtu"))
    assert vtu and b'Name="body"' in vtu[-1].read_bytes()


def test_probes_follow_a_body() -> None:
    """A point probe and a pressure line with ``follow`` move rigidly with a prescribed body
    (translation and rotation): at the end they read what fixed probes at the moved points
    read, and they differ from their start points' values."""
    from sph_core.scene import SceneError

    dx, dz, dth = 0.06, -0.02, 0.2
    p0, line0 = (0.5, 0.2), [(0.45, 0.22), (0.55, 0.24)]
    c, s = math.cos(dth), math.sin(dth)
    ref = (0.5, 0.31)                                         # the plate's centre of mass

    def moved(pt):
        rx, rz = pt[0] - ref[0], pt[1] - ref[1]
        return (ref[0] + dx + c * rx - s * rz, ref[1] + dz + s * rx + c * rz)

    base = {"dp": 0.02, "t_end": 0.1, "tank": {"x0": 0, "x1": 1.0, "z0": 0, "z1": 0.6},
            "water_blocks": [{"x0": 0, "x1": 1.0, "z0": 0, "z1": 0.3}],
            "output": {"probe_every": 0.05},
            "bodies": [{"name": "plate", "shape": "box", "x0": 0.4, "x1": 0.6, "z0": 0.26,
                        "z1": 0.36, "motion": "prescribed",
                        "series": [(0.0, 0.0, 0.0, 0.0), (0.1, dx, dz, dth)]}]}
    with pytest.raises(SceneError, match="follow"):
        make_scene({**base, "probes": [{"kind": "point", "name": "a", "x": 0.5, "z": 0.2,
                                        "follow": "nobody"}]})
    probes = [{"kind": "point", "name": "a", "x": p0[0], "z": p0[1], "follow": "plate"},
              {"kind": "point", "name": "a_fixed", "x": moved(p0)[0], "z": moved(p0)[1]},
              {"kind": "point", "name": "a_start", "x": p0[0], "z": p0[1]},
              {"kind": "pressure_line", "name": "l", "points": line0, "follow": "plate"},
              {"kind": "pressure_line", "name": "l_fixed", "points": [moved(q) for q in line0]}]
    sim = Simulation(make_scene({**base, "probes": probes}))
    sim.advance_to(0.1)
    v = sim.probe_values()
    same = {"rel": 1e-9, "abs": 1e-9}   # the points agree to round-off, not bit for bit
    for a, b in (("a_u", "a_fixed_u"), ("a_w", "a_fixed_w"), ("a_p", "a_fixed_p"),
                 ("l_p0", "l_fixed_p0"), ("l_p1", "l_fixed_p1")):
        assert v[a] == pytest.approx(v[b], **same)
    assert abs(v["a_p"] - v["a_start_p"]) > 10.0    # it moved 0.06 m: not the start point's


@pytest.mark.slow
def test_floating_box_settles_at_the_archimedes_draft() -> None:
    """Box (B 0.4 m, H 0.2 m, 500 kg/m^3: draft 0.1 m = 5 dp) released 0.02 m too deep, heave
    only, with a heave damper (no force at rest) so it settles; its mean draft over the last
    0.5 s, below the level the closed tank's water has, within 1 % of rho_b H / rho0."""
    sim = Simulation(floating_box_scene(dp=0.02, offset=0.02, damper=800.0, t_end=2.0))
    sim.advance_to(2.0)
    t = np.array([r["t"] for r in sim.body_history])
    zb = np.array([r["box_z"] for r in sim.body_history]) - 0.1
    draft = box_draft(sim, z_bottom=zb)[t > 1.5].mean()
    assert draft == pytest.approx(archimedes_draft(500.0, 0.2), rel=0.01)


def test_example_scene_with_a_box_and_a_flap_runs() -> None:
    from pathlib import Path

    from sph_core.scene import load_scene

    path = Path(__file__).resolve().parents[2] / "examples" / "scenes" / "floating_box_and_flap.toml"
    sim = Simulation(load_scene(path))
    assert sim.bodies.names == ["box", "flap"]
    sim.advance_to(0.05)
    assert np.all(np.isfinite(sim.bodies.state.q)) and sim.body_history[-1]["box_fz"] > 0


STUDY = {"h_over_dp": 2.0, "alpha_wall_factor": 0.0}   # what the body checks need (BODIES.md)


def test_a_body_thinner_than_the_kernel_support_is_warned() -> None:
    import warnings

    from sph_core.bodies import BodySet

    with pytest.warns(UserWarning, match="thinner than the kernel support"):
        thin = BodySet(hinged_flap_scene(dp=0.02), 0.06)   # flap 0.04 m, 2h = 0.057 m
    assert thin.names == thin.thin == ["flap"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert BodySet(hinged_flap_scene(dp=0.01), 0.03).thin == []   # 2h = 0.028 m


@pytest.mark.slow
def test_floating_box_heave_period_matches_linear_potential_flow() -> None:
    """Free heave release (bench/bodies.py heave_period) at dp = 0.02 with h/dp 2 and no wall
    AV: the period measure within 5 % of linear potential flow for the same tank
    (measured 4.8 %; 0.13 % at dp = 0.01), the first crossing within 2 % (0.6 %), and the first
    half-cycle peak ratio measured between 0.5 and the linear 0.63 (0.61; with h/dp sqrt 2 it
    was 0.31: twice the damping)."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
    from bodies import heave

    r = heave(0.02, constants=STUDY)
    assert r["rel_error"] < 0.05
    assert r["first_crossing"] == pytest.approx(r["first_crossing_linear"], rel=0.02)
    assert 0.5 < r["peak_ratio"] < r["peak_ratio_linear"] + 0.02


@pytest.mark.slow
def test_spring_flap_in_still_water_oscillates_at_the_wavemaker_theory_period() -> None:
    """A bottom-hinged flap on a torsion spring in 0.3 m of still water (dp = 0.01: the 0.04 m
    flap is as thick as the kernel support, h/dp 2): the period within 5 % of linear wavemaker
    theory with the added inertia at the natural frequency (2.5 x the flap's own)."""
    ref = spring_flap_in_water(0.04, 0.4, 500.0, 600.0, 0.3)
    scene = hinged_flap_scene(dp=0.01, spring=600.0, omega0=0.5, t_end=1.0, probe_every=0.002)
    d = scene.model_dump(mode="json")
    d["constants"].update(STUDY)
    sim = Simulation(make_scene(d))
    sim.advance_to(1.0)
    t = np.array([r["t"] for r in sim.body_history])
    th = np.array([r["flap_theta"] for r in sim.body_history])
    assert zero_crossing_period(t, th) == pytest.approx(ref["period"], rel=0.05)


@pytest.mark.slow
def test_wedge_entry_impulse_between_von_karman_and_wagner() -> None:
    """Zhao et al. (1996) drop test at dp = 0.01: the fluid's impulse on the wedge since contact,
    M (V0 - V) + M g t (an integral: robust against the impact's acoustic ringing), lies between
    the added-mass momentum rho pi c^2 V / 2 of von Karman (c = zeta cot beta, no water pile-up:
    a lower bound) and of Wagner (c = pi zeta cot beta / 2: an upper bound at 30 deg deadrise)
    at both of the paper's times (measured 0.90 and 0.55 of Wagner at dp 0.01, 0.69 and 0.57 at
    dp 0.005; von Karman is 0.405)."""
    from wavesph.cases.wedge_entry import TIMES, wedge_pressures, wedge_scene

    sim = Simulation(wedge_scene(dp=0.01, constants=STUDY))
    for row in wedge_pressures(sim, TIMES, samples=3):
        assert row["impulse_von_karman"] < row["impulse_sph"] < row["impulse_wagner"]


def _isph(scene_dict: dict):
    """The scene under ISPH at its own default h/dp (sqrt 2)."""
    d = {**scene_dict, "scheme": {"kind": "isph"}}
    d["constants"] = {k: v for k, v in (d.get("constants") or {}).items() if k != "h_over_dp"}
    return make_scene(d)


@pytest.mark.slow   # 38 s for a known, measured failure: kept out of the default run's budget
@pytest.mark.xfail(strict=True, reason=(
    "ISPH: the fixed box's heave load after the first step is 0.907 x rho0 g B d (0.89-0.90 "
    "over 0.5 s): p = 0 sits on the surface particles' centres, dp/2 below the surface, a "
    "deficit of (dp/2)/d = 10 % at a draft of 5 dp (docs/studies/schemes.md '## ISPH'). Measured"))
def test_isph_hydrostatic_load_on_a_fixed_box_is_archimedes() -> None:
    """ISPH solves no pressure before its first step: the load is the first step's."""
    d = floating_box_scene(dp=0.02, breadth=0.4, height=0.2, density=500.0).model_dump()
    d["bodies"][0]["motion"] = "fixed"
    sim = Simulation(_isph(d))
    sim.advance_steps(1)
    fx, fz, my = sim.bodies.state.load[0]
    ref = 1000.0 * 9.81 * 0.4 * archimedes_draft(500.0, 0.2)
    assert abs(fx) < 1e-3 * ref and abs(my) < 1e-3 * ref * 0.4   # symmetric (measured 1e-6)
    assert fz == pytest.approx(ref, rel=0.02)


def test_isph_prescribed_body_follows_its_series_and_checkpoint_restores_it() -> None:
    """Under ISPH a prescribed body is a moving wall of the pressure equation; its motion is
    exact and a restore repeats the run bit for bit (fluid included)."""
    scene = _isph({
        "dp": 0.02, "t_end": 0.2, "tank": {"x0": 0, "x1": 1.0, "z0": 0, "z1": 0.6},
        "water_blocks": [{"x0": 0, "x1": 1.0, "z0": 0, "z1": 0.3}],
        "output": {"probe_every": 0.02},
        "bodies": [{"name": "plate", "shape": "box", "x0": 0.4, "x1": 0.6, "z0": 0.26,
                    "z1": 0.36, "motion": "prescribed",
                    "series": [(0.0, 0.0, 0.0, 0.0), (0.2, 0.02, -0.01, 0.05)]}]})
    sim = Simulation(scene)
    n0 = sim.n_fluid
    sim.advance_to(0.1)
    c = sim.checkpoint()
    sim.advance_to(0.2)
    q_end = sim.bodies.state.q[0].copy()
    first = sim.fluid_state()
    assert q_end == pytest.approx(np.array([0.5 + 0.02, 0.31 - 0.01, 0.05]), abs=1e-12)
    assert sim.n_fluid == n0 and np.all(np.isfinite(sim.bodies.state.load[0]))
    sim.restore(c)
    sim.advance_to(0.2)
    assert np.array_equal(sim.bodies.state.q[0], q_end)
    again = sim.fluid_state()
    for k in ("x", "z", "vx", "p"):
        np.testing.assert_array_equal(first[k], again[k])
