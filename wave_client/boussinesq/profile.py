"""Velocity profile under a Nwogu Boussinesq wave (seed 001, Algorithm 2, line 6).

Nwogu (1993) expands the velocity potential about the bed, phi = phi_0 - z (h u_0)_x - z^2/2 u_0,x
(mild slope), so that, with z up from the still-water level and the bed at z = -h,

    u(z) = u_alpha + (z_alpha - z) (h u_alpha)_xx + 1/2 (z_alpha^2 - z^2) u_alpha,xx
    w(z) = -(h u_alpha)_x - z u_alpha,x

to O(mu^2), where u_alpha is the horizontal velocity at z = z_alpha = beta h. Checks: u(z_alpha) =
u_alpha; the continuity u_x + w_z = 0 holds for a flat bed; on the bed w(-h) = -u h_x (no flux
through the bed); on a flat bed at the surface, w(0) = -h u_x = eta_t (linear mass equation).

Seed 001 adds the terms  dx z_alpha (h u_alpha)_x + z_alpha dx z_alpha u_alpha,x, which appear if
u_alpha is taken as the gradient of the potential on the sloping level z_alpha(x) rather than the
velocity at z_alpha. Our momentum equation (Nwogu's, gradients of z_alpha neglected) evolves the
velocity at z_alpha, and SPH hands back the velocity measured at z_alpha, so we keep u(z_alpha) =
u_alpha and leave those terms out; they are O(h_x mu^2) and vanish on a flat bed, where the
coupling boundary should lie.
"""

from __future__ import annotations

import numpy as np

from .dispersion import BETA


def reconstruct_velocity(z: np.ndarray, h: np.ndarray, ua: np.ndarray, ux: np.ndarray, uxx: np.ndarray,
                         hux: np.ndarray, huxx: np.ndarray, beta: float = BETA) -> tuple[np.ndarray, np.ndarray]:
    """(u, w) [m/s] at heights z [m] (up from still water) from u_alpha and its x-derivatives.

    ux, uxx: u_alpha,x and u_alpha,xx; hux, huxx: (h u_alpha)_x and (h u_alpha)_xx; h: depth [m].
    """
    za = beta * h
    u = ua + (za - z) * huxx + 0.5 * (za * za - z * z) * uxx
    w = -hux - z * ux
    return u, w
