"""The Boussinesq model as a coupling partner: WaveModel contract, velocity profile, two-way
feedback by pinned nodes, absorption-only mode, checkpoint/restore."""

from __future__ import annotations

import numpy as np
import pytest

from wave_client.boussinesq import BoussinesqModel, nwogu_wavenumber
from wave_client.boussinesq.dispersion import BETA, alpha
from wave_client.model import WaveModel
from wave_client.theories import wavenumber as airy_wavenumber

G = 9.81


def flume(depth: float, period: float, left: float, right: float, sponge_right: bool = True,
          height: float = 0.002) -> tuple[BoussinesqModel, float]:
    """Flat flume [left, right] wavelengths, regular source at x = 0; returns (model, wavelength)."""
    k = float(nwogu_wavenumber(2 * np.pi / period, depth))
    wl = 2 * np.pi / k
    m = BoussinesqModel(left * wl, right * wl, wl / 40, depth, sponge_left=1.5 * wl,
                        sponge_right=1.5 * wl if sponge_right else 0.0)
    m.set_regular_wave(0.0, height, period, ramp_periods=2)
    return m, wl


def test_satisfies_wave_model_contract():
    m, _ = flume(0.5, 2.0, -3, 6)
    assert isinstance(m, WaveModel)
    assert m.depth == pytest.approx(0.5)
    assert m.reference_level == pytest.approx(-0.531 * 0.5)
    m.advance_to(1.0)
    assert m.t == 1.0
    u, w = m.velocity(1.0, np.linspace(-0.5, 0.1, 7))
    assert u.shape == (7,) and w.shape == (7,) and np.all(np.isfinite(u)) and np.all(np.isfinite(w))
    with pytest.raises(ValueError, match="outside"):
        m.elevation(1e3)


def test_velocity_profile_of_a_progressive_wave():
    """Linear progressive wave, kd ~ 1: u(z), w(z) amplitudes per unit eta amplitude match
    Nwogu's linear profile (u_alpha = g k a / (omega (1 - alpha (kd)^2)), quadratic in z) within
    1 %, and Airy's cosh/sinh profile within Nwogu's own profile error + 1 %."""
    depth, period = 0.5, 1.5
    m, wl = flume(depth, period, -3, 5)
    omega = 2 * np.pi / period
    k = 2 * np.pi / wl
    x = 1.25 * wl
    zs = np.array([0.0, -0.25 * depth, -0.5 * depth, -depth])
    m.advance_to(20 * period)
    n = int(round(8 * period / m.dt / 2))
    ts, eta, uu, ww = np.empty(n), np.empty(n), np.empty((n, zs.size)), np.empty((n, zs.size))
    for i in range(n):
        m.advance_steps(2)
        ts[i], eta[i] = m.t, m.elevation(x)
        uu[i], ww[i] = m.velocity(x, zs)

    def amp(y):
        basis = np.c_[np.cos(omega * ts), np.sin(omega * ts)]
        c, *_ = np.linalg.lstsq(basis, y, rcond=None)
        return np.hypot(*c)

    a = amp(eta)
    u_amp = np.array([amp(uu[:, j]) for j in range(zs.size)]) / a
    w_amp = np.array([amp(ww[:, j]) for j in range(zs.size)]) / a
    kd = k * depth
    za = BETA * depth
    ua = G * k / (omega * (1 - alpha() * kd**2))
    u_nw = ua * np.abs(1 - k**2 * ((za - zs) * depth + 0.5 * (za**2 - zs**2)))
    w_nw = ua * k * (depth + zs)
    np.testing.assert_allclose(u_amp, u_nw, rtol=0.01)
    np.testing.assert_allclose(w_amp[:-1], w_nw[:-1], rtol=0.01)
    assert w_amp[-1] < 1e-3 * w_amp[0]  # no flow through the flat bed
    ka = float(airy_wavenumber(omega, depth))
    u_airy = omega * np.cosh(ka * (zs + depth)) / np.sinh(ka * depth)
    w_airy = omega * np.sinh(ka * (zs + depth)) / np.sinh(ka * depth)
    assert np.all(np.abs(u_amp / u_airy - 1) <= np.abs(u_nw / u_airy - 1) + 0.01)
    assert np.all(np.abs(w_amp[:-1] / w_airy[:-1] - 1) <= np.abs(w_nw[:-1] / w_airy[:-1] - 1) + 0.01)


