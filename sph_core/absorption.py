"""Gain of the open ends' active absorption (seed 002 correction): du = n_x P(z) G (eta_meas - eta_gauge).

The buffer adds one velocity du P(z) to the source's profile: it is a wave maker that must emit
the wave cancelling the unwanted one the gauge sees. An outgoing Airy wave
eta = a cos(k x - omega t) in depth d has u(z) = a omega cosh k(z + d) / sinh kd; at the end the
fluid's velocity is the source's profile plus U P(z), and the field radiated by the end is a
progressive wave (mode cosh k(z + d)) plus evanescent modes, which carry nothing away. The end
swallows the wave iff U P and u(z) have the same projection on the progressive mode
(``transfer_gain``); for a uniform P
    G(omega) = U / a = omega (sinh 2kd + 2kd) / (4 sinh^2 kd) = omega / (H/S),
Biesel's (1951) transfer function of a piston wave maker (H/S = 4 sinh^2 kd/(sinh 2kd + 2kd);
Schaeffer & Klopman 2000 absorb with it), -> sqrt(g/d) as kd -> 0 (seed 002's shallow-water
gain), 0.92 sqrt(g/d) at kd 0.76, 0.86 at 1.2, 0.83 at 2 (a minimum; deep water omega/2). The
profile P is linear theory's cosh k(z + d) at the wave period (``correction_profile``; then
G = omega/(kd) and no evanescent mode is radiated at that frequency), uniform when no period is
known.

The gain follows G(omega) frequency by frequency with a causal filter on the mismatch
e = eta_meas - eta_gauge (Schaeffer & Klopman 2000 in spirit),
    du = n_x [D e + sum_j c_j x_j],   dx_j/dt = (e - x_j) / tau_j,
fitted (least squares, then reweighted towards the largest error) to the ideal response
    H(omega) = G(omega) exp(-i k(omega) delta)
over kd in FILTER_KD_BAND. delta is the gauge's distance inside the face: the outgoing wave the
end must swallow passes the gauge delta/c before it reaches the face, so the ideal correction is
the gauge's reading delayed by that much. A causal filter cannot follow G(omega) exactly (its
phase follows its magnitude); the delay makes the fit closer (Schaeffer & Klopman's point about
a gauge away from the paddle). With a known wave period the fit is made exact there (a regular
wave's own frequency gets the transfer gain, delayed), and the rest of the band (harmonics, a
spectrum's flanks) gets the fit: a causal three-pole filter keeps the gain error's reflection
at 2.5-4.7 % over kd 0.3-2 for the piston gain, whose G(omega) varies by 0.83-1 sqrt(g/d) over
the band. At omega -> 0 the gain D + sum c_j is 0.9-0.95 sqrt(g/d).

Measured and retired (docs/decisions/): the plain gains sqrt(g/d) and G at the period
(``absorption`` shallow/linear), the depth-mean "flux" transfer omega/(k d) (19 % low at kd 2)
and the uniform profile at a known period (``absorption_profile``).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

# the filter's time constants tau_j in units of sqrt(d/g), and the kd band it is fitted over
FILTER_TAUS = (0.3, 1.0, 3.0)  # 4 fit closer, but D ~ 1.8 sqrt(g/d) amplifies gauge noise
FILTER_KD_BAND = (0.2, 2.5)
N_FILTER = len(FILTER_TAUS)


def linear_wavenumber(omega: float, depth: float, g: float = 9.81) -> float:
    """Linear-dispersion wavenumber k [1/m]: omega^2 = g k tanh(k d) (Newton from Eckart's
    approximation, converged to round-off)."""
    if not (omega > 0 and depth > 0):
        raise ValueError(f"omega ({omega}) and depth ({depth}) must be > 0")
    k0 = omega * omega / g
    k = k0 / math.sqrt(math.tanh(k0 * depth))
    for _ in range(50):
        th = math.tanh(k * depth)
        f = g * k * th - omega * omega
        df = g * th + g * k * depth * (1.0 - th * th)
        step = f / df
        k -= step
        if abs(step) < 1e-14 * k:
            break
    return k


def _sinhc(x: np.ndarray | float) -> np.ndarray | float:
    """sinh(x)/x, 1 at x = 0."""
    x = np.asarray(x, dtype=float)
    small = np.abs(x) < 1e-6
    return np.where(small, 1.0 + x * x / 6.0, np.sinh(np.where(small, 1.0, x)) / np.where(small, 1.0, x))


def correction_profile(s: np.ndarray | float, profile_kd: float = 0.0) -> np.ndarray:
    """The correction's vertical profile P at relative height s = (z - z_bed)/d (1 at the
    still-water level): cosh(q s) q / sinh q for q = ``profile_kd`` > 0 (linear theory's
    orbital velocity cosh k(z + d) at the wave whose kd is q), 1 for q = 0 (a piston). Its
    depth mean over 0 <= s <= 1 is 1, so every profile carries the same volume flux per unit
    correction and the gains below share the long-wave limit sqrt(g/d)."""
    s = np.asarray(s, dtype=float)
    if not (math.isfinite(profile_kd) and profile_kd >= 0):
        raise ValueError(f"profile_kd: must be a finite number >= 0, got {profile_kd}")
    if profile_kd == 0.0:
        return np.ones_like(s)
    q = profile_kd
    return np.cosh(q * s) * q / math.sinh(q)


def transfer_gain(omega: np.ndarray | float, kd: np.ndarray | float,
                  profile_kd: float = 0.0) -> np.ndarray | float:
    """Ideal gain G(omega) [1/s] of the correction U P(z) (``correction_profile``; uniform for
    ``profile_kd`` 0), for wavenumber kd = k(omega) d: the end's velocity U P(z) radiates a
    progressive wave (mode phi = cosh k(z + d)) plus evanescent modes, which carry nothing away.
    Projecting U P and the outgoing wave's Airy velocity a omega phi / sinh kd onto phi, the end
    swallows the wave without reflection iff
        G = U/a = omega int phi^2 dz / (sinh kd int P phi dz),
    for P = 1 Biesel's omega (sinh 2kd + 2kd) / (4 sinh^2 kd) (Schaeffer & Klopman 2000 absorb
    with it); with the wave's own profile (q = kd) G = omega/(kd): no evanescent mode."""
    if not (math.isfinite(profile_kd) and profile_kd >= 0):
        raise ValueError(f"profile_kd: must be a finite number >= 0, got {profile_kd}")
    q = profile_kd
    # int_0^1 P(s) cosh(kd s) ds with P = cosh(q s) q / sinh q (q = 0: sinh kd / kd)
    p_phi = 0.5 * (q / math.sinh(q) if q > 0 else 1.0) * (
        np.sinh(kd + q) / (kd + q) + _sinhc(kd - q))
    return omega * (np.sinh(2.0 * kd) + 2.0 * kd) / (4.0 * kd * np.sinh(kd) * p_phi)


