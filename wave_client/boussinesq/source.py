"""Internal wave generation by a source function in the mass equation (Wei, Kirby & Sinha 1999).

A term f(x, t) = G(x) S(t) is added to the right-hand side of the mass equation, with

    G(x) = exp(-beta_s (x - x_s)^2),       beta_s = 80 / (delta^2 L^2)   (width ~ delta L / 2)
    S(t) = r(t) * sum_n D_n cos(omega_n t - phi_n)

For each component, the linearised Nwogu equations (flat bed, depth d) radiate to both sides of
x_s the waves  eta = a_n cos(omega_n t - phi_n -+ k_n (x - x_s))  if

    D_n = 2 a_n (omega_n^2 - a1 g k_n^4 d^3) / (omega_n k_n I_1 [1 - alpha (k_n d)^2]),
    I_1 = sqrt(pi / beta_s) exp(-k_n^2 / (4 beta_s)),   a1 = alpha + 1/3,

with k_n from Nwogu's own dispersion relation (Wei, Kirby & Sinha 1999, eq. 17-21; we re-derived
it by Fourier transform and residues: the radiated wave is in phase with S, no shift). r(t) is a
half-cosine ramp over `ramp` seconds that avoids the start-up transient.

Reference: G. Wei, J. T. Kirby, A. Sinha (1999), Generation of waves in Boussinesq models using a
source function method, Coastal Engineering 36, 271-299.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .dispersion import BETA, G, alpha, nwogu_wavenumber


@dataclass(frozen=True)
class SourceFunction:
    """Spatial shape and spectral content of the source (arrays for the jitted kernel)."""

    shape: np.ndarray  # G(x_i) on the model grid [-]
    amplitude: np.ndarray  # D_n [m/s]
    omega: np.ndarray  # omega_n [rad/s]
    phase: np.ndarray  # phi_n [rad]
    ramp: float  # ramp duration [s]


def source_amplitude(a: np.ndarray, omega: np.ndarray, depth: float, beta_s: float,
                     beta: float = BETA, g: float = G) -> np.ndarray:
    """D_n of Wei, Kirby & Sinha (1999) for target amplitudes a_n [m] at frequencies omega_n."""
    al = alpha(beta)
    a1 = al + 1.0 / 3.0
    k = nwogu_wavenumber(omega, depth, beta, g)
    i1 = np.sqrt(np.pi / beta_s) * np.exp(-k * k / (4.0 * beta_s))
    return 2.0 * a * (omega**2 - a1 * g * k**4 * depth**3) / (omega * k * i1 * (1.0 - al * (k * depth) ** 2))


def make_source(x: np.ndarray, x_s: float, depth: float, a: np.ndarray, omega: np.ndarray,
                phase: np.ndarray, wavelength: float, delta: float = 0.5, ramp: float = 0.0,
                beta: float = BETA, g: float = G) -> SourceFunction:
    """Build the source for components eta_n = a_n cos(omega_n t - phi_n) radiated from x_s.

    `wavelength` sets the Gaussian width (the peak or regular wavelength, Nwogu's dispersion);
    `depth` is the still-water depth at x_s, which must be flat over the source width.
    """
    beta_s = 80.0 / (delta * delta * wavelength * wavelength)
    shape = np.exp(-beta_s * (x - x_s) ** 2)
    shape[shape < 1e-14] = 0.0
    amp = source_amplitude(np.asarray(a, float), np.asarray(omega, float), depth, beta_s, beta, g)
    return SourceFunction(shape, amp, np.asarray(omega, float), np.asarray(phase, float), float(ramp))


def components_from_series(t: np.ndarray, eta: np.ndarray, depth: float, kd_max: float = 3.0,
                           beta: float = BETA, g: float = G) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Fourier components (a_n, omega_n, phi_n) of a uniformly sampled elevation series.

    The series is treated as periodic over its duration N*dt (the usual FFT synthesis);
    the mean is dropped and components with Nwogu k d > kd_max (outside the model's dispersion
    range) are removed. eta(t) = sum_n a_n cos(omega_n t - phi_n).
    """
    t = np.asarray(t, float)
    eta = np.asarray(eta, float)
    if t.ndim != 1 or t.shape != eta.shape or t.size < 4:
        raise ValueError("wave series: time and eta must be 1D arrays of equal length >= 4")
    dt = np.diff(t)
    if np.any(dt <= 0) or np.ptp(dt) > 1e-6 * dt.mean():
        raise ValueError("wave series: time must be uniformly sampled and increasing")
    n = t.size
    spec = np.fft.rfft(eta - eta.mean())
    freq = np.fft.rfftfreq(n, dt.mean())
    a = 2.0 * np.abs(spec) / n
    if n % 2 == 0:
        a[-1] *= 0.5  # Nyquist bin is not doubled
    omega = 2.0 * np.pi * freq
    # phase referred to t[0]: eta = a cos(omega (t - t0) + arg) = a cos(omega t - phi)
    phi = -(np.angle(spec) - omega * t[0])
    keep = (freq > 0) & (a > 1e-12 * max(a.max(), 1e-300))
    kd = nwogu_wavenumber(omega[keep], depth, beta, g) * depth
    idx = np.flatnonzero(keep)[kd <= kd_max]
    return a[idx], omega[idx], phi[idx]
