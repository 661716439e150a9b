"""The pieces behind the flume figures: the seed 002 correction, the boundary profile
interpolation, the outlet's ghost-node interpolation, the reflection analysis and the RMSE."""

from __future__ import annotations

import math

import numpy as np
import pytest

from wavesph.analysis import (reflected_wave, reflection_coefficient, rmse_over_height,
                              separate_harmonics)
from sph_core import open_boundary as ob
from sph_core.particles import FLUID, P, X, Z
from sph_core.scene import make_scene
from sph_core.simulation import Simulation
from sph_core.state import closed_ends

G, D = 9.81, 0.5


def ends(eta_th: np.ndarray, meas: np.ndarray, absorb: bool = True,
         imposed: tuple[bool, bool] = (True, False)):
    """Two open ends over a flat bed, still water D, window elevations eta_th[end, level] (the
    source's gauge elevation the same), measured gauge elevations meas[end]."""
    e = closed_ends(capacity=1)
    e.on[:] = True
    e.swl[:] = D
    e.sqgd[:] = math.sqrt(G / D)
    e.absorb[:] = absorb
    e.imposed[:] = imposed
    e.z_top[:] = 2 * D
    e.win_eta[:] = eta_th
    e.win_etag[:] = eta_th
    e.eta_meas[:] = meas
    return e._replace(active=True)


def test_seed_002_corrections_have_the_published_signs():
    """v_in = v_th - (eta_in,meas - eta_th) sqrt(g/d);
    v_out = v_th - (eta_th - eta_out,meas) sqrt(g/d)."""
    eta_th = np.array([[0.01, 0.01], [0.02, 0.02]])  # [end, window level]
    meas = np.array([0.03, 0.05])
    zs_in, du_in = ob.boundary_state(0, 0.5, 1e-4, ends(eta_th, meas))
    zs_out, du_out = ob.boundary_state(1, 0.5, 1e-4, ends(eta_th, meas))
    assert du_in == pytest.approx(-(0.03 - 0.01) * math.sqrt(G / D))
    assert du_out == pytest.approx(-(0.02 - 0.05) * math.sqrt(G / D))
    # inlet: imposed surface; outlet: extrapolated (measured) surface
    assert zs_in == pytest.approx(D + 0.01) and zs_out == pytest.approx(D + 0.05)
    # correction off, or a dry gauge (NaN): theory only
    assert ob.boundary_state(0, 0.5, 1e-4, ends(eta_th, meas, absorb=False))[1] == 0.0
    zs, du = ob.boundary_state(1, 0.5, 1e-4, ends(eta_th, np.array([np.nan, np.nan])))
    assert du == 0.0 and zs == pytest.approx(D + 0.02)


def test_profile_is_linear_in_z_and_in_time_and_clamped_at_the_ends():
    zn = np.array([0.0, 0.1, 0.2])
    a = np.array([[0.0, 1.0, 2.0], [10.0, 11.0, 12.0]])  # [window level, node]
    assert ob.profile_value(zn, a, 0.0, 0.05) == pytest.approx(0.5)
    assert ob.profile_value(zn, a, 0.25, 0.15) == pytest.approx(0.75 * 1.5 + 0.25 * 11.5)
    assert ob.profile_value(zn, a, 1.0, 0.5) == pytest.approx(12.0)
    assert ob.profile_value(zn, a, 0.0, -0.1) == pytest.approx(0.0)
    assert ob.window_weight(1.5, np.array([1.0, 3.0])) == pytest.approx(0.25)


