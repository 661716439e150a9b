"""Solitary waves for the Nwogu model: the KdV-type profile and the model's own exact solution.

KdV-type (first-order) profile, the usual initial condition:

    eta = H sech^2(sqrt(3H/(4d^3)) (x - x0)),   c = sqrt(g (d + H)),   u_alpha = c eta / (d + eta)

Exact travelling wave of Nwogu's weakly nonlinear equations (flat bed, xi = x - C t, decay at
infinity). Integrating the mass and momentum equations once in xi:

    -C eta + (d + eta) u + a1 d^3 u'' = 0              (a1 = alpha + 1/3)
    -C u + g eta + u^2/2 - alpha d^2 C u'' = 0

Eliminating u'' gives eta as a rational function of u,

    eta(u) = [u (r C - d) - r u^2/2] / (u + r g - C),   r = a1 d / (alpha C),

and then u'' = Q(u) / (alpha d^2 C), Q = -C u + g eta(u) + u^2/2, whose first integral is
u'^2/2 = V(u) = int_0^u Q ds / (alpha d^2 C) (closed form below). The crest u_m is the first
positive root of V; C is found so that eta(u_m) = H; the profile follows from
u'' = Q(u) / (alpha d^2 C) integrated from the crest. (Wei & Kirby 1995 give a closed form with a sech^2 +
sech^4 elevation; with u_alpha = A sech^2 the weakly nonlinear mass flux leaves an unbalanced
sech^6 term, so we solve the travelling-wave equations numerically instead.)
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from .dispersion import BETA, G, alpha
from .solver import BoussinesqModel


def kdv_solitary(x: np.ndarray, height: float, depth: float, x0: float,
                 g: float = G) -> tuple[np.ndarray, np.ndarray, float]:
    """(eta, u_alpha, c) of the KdV-type profile centred at x0."""
    kappa = math.sqrt(3.0 * height / (4.0 * depth**3))
    c = math.sqrt(g * (depth + height))
    eta = height / np.cosh(kappa * (x - x0)) ** 2
    return eta, c * eta / (depth + eta), c


class _Travelling:
    """eta(u) and V(u) of the travelling-wave equations for speed C."""

    def __init__(self, c: float, depth: float, beta: float, g: float):
        al = alpha(beta)
        a1 = al + 1.0 / 3.0
        self.c, self.d, self.g, self.al = c, depth, g, al
        r = a1 * depth / (al * c)
        self.a = r * c - depth  # eta = (a u + b u^2) / (u + D)
        self.b = -0.5 * r
        self.D = r * g - c  # < 0: the pole lies at u = -D > 0
        self.scale = al * depth * depth * c

    def eta(self, u: np.ndarray | float) -> np.ndarray | float:
        return (self.a * u + self.b * u * u) / (u + self.D)

    def q(self, u: float) -> float:
        return -self.c * u + self.g * self.eta(u) + 0.5 * u * u

    def potential(self, u: np.ndarray | float) -> np.ndarray | float:
        """V(u) = int_0^u Q / (alpha d^2 C); eta(s) = b s + k - k D / (s + D), k = a - b D."""
        k = self.a - self.b * self.D
        int_eta = 0.5 * self.b * u * u + k * u - k * self.D * np.log((u + self.D) / self.D)
        return (-0.5 * self.c * u * u + self.g * int_eta + u**3 / 6.0) / self.scale

    def crest(self) -> float | None:
        """First positive root of V (the crest velocity u_m), or None if V stays positive."""
        us = np.linspace(0.0, -self.D, 2001)[1:-1]
        v = self.potential(us)
        sign = np.flatnonzero((v[:-1] > 0) & (v[1:] <= 0))
        if sign.size == 0:
            return None
        i = sign[0]
        return brentq(self.potential, us[i], us[i + 1], xtol=1e-15 * -self.D, rtol=1e-15)


def nwogu_solitary(height: float, depth: float, beta: float = BETA,
                   g: float = G) -> tuple[float, Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]]:
    """Exact solitary wave of Nwogu's equations of height H over depth d.

    Returns (C, profile) where profile(xi) -> (eta, u_alpha) at xi = x - x_crest [m].
    """
    if not 0 < height < 0.6 * depth:
        raise ValueError(f"solitary wave: height/depth must be in (0, 0.6), got {height / depth}")
    c0 = math.sqrt(g * depth)

    def mismatch(c: float) -> float:
        tw = _Travelling(c, depth, beta, g)
        um = tw.crest()
        return (tw.eta(um) if um is not None else 0.0) - height

    c = brentq(mismatch, c0 * (1 + 1e-9), c0 * math.sqrt(1 + 1.5 * height / depth), xtol=1e-14 * c0)
    tw = _Travelling(c, depth, beta, g)
    um = tw.crest()
    # u'' = Q(u) / (alpha d^2 C) from the crest (u = u_m, u' = 0) down to u = 1e-6 u_m; the
    # separatrix is unstable, but errors of 1e-13 grow only to ~1e-1 of u there. Beyond, the
    # linearised tail u ~ exp(-kappa xi), kappa^2 = Q'(0) / (alpha d^2 C).
    kappa = math.sqrt((tw.q(1e-7 * um) / (1e-7 * um)) / tw.scale)
    u_cut = 1e-6 * um

    def low(_, y):
        return y[0] - u_cut

    low.terminal = True
    sol = solve_ivp(lambda _, y: [y[1], tw.q(y[0]) / tw.scale], (0.0, 100.0 / kappa), [um, 0.0],
                    method="DOP853", rtol=1e-13, atol=1e-18 * um, dense_output=True, events=low)
    xi_cut = float(sol.t_events[0][0])

    def profile(xi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        s = np.abs(np.asarray(xi, float))
        near = s < xi_cut
        u = u_cut * np.exp(-kappa * (s - xi_cut))
        u[near] = sol.sol(s[near])[0]
        return tw.eta(u), u

    return c, profile


def solitary_approach(height: float, depth: float, t_crest: float, t_end: float,
                      g: float = G) -> BoussinesqModel:
    """A Boussinesq model (flat bed ``depth``) carrying its own solitary wave of ``height``
    (``nwogu_solitary``: steady in the model, no shed tail) whose crest passes x = 0 at
    ``t_crest`` [s]: the far field of a run-up or impact case whose SPH zone starts at x = 0.
    The grid (depth/20) runs downstream far enough, ending in a sponge, that nothing comes back
    to x = 0 before ``t_end``."""
    if not (height > 0 and depth > 0 and t_crest > 0 and t_end > t_crest):
        raise ValueError(f"solitary_approach: need height, depth > 0 and 0 < t_crest < t_end, got "
                         f"{height}, {depth}, {t_crest}, {t_end}")
    kappa = math.sqrt(3.0 * height / (4.0 * depth**3))
    c_model, shape = nwogu_solitary(height, depth, g=g)
    x_start = -c_model * t_crest
    sponge = 5.0 / kappa
    model = BoussinesqModel(x_start - 10.0 / kappa, c_model * t_end + sponge, 0.05 * depth, depth,
                            sponge_right=sponge, x_couple=0.0, g=g)
    eta, u = shape(model.x - x_start)
    model.set_state(eta, u)
    return model
