"""Wendland C2 smoothing kernel (2D and 3D: only a_D differs), as jitted scalar functions.

W(r, h) = a_D (1 - q/2)^4 (2q + 1),  q = r/h in [0, 2],  a_D = 7 / (4 pi h^2)   (2D)
                                                          a_D = 21 / (16 pi h^3) (3D)
Wendland (1995); Dehnen & Aly (2012). The support radius is 2h.

The interaction loops need the gradient  grad_i W_ij = -F(r) (r_i - r_j)  with
F(r) = -(dW/dr)/r = 5 a_D (1 - q/2)^3 / h^2, which is finite at r = 0 and needs no division by r.
"""

from __future__ import annotations

import math

from numba import njit

DIM = 2  # the default scene: the vertical plane (x, z); a scene with dim = 3 passes 3


def wendland_alpha(h: float, dim: int = DIM) -> float:
    """Normalisation constant a_D of the Wendland C2 kernel for smoothing length ``h`` [m]."""
    if dim == 2:
        return 7.0 / (4.0 * math.pi * h * h)
    if dim == 3:
        return 21.0 / (16.0 * math.pi * h**3)
    raise ValueError(f"dim: must be 2 or 3, got {dim}")


@njit(cache=True, inline="always")
def w_of_q(q: float, alpha: float) -> float:
    """W = a_D (1 - q/2)^4 (2q + 1) for q < 2, else 0."""
    if q >= 2.0:
        return 0.0
    t = 1.0 - 0.5 * q
    t2 = t * t
    return alpha * t2 * t2 * (2.0 * q + 1.0)


@njit(cache=True, inline="always")
def f_of_q(q: float, alpha_f: float) -> float:
    """F = -(dW/dr)/r = alpha_f (1 - q/2)^3 for q < 2, with alpha_f = 5 a_D / h^2."""
    if q >= 2.0:
        return 0.0
    t = 1.0 - 0.5 * q
    return alpha_f * t * t * t