def test_ghost_node_interpolation_reproduces_a_linear_field_exactly():
    """First-order consistency: p = a + b x + c z on disordered fluid is returned with its
    gradient to round-off, inside the fluid, with half a support (at the face of an outlet) and
    at a corner; a node with no fluid says so."""
    dp = 0.02
    sim = Simulation(make_scene({
        "dp": dp, "t_end": 1.0, "still_water_level": 0.3,
        "tank": {"x0": 0.0, "x1": 0.6, "z0": 0.0, "z1": 0.4},
        "water_blocks": [{"x0": 0.0, "x1": 0.6, "z0": 0.0, "z1": 0.3}]}))
    ps = sim.particles
    f, kind = ps.f, ps.kind[: ps.n]
    fl = kind == FLUID
    rng = np.random.default_rng(3)
    # disorder the lattice in place (cells stay valid: shifts are far below a cell)
    f[X, : ps.n][fl] += rng.uniform(-0.3, 0.3, fl.sum()) * dp
    f[Z, : ps.n][fl] += rng.uniform(-0.3, 0.3, fl.sum()) * dp
    a, b, c = 50.0, 300.0, -9810.0
    f[P, : ps.n][fl] = a + b * f[X, : ps.n][fl] + c * f[Z, : ps.n][fl]
    for xg, zg in [(0.3, 0.15), (0.6, 0.15), (0.59, 0.01), (0.3, 0.29)]:
        pg, px, pz, order = ob.ghost_pressure(ps.view, sim.cells, xg, 0.0, zg, sim.prm)
        assert order == 1, (xg, zg)
        assert pg == pytest.approx(a + b * xg + c * zg, rel=1e-9, abs=1e-6), (xg, zg)
        assert (px, pz) == pytest.approx((b, c), rel=1e-7), (xg, zg)
    assert ob.ghost_pressure(ps.view, sim.cells, 0.3, 0.0, 0.39, sim.prm)[3] == -1


def test_decay_aware_reflection_fit_separates_damping_from_reflection():
    """Incident and reflected waves both damped at 0.07 /m (case V at H/dp = 3): the decay-aware
    fit over nine gauges recovers K_R at the array centre, the plain fit does not."""
    period, k, a_i, delta = 2.0, 2 * math.pi / 3.32, 0.025, 0.07
    omega = 2 * math.pi / period
    t = np.arange(0.0, 3 * period, period / 40)
    xs = 1.66 + np.arange(-4, 5) * 3.32 / 16
    xc = xs - 1.66
    for kr in (0.0, 0.03):
        etas = np.array([a_i * np.exp(-delta * x) * np.cos(k * x - omega * t)
                         + kr * a_i * np.exp(delta * x) * np.cos(k * x + omega * t + 0.7)
                         for x in xc])
        got, inc, _ = reflection_coefficient(t, etas, xs, period, k, decay=True)
        assert got == pytest.approx(kr, abs=1e-6)
        assert inc == pytest.approx(a_i, rel=1e-6)
        plain = reflection_coefficient(t, etas[[2, 4, 6]], xs[[2, 4, 6]], period, k)[0]
        assert abs(plain - kr) > 0.01, plain


@pytest.mark.parametrize("kr", [0.0, 0.2, 0.6])
def test_reflection_coefficient_recovers_a_known_reflection(kr):
    period, k, a_i = 2.0, 2 * math.pi / 3.0, 0.03
    omega = 2 * math.pi / period
    t = np.arange(0.0, 3 * period, period / 40)
    xs = np.array([1.0, 1.375, 1.75])
    etas = np.array([a_i * np.cos(k * x - omega * t) + kr * a_i * np.cos(k * x + omega * t + 0.7)
                     + 0.002 * np.cos(2 * (k * x - omega * t)) for x in xs])
    got, inc, ref = reflection_coefficient(t, etas, xs, period, k)
    assert got == pytest.approx(kr, abs=1e-6)
    assert inc == pytest.approx(a_i, rel=1e-6)