def test_two_way_pin_carries_reflected_waves_back():
    """Model A ends in a reflective wall (stand-in for an SPH zone that reflects); model B runs on
    a longer absorbing flume but has eta and u_alpha of A imposed at x_b every step. Upstream of
    x_b, B must reproduce A's partly standing wave (the reflection enters B through the pin),
    which a free B (no feedback) does not."""
    depth, period = 0.5, 2.0
    a_model, wl = flume(depth, period, -3, 4.0, sponge_right=False, height=0.01)
    b_model, _ = flume(depth, period, -3, 8.0, height=0.01)
    free, _ = flume(depth, period, -3, 8.0, height=0.01)
    assert a_model.dt == pytest.approx(b_model.dt)
    x_b = 3.5 * wl
    i_b = int(round((x_b - a_model.x0) / a_model.dx))
    xs = np.array([0.5, 1.0, 1.5, 2.0, 2.5, 3.0]) * wl
    err, diff_free, scale = 0.0, 0.0, 0.0
    while a_model.t < 25 * period:
        a_model.advance_steps(1)
        b_model.impose(x_b, a_model.eta_nodes[i_b], a_model.u_nodes[i_b])
        b_model.advance_steps(1)
        free.advance_steps(1)
        if a_model.t > 15 * period:
            ea = a_model.elevation(xs)
            err = max(err, np.max(np.abs(b_model.elevation(xs) - ea)))
            diff_free = max(diff_free, np.max(np.abs(free.elevation(xs) - ea)))
            scale = max(scale, np.max(np.abs(ea)))
    assert err < 0.01 * scale
    assert diff_free > 0.5 * scale  # the reflection is a large effect: the test can fail


def test_windows_end_exactly_and_agree_with_one_long_advance():
    """Coupling windows that are not a multiple of the CFL step: each ends exactly on its time
    (the step shrinks once, the history restarts once), and the result matches one long
    advance_to to within the discretisation error."""
    period = 2.02
    windowed, _ = flume(0.5, period, -3, 6, height=0.01)
    single, _ = flume(0.5, period, -3, 6, height=0.01)
    window = period / 50
    for i in range(1, 201):
        windowed.advance_to(i * window)
        assert windowed.t == i * window
    assert windowed.dt < windowed.dt_max and (window / windowed.dt) == pytest.approx(round(window / windowed.dt))
    single.advance_to(200 * window)
    assert single.t == windowed.t
    scale = np.abs(single.eta_nodes).max()
    assert scale > 0.004
    assert np.max(np.abs(windowed.eta_nodes - single.eta_nodes)) < 1e-3 * scale


def test_transparent_sph_zone_gives_a_transparent_boundary():
    """SPH that measures exactly the incident wave (here: the model's own values at x_b, as a
    perfectly absorbing SPH zone would report) must not reflect anything back: the characteristic
    boundary keeps the model's outgoing wave, so the amplitude stays uniform upstream (no
    standing-wave modulation) and equal to the generated one. Beyond x_b the model reports its
    uncoupled field (a twin that never got SPH data)."""
    depth, period, height = 0.5, 2.0, 0.002
    m, wl = flume(depth, period, -3, 6, height=height)
    free, _ = flume(depth, period, -3, 6, height=height)
    x_b = 3.0 * wl
    xs = np.array([0.5, 0.875, 1.25, 1.625, 2.0]) * wl
    omega = 2 * np.pi / period
    n = int(round(25 * period / m.dt))
    ts, es = [], []
    for i in range(n):
        if i > 0:
            m.impose(x_b, float(m.elevation(x_b)), float(m.velocity(x_b, np.array([BETA * depth]))[0][0]))
        m.advance_steps(1)
        free.advance_steps(1)
        if m.t > 15 * period:
            ts.append(m.t)
            es.append(m.elevation(xs))
    ts, es = np.array(ts), np.array(es)
    basis = np.c_[np.cos(omega * ts), np.sin(omega * ts)]
    amps = np.array([np.hypot(*np.linalg.lstsq(basis, es[:, j], rcond=None)[0]) for j in range(xs.size)])
    np.testing.assert_allclose(amps, height / 2, rtol=0.01)
    # beyond x_b (inside the SPH zone) the model answers with its uncoupled prediction
    x_in = x_b + np.array([0.1, 0.5]) * wl
    np.testing.assert_array_equal(m.elevation(x_in), free.elevation(x_in))
    np.testing.assert_array_equal(m.velocity(x_in, -0.1)[0], free.velocity(x_in, -0.1)[0])
    assert np.abs(free.elevation(x_in)).max() > 0.2 * height


