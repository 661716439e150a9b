"""Physics of the Nwogu Boussinesq model: dispersion, generation, solitary wave, convergence.

References (nobody tuned): Nwogu's linear dispersion relation and Airy theory
(wave_client.boussinesq.dispersion), the solitary-wave speed sqrt(g (d + H)), the target
amplitude of the Wei-Kirby-Sinha source function.
"""

from __future__ import annotations

import numpy as np
import pytest

from wave_client.boussinesq import BoussinesqModel, airy_celerity, nwogu_celerity, nwogu_wavenumber
from wave_client.boussinesq import stepping
from wave_client.boussinesq.checks import solitary_run, standing_wave_speed
from wave_client.boussinesq.dispersion import alpha
from wave_client.boussinesq.solitary import nwogu_solitary
from wave_client.theories import wavenumber as airy_wavenumber

G = 9.81


@pytest.mark.parametrize("kd", [0.5, 1.0, 2.0, 3.0])
def test_linear_dispersion_matches_nwogu_and_airy(kd):
    depth = 0.7
    c = standing_wave_speed(kd, depth)
    c_nwogu = float(nwogu_celerity(kd, depth))
    c_airy = float(airy_celerity(kd, depth))
    assert abs(c / c_nwogu - 1) < 0.01
    # Against Airy: within Nwogu's own error of the relation, plus 0.2 % for the discretisation.
    assert abs(c / c_airy - 1) <= abs(c_nwogu / c_airy - 1) + 0.002


def fit_harmonic(t: np.ndarray, y: np.ndarray, omega: float) -> tuple[float, float]:
    """Amplitude and phase phi of y = A cos(omega t - phi) by least squares."""
    basis = np.c_[np.cos(omega * t), np.sin(omega * t)]
    (cc, ss), *_ = np.linalg.lstsq(basis, y, rcond=None)
    return float(np.hypot(cc, ss)), float(np.arctan2(ss, cc))


def record(m: BoussinesqModel, xs: np.ndarray, duration: float) -> tuple[np.ndarray, np.ndarray]:
    """Times and elevations at xs (rows), every 4 model steps over ``duration`` [s] from now."""
    n = int(round(duration / m.dt / 4))
    ts, es = np.empty(n), np.empty((n, np.size(xs)))
    for i in range(n):
        m.advance_steps(4)
        ts[i], es[i] = m.t, m.elevation(xs)
    return ts, es


@pytest.mark.parametrize("depth,period", [(0.5, 2.0), (0.5, 0.9)])
def test_source_function_generates_target_wave(depth, period):
    """Small regular waves from the source: amplitude H/2 and phase k|x - x_s| at gauges on both
    sides, and no standing-wave modulation (the sponges absorb)."""
    height = 0.002
    omega = 2 * np.pi / period
    k = float(nwogu_wavenumber(omega, depth))
    wl = 2 * np.pi / k
    m = BoussinesqModel(-3 * wl, 6 * wl, wl / 40, depth, sponge_left=1.5 * wl, sponge_right=1.5 * wl)
    m.set_regular_wave(0.0, height, period, ramp_periods=2)
    xs = np.array([-wl, 0.75 * wl, 1.5 * wl, 2.25 * wl, 3.0 * wl])
    m.advance_to(20 * period)
    ts, es = record(m, xs, 20 * period)
    for j, x in enumerate(xs):
        amp, phase = fit_harmonic(ts, es[:, j], omega)
        assert amp == pytest.approx(height / 2, rel=0.01), f"amplitude at x = {x:.3f} m"
        dphi = np.angle(np.exp(1j * (phase - k * abs(x))))
        assert abs(dphi) < 0.02, f"phase at x = {x:.3f} m"


