"""Gain of the open ends' active absorption (seed 002 correction): du = n_x G (eta_meas - eta_gauge).

The buffer adds one velocity du, uniform over the depth, to the source's profile: it is a piston
wave maker that must emit the wave cancelling the unwanted one the gauge sees. An outgoing Airy
wave eta = a cos(k x - omega t) in depth d has u(z) = a omega cosh k(z + d) / sinh kd; at the
end the fluid's velocity is the source's profile plus U, and the field radiated by the end is a
progressive wave (mode cosh k(z + d)) plus evanescent modes, which carry nothing away. The end
swallows the wave iff U and u(z) have the same projection on the progressive mode:
    G(omega) = U / a = omega (sinh 2kd + 2kd) / (4 sinh^2 kd) = omega / (H/S)      ("piston",
Biesel's (1951) transfer function of a piston wave maker, H/S = 4 sinh^2 kd/(sinh 2kd + 2kd);
Schaeffer & Klopman 2000 absorb with it), -> sqrt(g/d) as kd -> 0 (seed 002's shallow-water
gain, "shallow"), 0.92 sqrt(g/d) at kd 0.76, 0.86 at 1.2, 0.83 at 2 (a minimum; deep water
omega/2). The "flux" gain omega/(k d) = sqrt(g/d) sqrt(tanh kd / kd) (the wave's depth-mean
velocity: the uniform U carrying its volume flux) ignores that the evanescent modes carry flux
at the end too: it is low by 0.3 % at kd 0.76, 3.6 % at 1.2, 19 % at kd 2, a reflection of
(rho - 1)/(rho + 1) = 0.3 / 1.8 / 8.7 % of the absorbed wave (measured at kd 2, H/dp 4: 8.6 %;
docs/absorption.md). It was the transfer before 2026-11-23 and stays as an option
(``transfer = "flux"``). "linear" evaluates the transfer gain at the source's wave period (the
peak period of a spectrum), exact for regular waves.

"filter" (Schaeffer & Klopman 2000 in spirit) follows G(omega) frequency by frequency with a
causal filter on the mismatch e = eta_meas - eta_gauge,
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
the band (5-9 % for the flux gain, which falls to 0.69 sqrt(g/d)). At omega -> 0 the gain
D + sum c_j is 0.9-0.95 sqrt(g/d) (piston).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

ABSORPTION_KINDS = ("shallow", "linear", "filter")
# what the ideal gain G(omega) is: "piston" Biesel's transfer function of a depth-uniform
# wave maker (the default: it is what the buffer's correction is), "flux" the depth-mean
# velocity omega/(k d) of the wave (the gain before 2026-11-23; 8.7 % reflection at kd 2)
ABSORPTION_TRANSFERS = ("piston", "flux")
# the correction's vertical profile: "uniform" (a piston), "mode" linear theory's orbital
# velocity cosh k(z + d) at the wave period (no evanescent near field at that frequency;
# docs/absorption.md, 2026-11-23 kd 2 study)
ABSORPTION_PROFILES = ("uniform", "mode")
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
                  transfer: str = "piston", profile_kd: float = 0.0) -> np.ndarray | float:
    """Ideal gain G(omega) [1/s] of the correction U P(z) (``correction_profile``; uniform for
    ``profile_kd`` 0), for wavenumber kd = k(omega) d.

    ``piston`` (for the uniform profile Biesel's 1951 transfer function; Schaeffer & Klopman
    2000 use it for a piston absorber): the end's velocity U P(z) radiates a progressive wave
    (mode phi = cosh k(z + d)) plus evanescent modes, which carry nothing away. Projecting U P
    and the outgoing wave's Airy velocity a omega phi / sinh kd onto phi, the end swallows the
    wave without reflection iff
        G = U/a = omega int phi^2 dz / (sinh kd int P phi dz),
    for P = 1: omega (sinh 2kd + 2kd) / (4 sinh^2 kd). With the wave's own profile (q = kd)
    G = omega/(kd): no evanescent mode, and the flux gain is exact. ``flux``: omega/(k d), the
    depth-mean velocity per unit elevation (the same for every profile of depth mean 1); for
    the piston it ignores that the evanescent modes carry flux too, and is low by 0.3 % at kd
    0.76, 3.6 % at 1.2, 19 % at kd 2 (8.7 % reflection, as measured)."""
    if transfer not in ABSORPTION_TRANSFERS:
        raise ValueError(f"absorption_transfer: one of {ABSORPTION_TRANSFERS}, got {transfer!r}")
    if not (math.isfinite(profile_kd) and profile_kd >= 0):
        raise ValueError(f"profile_kd: must be a finite number >= 0, got {profile_kd}")
    if transfer == "flux":
        return omega / kd
    q = profile_kd
    # int_0^1 P(s) cosh(kd s) ds with P = cosh(q s) q / sinh q (q = 0: sinh kd / kd)
    p_phi = 0.5 * (q / math.sinh(q) if q > 0 else 1.0) * (
        np.sinh(kd + q) / (kd + q) + _sinhc(kd - q))
    return omega * (np.sinh(2.0 * kd) + 2.0 * kd) / (4.0 * kd * np.sinh(kd) * p_phi)


def profile_wavenumber(profile: str, g: float, depth: float, period: float | None) -> float:
    """q = k d of the correction's profile: the linear wave of ``period`` for ``mode``; 0 (a
    uniform piston) for ``uniform`` or when no period is known (the mode's long-wave limit)."""
    if profile not in ABSORPTION_PROFILES:
        raise ValueError(f"absorption_profile: one of {ABSORPTION_PROFILES}, got {profile!r}")
    if profile == "uniform" or period is None:
        return 0.0
    if not (math.isfinite(period) and period > 0):
        raise ValueError(f"absorption period: must be a positive number of seconds, got {period}")
    return linear_wavenumber(2.0 * math.pi / period, depth, g) * depth


def absorption_gain(kind: str, g: float, depth: float, period: float | None = None,
                    transfer: str = "piston", profile_kd: float = 0.0) -> float:
    """Gain G [1/s] of the depth-uniform correction du = n_x G (eta_meas - eta_gauge).

    ``shallow``: sqrt(g/d) (seed 002). ``linear``: the ``transfer`` gain (``transfer_gain``) at
    the wave ``period`` [s]; with no period known it is the shallow gain, its kd -> 0 limit."""
    if kind not in ABSORPTION_KINDS:
        raise ValueError(f"absorption: one of {ABSORPTION_KINDS}, got {kind!r}")
    if transfer not in ABSORPTION_TRANSFERS:
        raise ValueError(f"absorption_transfer: one of {ABSORPTION_TRANSFERS}, got {transfer!r}")
    if not (depth > 0 and g > 0):
        raise ValueError(f"depth ({depth}) and g ({g}) must be > 0")
    shallow = math.sqrt(g / depth)
    if kind == "shallow" or period is None:
        return shallow
    if not (math.isfinite(period) and period > 0):
        raise ValueError(f"absorption period: must be a positive number of seconds, got {period}")
    omega = 2.0 * math.pi / period
    return float(transfer_gain(omega, linear_wavenumber(omega, depth, g) * depth, transfer,
                               profile_kd))


def source_period(source: Any) -> float | None:
    """The wave period [s] a boundary-data source carries, if any: a ``WaveModelBoundary``
    over a theory with ``period`` (regular waves; the peak period of a spectrum)."""
    period = getattr(getattr(source, "model", None), "period", None)
    try:
        period = float(period) if period is not None else None
    except (TypeError, ValueError):
        return None
    return period if period is not None and math.isfinite(period) and period > 0 else None


def absorption_filter(kind: str, g: float, depth: float, delay: float = 0.0,
                      period: float | None = None, transfer: str = "piston",
                      profile_kd: float = 0.0) -> tuple[float, np.ndarray, np.ndarray]:
    """(D [1/s], tau [s], c [1/s]) of the correction du = n_x [D e + sum_j c_j x_j] with
    dx_j/dt = (e - x_j)/tau_j (module docstring). ``shallow``/``linear``: D = absorption_gain,
    c = 0 (a plain gain). ``filter``: fitted to G(omega) exp(-i k delay) over FILTER_KD_BAND
    (G the ``transfer`` gain of the correction profile ``profile_kd``), exact at ``period``
    when given; ``delay`` [m] is the gauge's distance inside the face."""
    tau = np.asarray(FILTER_TAUS) * math.sqrt(depth / g)
    if kind != "filter":
        return (absorption_gain(kind, g, depth, period, transfer, profile_kd), tau,
                np.zeros(N_FILTER))
    if not (depth > 0 and g > 0 and delay >= 0):
        raise ValueError(f"depth ({depth}), g ({g}) must be > 0, delay ({delay}) >= 0")
    kd = np.geomspace(*FILTER_KD_BAND, 200)
    weight = np.ones(200)
    if period is not None:
        omega0 = 2.0 * math.pi / period
        kd = np.append(kd, linear_wavenumber(omega0, depth, g) * depth)
        weight = np.append(weight, 1e3)  # exact at the wave's own frequency
    omega = np.sqrt(g * kd * np.tanh(kd) / depth)
    target = (transfer_gain(omega, kd, transfer, profile_kd)
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
                      delay: float, kd: np.ndarray, transfer: str = "piston",
                      profile_kd: float = 0.0) -> np.ndarray:
    """Reflection |(1 - rho)/(1 + rho)| of a correction (D, tau, c) at wavenumbers kd against the
    ideal H(omega) = G(omega) exp(-i k delay), rho = H_filter / H (the gain error alone)."""
    kd = np.asarray(kd, dtype=float)
    omega = np.sqrt(g * kd * np.tanh(kd) / depth)
    h_fit = d_gain + sum(cj / (1.0 + 1j * omega * tj) for cj, tj in zip(c, tau))
    rho = h_fit / (transfer_gain(omega, kd, transfer, profile_kd)
                   * np.exp(-1j * kd * delay / depth))
    return np.abs((1.0 - rho) / (1.0 + rho))