def test_separation_per_harmonic_with_noise_and_a_decaying_incident_wave():
    """Mansard & Funke per harmonic: a decaying incident wave (0.1 /m, the SPH flume at H/dp 4) with a bound second
    harmonic (wavenumber 2k), each reflected with its own K_R and phase, plus white noise of 5 %
    of the incident amplitude: both K_R and the decay come back within the noise's reach; the
    plain three-gauge fit of the same records reads a wrong K_R (the decay as reflection)."""
    period, wl, a_i, delta = 1.4, 2.4, 0.02, 0.1
    k, omega = 2 * math.pi / wl, 2 * math.pi / 1.4
    kr1, kr2, a2 = 0.04, 0.10, 0.004
    t = np.arange(0.0, 5 * period, period / 40)
    xs = 3.0 + np.arange(-4, 5) * wl / 16
    xc = xs - 3.0
    rng = np.random.default_rng(11)
    etas = np.array([a_i * np.exp(-delta * x) * np.cos(k * x - omega * t + 0.3)
                     + kr1 * a_i * np.exp(delta * x) * np.cos(k * x + omega * t - 1.1)
                     + a2 * np.cos(2 * (k * x - omega * t) + 0.5)
                     + kr2 * a2 * np.cos(2 * (k * x + omega * t) + 2.0)
                     + 0.05 * a_i * rng.standard_normal(t.size) for x in xc])
    first, second = separate_harmonics(t, etas, xs, period, [k, 2 * k], decay=True)
    assert first.kr == pytest.approx(kr1, abs=0.005)
    assert first.a_incident == pytest.approx(a_i, rel=0.01)
    assert first.decay == pytest.approx(delta, abs=0.02)
    assert second.kr == pytest.approx(kr2, abs=0.03)
    assert second.a_incident == pytest.approx(a2, rel=0.05)
    assert abs(second.decay) < 0.1
    plain = separate_harmonics(t, etas[[2, 4, 6]], xs[[2, 4, 6]], period, [k])[0]
    assert abs(plain.kr - kr1) > 0.01, plain.kr


def test_two_gauge_separation_recovers_phases():
    """Goda & Suzuki's two gauges, L/4 apart: amplitudes and phases of both waves exact."""
    period, k, a_i = 2.0, 2 * math.pi / 3.0, 0.03
    omega = 2 * math.pi / period
    t = np.arange(0.0, 2 * period, period / 50)
    xs = np.array([0.0, 0.75])
    etas = np.array([a_i * np.cos(omega * t - k * x + 0.4)
                     + 0.3 * a_i * np.cos(omega * t + k * x - 0.9) for x in xs])
    s = separate_harmonics(t, etas, xs, period, [k])[0]
    assert (s.kr, s.a_incident) == pytest.approx((0.3, a_i), rel=1e-9)
    assert (s.phase_incident, s.phase_reflected) == pytest.approx((0.4, -0.9), abs=1e-9)
    with pytest.raises(ValueError, match=">= 3 gauges"):
        separate_harmonics(t, etas, xs, period, [k], decay=True)


def test_rmse_over_height_and_dry_records():
    th = np.sin(np.linspace(0, 6, 50))
    assert rmse_over_height(th + 0.01, th, 0.5) == pytest.approx(0.02)
    with pytest.raises(ValueError, match="dry"):
        rmse_over_height(np.where(th > 0.9, np.nan, th), th, 0.5)


def test_reflected_wave_leaves_the_incident_wave_and_its_harmonics():
    """A partial standing wave with a bound second harmonic at two gauges: the record at the
    first less reflected_wave there is the incident wave with its harmonic."""
    period, k, a = 1.4, 3.2, 0.02
    omega = 2 * np.pi / period
    t = np.arange(0.0, 4 * period, period / 50) + 20.0
    xs = np.array([24.0, 24.4])

    def incident(x):
        return a * np.cos(omega * t - k * x + 0.3) + 0.15 * a * np.cos(2 * (omega * t - k * x + 0.3))

    etas = np.array([incident(x) + 0.08 * a * np.cos(omega * t + k * x + 1.0) for x in xs])
    sep = separate_harmonics(t, etas, xs, period, [k])[0]
    left = etas[0] - reflected_wave(sep, t, period, k, xs[0])
    np.testing.assert_allclose(left, incident(xs[0]), atol=1e-9 * a)
    assert rmse_over_height(etas[0], incident(xs[0]), 2 * a) > 0.02   # what was taken out