def test_solitary_wave_keeps_height_and_speed():
    """H/d = 0.1 over 50 depths (flat bed), initialised with the KdV-type profile (see
    `checks.solitary_run`): the crest height stays within 2 % of H and its speed within 1 % of
    sqrt(g (d + H)); once settled (second half of the run) the crest keeps its height."""
    r = solitary_run(0.1, depth=1.0, distance=50.0)
    t, xc, hc = r["t"], r["x"], r["height"]
    assert xc[-1] - xc[0] > 48 * r["d"]  # it did travel ~50 depths
    assert np.all(np.abs(hc / r["H"] - 1) < 0.02)
    speed = np.polyfit(t[20:], xc[20:], 1)[0]
    assert speed == pytest.approx(r["c"], rel=0.01)
    assert abs(hc[-1] / hc[20] - 1) < 0.002


def test_exact_nwogu_solitary_wave_is_steady():
    """The model's own solitary wave (travelling-wave equations solved numerically, not the
    scheme): over 50 depths the discrete model keeps its height within 0.1 % and moves at its
    speed C within 0.1 %; C itself is within 1 % of sqrt(g (d + H))."""
    r = solitary_run(0.1, depth=1.0, distance=50.0, profile="nwogu")
    assert r["c_profile"] == pytest.approx(r["c"], rel=0.01)
    assert np.all(np.abs(r["height"] / r["H"] - 1) < 1e-3)
    speed = np.polyfit(r["t"], r["x"], 1)[0]
    assert speed == pytest.approx(r["c_profile"], rel=1e-3)


def test_exact_solitary_profile_solves_travelling_wave_equations():
    """Residuals of the once-integrated mass and momentum equations (module docstring of
    `solitary`) on the returned profile, by finite differences: small against the terms."""
    d, height = 1.0, 0.2
    c, shape = nwogu_solitary(height, d)
    xi = np.linspace(-20, 20, 8001)
    eta, u = shape(xi)
    assert eta.max() == pytest.approx(height, rel=1e-9)
    h = xi[1] - xi[0]
    upp = np.gradient(np.gradient(u, h), h)
    a = alpha()
    mass = -c * eta + (d + eta) * u + (a + 1 / 3) * d**3 * upp
    mom = -c * u + G * eta + 0.5 * u * u - a * d * d * c * upp
    assert np.max(np.abs(mass[5:-5])) < 1e-5 * c * height
    assert np.max(np.abs(mom[5:-5])) < 1e-5 * G * height


def standing_wave_run(kd: float, ppw: int, n_steps: int) -> tuple[np.ndarray, np.ndarray]:
    """Linear standing wave (a = 1e-10 d, so nonlinear terms are negligible) in a closed tank one
    wavelength long, run to t = 3.25 periods (where phase errors show): (eta / a, exact / a)
    with the exact solution cos(kx) cos(omega t), omega from Nwogu's dispersion relation."""
    depth = 1.0
    k = kd / depth
    wl = 2 * np.pi / k
    omega = k * float(nwogu_celerity(kd, depth))
    t_end = 3.25 * 2 * np.pi / omega
    m = BoussinesqModel(0.0, wl, wl / ppw, depth, dt=t_end / n_steps, tol=1e-12, max_iter=50)
    a = 1e-10 * depth
    m.set_state(a * np.cos(k * m.x), np.zeros_like(m.x))
    m.advance_steps(n_steps)
    return m.eta_nodes / a, np.cos(k * m.x) * np.cos(omega * m.t)


def steps_for(ppw: int, courant: float, kd: float = 1.0) -> int:
    wl = 2 * np.pi / kd
    t_end = 3.25 * 2 * np.pi / (kd / 1.0 * float(nwogu_celerity(kd, 1.0)))
    return int(np.ceil(t_end / (courant * wl / ppw / np.sqrt(G))))


