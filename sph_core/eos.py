"""Tait equation of state and the hydrostatic density it implies.

p = B [(rho/rho0)^gamma - 1],  B = c0^2 rho0 / gamma,  gamma = 7   (Monaghan 1994; Batchelor 1967)
Inverse: rho = rho0 (1 + p/B)^(1/gamma).
Hydrostatic state below a free surface at z_s:  p = rho g (z_s - z) integrated exactly gives
rho(z) = rho0 (1 + rho0 g (z_s - z) / B)^(1/gamma) to first order in p/B (the form used by
DualSPHysics to initialise fluid); the pressure then is p(rho(z)) from the EOS itself, so the
initial state is in discrete EOS balance.
"""

from __future__ import annotations

import numpy as np
from numba import njit

GAMMA = 7.0


def tait_b(rho0: float, c0: float, gamma: float = GAMMA) -> float:
    """B = c0^2 rho0 / gamma [Pa]."""
    return c0 * c0 * rho0 / gamma


@njit(cache=True, inline="always")
def pressure(rho: float, rho0: float, b: float, gamma: float) -> float:
    """Tait: p = B [(rho/rho0)^gamma - 1]."""
    return b * ((rho / rho0) ** gamma - 1.0)


@njit(cache=True, inline="always")
def density(p: float, rho0: float, b: float, gamma: float) -> float:
    """Inverse Tait: rho = rho0 (1 + p/B)^(1/gamma); p/B is floored so the root stays real."""
    s = 1.0 + p / b
    if s < 1e-6:
        s = 1e-6
    return rho0 * s ** (1.0 / gamma)


def hydrostatic_density(z: np.ndarray, z_surface: np.ndarray | float, rho0: float, g: float,
                        b: float, gamma: float = GAMMA) -> np.ndarray:
    """rho(z) = rho0 (1 + rho0 g (z_s - z) / B)^(1/gamma) below a free surface at z_s."""
    depth = np.maximum(np.asarray(z_surface, dtype=float) - np.asarray(z, dtype=float), 0.0)
    return rho0 * (1.0 + rho0 * g * depth / b) ** (1.0 / gamma)
