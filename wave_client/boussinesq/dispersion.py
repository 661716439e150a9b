"""Linear dispersion of Nwogu's extended Boussinesq equations and of Airy theory.

Nwogu (1993), with the reference level z_alpha = beta*d (beta = -0.531):

    c^2 / (g d) = [1 - (alpha + 1/3) (kd)^2] / [1 - alpha (kd)^2],
    alpha = beta^2/2 + beta

Airy (linear potential) theory: omega^2 = g k tanh(k d).

References: O. Nwogu (1993), Alternative form of Boussinesq equations for nearshore wave
propagation, J. Waterway Port Coastal Ocean Eng. 119(6), 618-638.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from wave_client import G  # the package-wide value, imported from here by the solver

BETA = -0.531  # z_alpha / d, Nwogu's optimal reference level


def alpha(beta: float = BETA) -> float:
    """Nwogu's alpha = beta^2/2 + beta (z_alpha = beta d)."""
    return 0.5 * beta * beta + beta


def nwogu_celerity(kd: ArrayLike, depth: float, beta: float = BETA, g: float = G) -> np.ndarray:
    """Phase speed c [m/s] of Nwogu's equations for wavenumber-depth products kd."""
    a = alpha(beta)
    kd2 = np.asarray(kd, dtype=float) ** 2
    return np.sqrt(g * depth * (1.0 - (a + 1.0 / 3.0) * kd2) / (1.0 - a * kd2))


def airy_celerity(kd: ArrayLike, depth: float, g: float = G) -> np.ndarray:
    """Phase speed c = sqrt(g tanh(kd) / k) [m/s] of linear (Airy) theory."""
    kd = np.asarray(kd, dtype=float)
    return np.sqrt(g * depth * np.tanh(kd) / kd)


def nwogu_wavenumber(omega: ArrayLike, depth: float, beta: float = BETA, g: float = G) -> np.ndarray:
    """Wavenumber k [1/m] solving Nwogu's dispersion relation for angular frequency omega.

    With s = omega^2 d / g and K = kd the relation reads  a1 K^4 - (1 + s a) K^2 + s = 0,
    a1 = alpha + 1/3 < 0 for beta = -0.531; the physical root is the positive K^2.
    """
    a = alpha(beta)
    a1 = a + 1.0 / 3.0
    s = np.asarray(omega, dtype=float) ** 2 * depth / g
    b = 1.0 + s * a
    if abs(a1) < 1e-14:
        k2 = s / b
    else:
        k2 = (b - np.sqrt(b * b - 4.0 * a1 * s)) / (2.0 * a1)
    return np.sqrt(k2) / depth

