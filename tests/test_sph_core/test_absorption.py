"""The open ends' absorption gain (sph_core.absorption), how a flume picks it, and the retired
absorption options' scene errors."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sph_core import open_boundary as ob
from sph_core.absorption import (absorption_filter, correction_profile, filter_reflection,
                                 linear_wavenumber, profile_wavenumber, source_period,
                                 transfer_gain)
from sph_core.boundary_data import WaveModelBoundary
from sph_core.open_ends import OpenBoundaries, flume_nodes
from sph_core.scene import SceneError, make_scene
from sph_core.state import closed_ends
from wave_client.theories import build_theory
from wave_client.theories import wavenumber as theory_wavenumber

G, D = 9.81, 0.3


def _piston(period: float | None) -> float:
    """Biesel's piston gain at the wave period (sqrt(g/d), its long-wave limit, for None)."""
    if period is None:
        return math.sqrt(G / D)
    omega = 2 * math.pi / period
    return float(transfer_gain(omega, linear_wavenumber(omega, D, G) * D))


@pytest.mark.parametrize("kd", [0.3, 0.75, 1.2, 2.0])
def test_piston_gain_swallows_the_progressive_mode(kd):
    """Biesel's gain: a depth-uniform U cancels an outgoing Airy wave of amplitude a at the end
    iff U and the wave's u(z) = a omega cosh k(z+d)/sinh kd have the same projection on the
    progressive mode cosh k(z+d) (the rest goes into evanescent modes, which carry no wave
    away); both integrals done numerically here. Above the depth-mean velocity omega/(k d)
    (the retired "flux" transfer) by 19 % at kd 2."""
    k = kd / D
    omega = math.sqrt(G * k * math.tanh(kd))
    gain = _piston(2 * math.pi / omega)
    n = 4000
    zs = [D * (j + 0.5) / n for j in range(n)]  # height above the bed
    wave = sum(omega * math.cosh(k * z) ** 2 / math.sinh(kd) for z in zs)
    mode = sum(math.cosh(k * z) for z in zs)
    assert gain == pytest.approx(wave / mode, rel=1e-6)
    flux = omega / kd
    assert gain > flux
    if kd == 2.0:
        assert gain / flux == pytest.approx(1.19, abs=0.005)


@pytest.mark.parametrize("q", [0.0, 0.8, 2.0])
@pytest.mark.parametrize("kd", [0.3, 1.2, 2.0])
def test_profiled_gain_swallows_the_progressive_mode(q, kd):
    """A correction U P(z) with the mode profile of a wave of kd q (depth mean 1) cancels an
    outgoing Airy wave of amplitude a iff U P and the wave's u(z) have the same projection on
    cosh k(z + d): G = omega int phi^2 / (sinh kd int P phi), integrated numerically here. At
    its own wave (q = kd) the profile is the wave's, and G is the flux gain omega/(k d)."""
    k = kd / D
    omega = math.sqrt(G * k * math.tanh(kd))
    n = 4000
    s = (np.arange(n) + 0.5) / n  # height above the bed / d
    prof = correction_profile(s, q)
    assert prof.mean() == pytest.approx(1.0, rel=1e-6)  # same flux as the piston
    phi = np.cosh(kd * s)
    want = omega * np.sum(phi ** 2) / (math.sinh(kd) * np.sum(prof * phi))
    assert transfer_gain(omega, kd, q) == pytest.approx(want, rel=1e-6)
    if q == kd:
        assert transfer_gain(omega, kd, q) == pytest.approx(omega / kd, rel=1e-9)
        # the surface velocity per unit elevation is Airy's omega / tanh kd
        assert want * prof[-1] == pytest.approx(omega / math.tanh(kd), rel=2e-3)
    if q == 0.0:  # Biesel's closed form
        assert transfer_gain(omega, kd, q) == pytest.approx(
            omega * (math.sinh(2 * kd) + 2 * kd) / (4 * math.sinh(kd) ** 2), rel=1e-9)
    with pytest.raises(ValueError, match="profile_kd"):
        transfer_gain(omega, kd, -1.0)


