"""Linear (Airy) wave kinematics, the reference the coupling tests drive and check clients with."""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq


def airy(x: np.ndarray | float, z: np.ndarray, t: float, height: float, period: float, depth: float,
         g: float = 9.81) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """u, w [m/s] at (x, z) and the elevation eta [m] at x, time t [s]; z up from still water,
    held at 0 above it (no extrapolation into the crest)."""
    omega = 2 * np.pi / period
    k = brentq(lambda k: omega**2 - g * k * np.tanh(k * depth), 1e-6, 100.0, xtol=1e-15)
    a, phase, zc = height / 2, k * x - omega * t, np.minimum(z, 0.0)
    u = a * omega * np.cosh(k * (zc + depth)) / np.sinh(k * depth) * np.cos(phase)
    w = a * omega * np.sinh(k * (zc + depth)) / np.sinh(k * depth) * np.sin(phase)
    return u, w, a * np.cos(phase)