def test_absorption_only_mode_ignores_impose():
    depth, period = 0.5, 2.0
    m1, wl = flume(depth, period, -3, 6)
    m2 = BoussinesqModel(m1.x0, m1.x1, m1.dx, depth, sponge_left=1.5 * wl, sponge_right=1.5 * wl,
                         two_way=False)
    m2.set_regular_wave(0.0, 0.002, period, ramp_periods=2)
    for _ in range(50):
        m2.impose(3 * wl, 0.5, 1.0)
        m1.advance_steps(4)
        m2.advance_steps(4)
    np.testing.assert_array_equal(m1.eta_nodes, m2.eta_nodes)


def test_impose_rejects_bad_input():
    m, wl = flume(0.5, 2.0, -3, 6)
    with pytest.raises(ValueError, match="impose"):
        m.impose(100 * wl, 0.0, 0.0)
    with pytest.raises(ValueError, match="finite"):
        m.impose(wl, float("nan"), 0.0)


def test_checkpoint_restore_is_exact():
    m, wl = flume(0.5, 2.0, -3, 6)
    m.advance_to(3.0)
    m.impose(4 * wl, 0.001, 0.0)
    cp = m.checkpoint()
    m.advance_steps(100)
    eta1, t1 = m.eta_nodes.copy(), m.t
    m.impose(4 * wl, 0.003, 0.001)  # a different boundary, undone by the restore
    m.advance_steps(10)
    m.restore(cp)
    assert m.t == pytest.approx(3.0, abs=m.dt)
    m.advance_steps(100)
    assert m.t == t1
    np.testing.assert_array_equal(m.eta_nodes, eta1)


@pytest.mark.parametrize("split", ["model", "sph"])
def test_sph_mean_point_velocity_does_not_set_the_boundary_mean(monkeypatch, split):
    """SPH's velocity at z_alpha is a point value: its mean over a period is not the zone's
    mass-flux velocity (measured in the coupled flume: +8..+23 mm/s where the flux velocity is
    the model's return flow, -4.6 mm/s). With the mean split ("model", the default) a constant
    offset of SPH's u_ref leaves the model unchanged; taking it at face value ("sph", before)
    turns it into a left-going long wave of -offset/(2 r) at the boundary, which here (the model
    reading back its own boundary values) feeds on itself until the model blows up."""
    from wave_client.boussinesq import solver

    monkeypatch.setattr(solver, "MEAN_SPLIT", split)
    depth, period = 0.5, 2.0
    plain, wl = flume(depth, period, -3, 6, height=0.01)
    biased, _ = flume(depth, period, -3, 6, height=0.01)
    x_b = 3.0 * wl
    offset = 0.02
    try:
        while plain.t < 12 * period:
            for m, extra in ((plain, 0.0), (biased, offset)):
                if m.t > 0:
                    u = float(m.velocity(x_b, np.array([BETA * depth]))[0][0])
                    m.impose(x_b, float(m.elevation(x_b)), u + extra)
                m.advance_steps(1)
    except solver.BoussinesqUnstableError:
        assert split == "sph"  # the offset fed back on itself every step: it blew up
        return
    xs = np.array([1.0, 2.0, 2.9]) * wl
    diff = np.max(np.abs(biased.elevation(xs) - plain.elevation(xs)))
    if split == "model":
        assert diff < 1e-9
    else:
        assert diff > 0.3 * offset / (2 * plain.progressive_ratio(depth))