def test_mode_profile_of_the_flume_is_its_wave_period():
    """The ends' correction profile is cosh k(z + d) at the source's period (k from linear
    dispersion), depth mean 1 below still water; all ones (a piston) with no period known;
    the filter is then fitted to the profiled gain, exact at the wave period."""
    ends = _ends()
    kd0 = linear_wavenumber(2 * math.pi, D, G) * D
    assert profile_wavenumber(G, D, 1.0) == pytest.approx(kd0)
    assert profile_wavenumber(G, D, None) == 0.0
    zn = ends.ends.zn[1]
    want = np.cosh(kd0 * zn / D) * kd0 / math.sinh(kd0)
    assert np.allclose(ends.ends.corr_prof[1], want, rtol=1e-12)
    assert (_ends(sources=False).ends.corr_prof == 1.0).all()
    e = ends.ends
    refl = filter_reflection(e.sqgd[1], e.filt_tau[1], e.filt_c[1], G, D,
                             abs(ends.nodes["right"].x_gauge - ends.nodes["right"].x_face),
                             np.array([kd0]), kd0)
    assert refl[0] < 1e-3
    with pytest.raises(ValueError, match="period"):
        profile_wavenumber(G, D, -1.0)


def test_piston_gain_tends_to_the_shallow_water_gain_for_long_waves():
    shallow = math.sqrt(G / D)
    for period, tol in ((20.0, 2e-3), (200.0, 2e-5)):  # kd ~ 0.08, 0.008: error ~ (kd)^2 / 6
        assert _piston(period) == pytest.approx(shallow, rel=tol)


def test_wavenumber_agrees_with_the_wave_client_dispersion():
    for period in (0.5, 1.4, 3.0):
        omega = 2 * math.pi / period
        assert linear_wavenumber(omega, D, G) == pytest.approx(float(theory_wavenumber(omega, D)),
                                                        rel=1e-6)


def _ideal(omega: float, delay: float) -> complex:
    """The ideal correction per unit mismatch: the piston gain G(omega), delayed by delay/c."""
    k = linear_wavenumber(omega, D, G)
    return _piston(2 * math.pi / omega) * np.exp(-1j * k * delay)


@pytest.mark.parametrize("period", [0.7, 1.0, 2.5, None])
def test_filter_follows_the_linear_gain_per_frequency(period):
    """Exact (delayed) piston gain at the wave period; over kd 0.3-2 the gain error alone
    reflects less than 5 % (a causal three-pole fit of the piston gain: 2.5-4.7 %), where the
    plain gain of one period (the retired "linear" absorption) reflects more than 10 % away
    from it."""
    delay = 0.03
    d_gain, tau, c = absorption_filter(G, D, delay, period)
    kd = np.linspace(0.3, 2.0, 40)
    refl = filter_reflection(d_gain, tau, c, G, D, delay, kd)
    assert refl.max() < 0.05
    lin = _piston(period)
    assert filter_reflection(lin, tau, 0 * c, G, D, delay, kd).max() > 0.1
    if period is not None:
        kd0 = linear_wavenumber(2 * math.pi / period, D, G) * D
        assert filter_reflection(d_gain, tau, c, G, D, delay, np.array([kd0]))[0] < 1e-3
    # the gain at omega -> 0 stays near the long-wave limit sqrt(g/d) (a mean level is absorbed)
    assert 0.6 < (d_gain + c.sum()) / math.sqrt(G / D) < 1.1


def test_jitted_filter_has_the_designed_frequency_response():
    """Step the open end's correction through a sinusoidal mismatch e = a sin(omega t): once the
    start-up has died out, du is the designed response H(omega) applied to e, and it follows the
    ideal delayed linear gain to the fit's accuracy."""
    delay, period, dt, a = 0.03, 2.5, 2e-4, 0.01
    omega = 2 * math.pi / 0.94  # kd 1.5, far from the wave period's 0.47: the fitted band
    e = closed_ends(capacity=1)._replace(active=True)
    e.on[:] = e.absorb[:] = e.imposed[:] = True
    e.swl[:] = D
    e.z_top[:] = 2 * D
    e.sqgd[0], e.filt_tau[0], e.filt_c[0] = absorption_filter(G, D, delay, period)
    t = np.arange(0.0, 30.0, dt)
    du = np.empty(t.size)
    for i, ti in enumerate(t):
        e.eta_meas[0] = a * math.sin(omega * ti)
        du[i] = ob.boundary_state(0, 0.5, dt, e)[1]
    last = t > t[-1] - 4 * 0.94
    basis = np.column_stack([np.sin(omega * t[last]), np.cos(omega * t[last])])
    s, co = np.linalg.lstsq(basis, du[last], rcond=None)[0]
    got = -(s + 1j * co) / a  # du = n_x H e with n_x = -1 at the left end: sin -> Re, cos -> Im
    h_fit = e.sqgd[0] + sum(cj / (1 + 1j * omega * tj) for cj, tj in zip(e.filt_c[0], e.filt_tau[0]))
    assert abs(got - h_fit) < 2e-3 * abs(h_fit)  # the exact exponential update: round-off only
    assert abs(got / _ideal(omega, delay) - 1) < 0.2  # the fit (reflection < 10 %)