def profile_wavenumber(g: float, depth: float, period: float | None) -> float:
    """q = k d of the correction's profile: the linear wave of ``period``; 0 (a uniform piston,
    the mode's long-wave limit) when no period is known."""
    if period is None:
        return 0.0
    if not (math.isfinite(period) and period > 0):
        raise ValueError(f"absorption period: must be a positive number of seconds, got {period}")
    return linear_wavenumber(2.0 * math.pi / period, depth, g) * depth


def source_period(source: Any) -> float | None:
    """The wave period [s] a boundary-data source carries, if any: a ``WaveModelBoundary``
    over a theory with ``period`` (regular waves; the peak period of a spectrum)."""
    period = getattr(getattr(source, "model", None), "period", None)
    try:
        period = float(period) if period is not None else None
    except (TypeError, ValueError):
        return None
    return period if period is not None and math.isfinite(period) and period > 0 else None


def absorption_filter(g: float, depth: float, delay: float = 0.0, period: float | None = None,
                      profile_kd: float = 0.0) -> tuple[float, np.ndarray, np.ndarray]:
    """(D [1/s], tau [s], c [1/s]) of the correction du = n_x [D e + sum_j c_j x_j] with
    dx_j/dt = (e - x_j)/tau_j (module docstring), fitted to G(omega) exp(-i k delay) over
    FILTER_KD_BAND (G the transfer gain of the correction profile ``profile_kd``), exact at
    ``period`` when given; ``delay`` [m] is the gauge's distance inside the face."""
    tau = np.asarray(FILTER_TAUS) * math.sqrt(depth / g)
    if not (depth > 0 and g > 0 and delay >= 0):
        raise ValueError(f"depth ({depth}), g ({g}) must be > 0, delay ({delay}) >= 0")
    kd = np.geomspace(*FILTER_KD_BAND, 200)
    weight = np.ones(200)
    if period is not None:
        omega0 = 2.0 * math.pi / period
        kd = np.append(kd, linear_wavenumber(omega0, depth, g) * depth)
        weight = np.append(weight, 1e3)  # exact at the wave's own frequency
    omega = np.sqrt(g * kd * np.tanh(kd) / depth)
    target = (transfer_gain(omega, kd, profile_kd)
              * np.exp(-1j * kd * delay / depth))  # delayed
    cols = np.column_stack([np.ones(kd.size)] + [1.0 / (1.0 + 1j * omega * t) for t in tau])
    a = cols / target[:, None]  # relative error: the reflection is set by H_fit/H - 1
    band = np.ones(kd.size)
    for _ in range(30):  # iteratively reweighted towards the largest relative error in the band
        w = band * weight
        coef = np.linalg.lstsq(np.vstack([(a * w[:, None]).real, (a * w[:, None]).imag]),
                               np.concatenate([w, np.zeros(kd.size)]), rcond=None)[0]
        err = np.abs(a @ coef - 1.0)
        band = band * np.sqrt(err / err.max() + 1e-3)
        band = band / band.max()
        band[200:] = 1.0  # the wave's own frequency stays exact
    return float(coef[0]), tau, np.asarray(coef[1:], dtype=float)


def filter_reflection(d_gain: float, tau: np.ndarray, c: np.ndarray, g: float, depth: float,
                      delay: float, kd: np.ndarray, profile_kd: float = 0.0) -> np.ndarray:
    """Reflection |(1 - rho)/(1 + rho)| of a correction (D, tau, c) at wavenumbers kd against the
    ideal H(omega) = G(omega) exp(-i k delay), rho = H_filter / H (the gain error alone)."""
    kd = np.asarray(kd, dtype=float)
    omega = np.sqrt(g * kd * np.tanh(kd) / depth)
    h_fit = d_gain + sum(cj / (1.0 + 1j * omega * tj) for cj, tj in zip(c, tau))
    rho = h_fit / (transfer_gain(omega, kd, profile_kd)
                   * np.exp(-1j * kd * delay / depth))
    return np.abs((1.0 - rho) / (1.0 + rho))
