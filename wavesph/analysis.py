"""Wave-record analysis for flume validation: RMSE against theory, reflection coefficient.

Reflection by least squares over two or more gauges (Goda & Suzuki 1976 for two gauges;
Mansard & Funke 1980 for more): at the angular frequency omega each gauge j's complex amplitude
    A_j = (2/N) sum_n eta_j(t_n) exp(-i omega t_n)     (over a whole number of periods)
is fitted by an incident and a reflected progressive wave,
    A_j = a_I exp(-i k x_j) + a_R exp(+i k x_j),
and the reflection coefficient is K_R = |a_R| / |a_I|. Gauge spacing must avoid multiples of
half a wavelength (the 2 x 2 system is singular there); L/4 is best.

A coarse SPH flume damps its waves (case V at H/dp = 3: amplitude -7 % per metre), and a decaying
incident wave fitted with constant amplitudes reads as reflection: 6.5 % from mid-flume and L/8
either side where the decay-aware fit over 9 gauges within L/4 of it gives 4.0 % (same run). With
``decay=True`` both waves decay along their direction of travel at one rate delta [1/m],
    A_j = a_I exp(-(i k + delta) x_j) + a_R exp(+(i k + delta) x_j),   x_j from the array centre,
delta chosen by least squares too, and K_R is the ratio at the centre of the gauge array.

Per harmonic (``separate_harmonics``): the n-th harmonic n omega of the records is separated the
same way with the wavenumber the caller gives for it: n k for the bound harmonics of a steady
nonlinear wave (they travel at the fundamental's phase speed), the linear-dispersion k(n omega)
for free waves (e.g. spurious harmonics emitted by a boundary). Mansard & Funke (1980) fit the
same least squares with a residual ("noise") term: uncorrelated noise adds only to the residual
returned here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar


def group_velocity(wavelength: float, period: float, depth: float) -> float:
    """Linear group velocity [m/s] of a wave of ``wavelength`` and ``period`` in ``depth``."""
    kd = 2.0 * math.pi / wavelength * depth
    return 0.5 * (wavelength / period) * (1.0 + 2.0 * kd / math.sinh(2.0 * kd))


def rmse_over_height(eta: np.ndarray, eta_theory: np.ndarray, height: float) -> float:
    """sqrt(mean((eta - eta_theory)^2)) / H.

    A dry sample (NaN) has no elevation to compare, and any stand-in value would be arbitrary:
    dry or non-finite samples raise ValueError (a gauge mid-flume must stay wet)."""
    eta = np.asarray(eta, dtype=float)
    eta_theory = np.asarray(eta_theory, dtype=float)
    if eta.shape != eta_theory.shape or eta.size == 0:
        raise ValueError(f"eta: shape {eta.shape} does not match eta_theory {eta_theory.shape}")
    if not np.all(np.isfinite(eta)):
        raise ValueError(f"eta: {int(np.sum(~np.isfinite(eta)))} dry or non-finite samples")
    return float(np.sqrt(np.mean((eta - eta_theory) ** 2)) / height)


def harmonic_amplitude(t: np.ndarray, eta: np.ndarray, omega: float) -> complex:
    """Complex amplitude A of the component Re(A exp(i omega t)) of a uniformly sampled record
    spanning a whole number of periods (the caller trims it)."""
    t = np.asarray(t, dtype=float)
    eta = np.asarray(eta, dtype=float) - np.mean(eta)
    return complex(2.0 / t.size * np.sum(eta * np.exp(-1j * omega * t)))


def _separate(amp: np.ndarray, xs: np.ndarray, k: float, delta: float
              ) -> tuple[complex, complex, float]:
    """Least squares (a_I, a_R, residual norm) of
    A_j = a_I exp(-(i k + delta) x_j) + a_R exp((i k + delta) x_j)."""
    a = np.stack([np.exp(-(1j * k + delta) * xs), np.exp((1j * k + delta) * xs)], axis=1)
    (a_i, a_r), *_ = np.linalg.lstsq(a, amp, rcond=None)
    return complex(a_i), complex(a_r), float(np.linalg.norm(a @ np.array([a_i, a_r]) - amp))


@dataclass(frozen=True)
class Separation:
    """Incident and reflected components of one harmonic (amplitudes [m] and phases [rad] of
    Re(a exp(i omega t)) at the array centre with ``decay``, else at x = 0), the fitted decay
    rate [1/m] (0 without ``decay``) and the least-squares residual norm [m]."""

    harmonic: int
    kr: float
    a_incident: float
    a_reflected: float
    phase_incident: float
    phase_reflected: float
    decay: float
    residual: float


def _whole_periods(t: np.ndarray, etas: np.ndarray, xs: np.ndarray, period: float,
                   n_gauges: int) -> int:
    """Checks the records; returns the sample count spanning the most whole periods."""
    if etas.shape != (xs.size, t.size) or xs.size < n_gauges:
        raise ValueError(f"etas: expected shape ({xs.size}, {t.size}) with >= {n_gauges} "
                         f"gauges, got {etas.shape}")
    if not np.all(np.isfinite(etas)):
        raise ValueError("etas: records contain dry or non-finite samples")
    dt = t[1] - t[0]
    n_per = math.floor((t[-1] - t[0] + dt) / period + 1e-9)
    if n_per < 1:
        raise ValueError(f"t: records shorter than one period ({period} s)")
    return int(round(n_per * period / dt))


def separate_harmonics(t: np.ndarray, etas: np.ndarray, xs: np.ndarray, period: float,
                       wavenumbers: list[float] | np.ndarray, decay: bool = False
                       ) -> list[Separation]:
    """Incident/reflected separation of harmonics 1..len(wavenumbers) of records
    ``etas[j, :]`` at gauge positions ``xs[j]`` [m] (uniform ``t``, trimmed to whole periods).

    ``wavenumbers[n - 1]``: the wavenumber [1/m] of harmonic n (see the module docstring).
    Two gauges suffice without ``decay`` (Goda & Suzuki 1976), three or more with it (the
    decay rate is fitted per harmonic). Gauge spacings near a multiple of half the harmonic's
    wavelength make its fit ill-conditioned."""
    t = np.asarray(t, dtype=float)
    etas = np.atleast_2d(np.asarray(etas, dtype=float))
    xs = np.asarray(xs, dtype=float)
    m = _whole_periods(t, etas, xs, period, 3 if decay else 2)
    omega = 2.0 * math.pi / period
    out = []
    for n, k in enumerate(np.asarray(wavenumbers, dtype=float), start=1):
        amp = np.array([harmonic_amplitude(t[:m], e[:m], n * omega) for e in etas])
        dl = 0.0
        x = xs
        if decay:
            x = xs - 0.5 * (xs.min() + xs.max())
            # residual vs delta is smooth with one minimum for |delta| well below k (a decay by
            # e over a wavelength/(2 pi) is far beyond any usable flume)
            fit = minimize_scalar(lambda d: _separate(amp, x, k, d)[2], bounds=(-0.5 * k, 0.5 * k),
                                  method="bounded", options={"xatol": 1e-6 * k})
            dl = float(fit.x)
        a_i, a_r, res = _separate(amp, x, k, dl)
        out.append(Separation(n, float(abs(a_r) / abs(a_i)), float(abs(a_i)), float(abs(a_r)),
                              float(np.angle(a_i)), float(np.angle(a_r)), dl, res))
    return out


def reflection_coefficient(t: np.ndarray, etas: np.ndarray, xs: np.ndarray, period: float,
                           k: float, decay: bool = False) -> tuple[float, float, float]:
    """(K_R, |a_I|, |a_R|) of the first harmonic (``separate_harmonics``) from records
    ``etas[j, :]`` at gauge positions ``xs[j]`` [m]; with ``decay`` (>= 3 gauges) the
    amplitudes are those at the centre of the gauge array."""
    s = separate_harmonics(t, etas, xs, period, [k], decay=decay)[0]
    return s.kr, s.a_incident, s.a_reflected