def test_checkpoint_keeps_the_filter_state():
    ends = _ends()
    assert ends.ends.filt_c.any()
    ends.ends.filt_x[:] = 0.25
    saved = ends.state()
    ends.ends.filt_x[:] = -1.0
    ends.set_state(saved)
    assert (ends.ends.filt_x == 0.25).all()


def _ends(period_field: float | None = None, sources: bool = True) -> OpenBoundaries:
    """A 0.6 m flume's open ends, both sides driven by a linear wave of period 1 s (or none)."""
    sides = [{"side": s, "elevation": e, "absorption_period": period_field}
             for s, e in (("left", "imposed"), ("right", "extrapolated"))]
    scene = make_scene({
        "dp": 0.02, "t_end": 1.0, "still_water_level": D,
        "tank": {"x0": 0.0, "x1": 0.6, "z0": 0.0, "z1": D + 0.12},
        "water_blocks": [{"x0": 0.0, "x1": 0.6, "z0": 0.0, "z1": D}],
        "constants": {"c0": 10.0 * math.sqrt(G * D)}, "open_boundaries": sides})
    if not sources:
        return OpenBoundaries.from_scene(scene, None, 0.02)
    model = build_theory("linear", height=0.01, period=1.0, depth=D, ramp_time=1.0)
    return OpenBoundaries.from_scene(scene, {side: WaveModelBoundary(model, nd, D, nd.x_face)
                                             for side, nd in flume_nodes(scene).items()}, 0.02)


def test_flume_takes_the_filter_of_the_source_period_or_its_scene():
    """The filter is fitted at the source theory's period, or at the scene's absorption_period,
    to the gain of the mode profile of that period, delayed by the gauge's offset."""
    ends = _ends()
    assert source_period(ends.sources["left"]) == 1.0
    for period, e in ((1.0, ends), (2.5, _ends(2.5))):
        q = profile_wavenumber(G, D, period)
        for b, side in enumerate(("left", "right")):
            nd = e.nodes[side]
            d_gain, tau, c = absorption_filter(G, D, abs(nd.x_gauge - nd.x_face), period, q)
            assert e.ends.sqgd[b] == d_gain
            np.testing.assert_array_equal(e.ends.filt_c[b], c)
            np.testing.assert_array_equal(e.ends.filt_tau[b], tau)


@pytest.mark.parametrize("key, value", [("absorption", "shallow"), ("absorption", "linear"),
                                        ("absorption_transfer", "flux"),
                                        ("absorption_profile", "uniform"),
                                        ("surface", "gauge")])
def test_retired_absorption_options_name_their_decision_page(key, value):
    """Each retired value is refused naming docs/decisions/<key>.md; the surviving default,
    written explicitly, is still accepted (and is what the end does)."""
    base = {"dp": 0.02, "t_end": 1.0, "still_water_level": D,
            "tank": {"x0": 0.0, "x1": 0.6, "z0": 0.0, "z1": D + 0.12},
            "water_blocks": [{"x0": 0.0, "x1": 0.6, "z0": 0.0, "z1": D}]}
    end = {"side": "right", "elevation": "extrapolated"}
    with pytest.raises(SceneError, match=rf"open_boundaries\.0\.{key}: '{value}' was measured "
                                         rf"and retired \(see docs/decisions/{key}\.md\)"):
        make_scene({**base, "open_boundaries": [{**end, key: value}]})
    kept = {"absorption": "filter", "absorption_transfer": "piston", "absorption_profile": "mode",
            "surface": "face"}[key]
    explicit = make_scene({**base, "open_boundaries": [{**end, key: kept}]})
    assert explicit == make_scene({**base, "open_boundaries": [end]})