def test_convergence_order_space_and_time():
    """dx and dt halved together: the error falls at 2nd order, the order of the 3-point dispersive
    terms (Wei & Kirby 1995: truncation O(dx^4, dx^2 mu^2); first derivatives are 4th order, so
    coarse grids show a steeper, 4th-order-dominated fall). dt halved alone on a fixed grid: the
    iterated ABM corrector (RK4 start) converges at 4th order."""
    n0 = steps_for(40, 0.4)
    e = []
    for r in (1, 2, 4):
        eta, exact = standing_wave_run(1.0, 40 * r, n0 * r)
        e.append(np.max(np.abs(eta - exact)))
    orders = np.log2(np.array(e[:-1]) / np.array(e[1:]))
    assert np.all((orders > 1.7) & (orders < 2.5)), (e, orders)
    # time alone: the exact solution of the semi-discrete system is replaced by a 16x finer step
    n1 = steps_for(40, 0.8)
    ref, _ = standing_wave_run(1.0, 40, 16 * n1)
    et = [np.max(np.abs(standing_wave_run(1.0, 40, r * n1)[0] - ref)) for r in (1, 2)]
    assert np.log2(et[0] / et[1]) > 3.7, et


def test_linear_shoaling_on_a_mild_slope():
    """Small regular waves (T = 2 s) shoal up a 1:30 slope from 0.6 m to 0.2 m depth: the
    amplitude ratio equals the linear shoaling coefficient sqrt(cg_deep / cg_shallow) of Airy
    theory within 1 % (energy-flux conservation; tests the variable-depth terms)."""
    period, d0, d1 = 2.0, 0.6, 0.2
    omega = 2 * np.pi / period
    wl0 = 2 * np.pi / float(nwogu_wavenumber(omega, d0))
    wl1 = 2 * np.pi / float(nwogu_wavenumber(omega, d1))
    m = BoussinesqModel(-3 * wl0, 22 + 4 * wl1, wl1 / 40, ([5.0, 17.0], [d0, d1]),
                        sponge_left=1.5 * wl0, sponge_right=1.5 * wl1)
    m.set_regular_wave(0.0, 0.002, period, ramp_periods=2)
    xg = np.array([2.0, 3.0, 20.0, 21.0, 22.0])
    m.advance_to(30 * period)
    ts, es = record(m, xg, 10 * period)
    amps = np.array([fit_harmonic(ts, es[:, j], omega)[0] for j in range(xg.size)])
    ratio = amps[2:].mean() / amps[:2].mean()

    def group_velocity(d: float) -> float:
        dw = 1e-6 * omega
        return 2 * dw / float(airy_wavenumber(omega + dw, d) - airy_wavenumber(omega - dw, d))

    assert ratio == pytest.approx(np.sqrt(group_velocity(d0) / group_velocity(d1)), rel=0.01)


def test_shapiro_filter_removes_grid_noise_only():
    """The 4th-order Shapiro filter removes the 2dx mode and changes a 40-points-per-wavelength
    wave by (k dx)^4 / 16 at most (here 2.4e-4)."""
    n = 200
    x = np.arange(n + 2 * stepping.NG) - stepping.NG
    smooth = np.cos(2 * np.pi * x / 40)
    noisy = smooth + 0.01 * (-1.0) ** x
    work = np.zeros_like(noisy)
    stepping.shapiro_filter(noisy, work, n + stepping.NG)
    inner = slice(stepping.NG, n + stepping.NG)
    assert np.max(np.abs(noisy[inner] - smooth[inner])) < 2.5e-4
    assert np.max(np.abs(noisy[inner] - smooth[inner])) > 1e-5  # it does act on the wave a little


def test_filtered_run_keeps_generated_amplitude():
    """With the filter every 10 steps, regular waves keep their target amplitude within 1 %."""
    depth, period, height = 0.5, 2.0, 0.002
    omega = 2 * np.pi / period
    wl = 2 * np.pi / float(nwogu_wavenumber(omega, depth))
    m = BoussinesqModel(-3 * wl, 6 * wl, wl / 40, depth, sponge_left=1.5 * wl, sponge_right=1.5 * wl,
                        filter_every=10)
    m.set_regular_wave(0.0, height, period, ramp_periods=2)
    m.advance_to(15 * period)
    ts, es = record(m, np.array([3 * wl]), 10 * period)
    assert fit_harmonic(ts, es[:, 0], omega)[0] == pytest.approx(height / 2, rel=0.01)
