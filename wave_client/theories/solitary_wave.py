"""A solitary wave (first-order, KdV/Boussinesq profile) entering the model's x = 0 at time t0.

    eta = H sech^2(k (x - c (t - t0))),   k = sqrt(3 H / (4 d^3)),   c = sqrt(g (d + H))
    u   = c eta / (d + eta)                               (depth-uniform)
    w   = -(z + d) du/dx                                  (continuity with a depth-uniform u)

Approximation: the leading-order (Boussinesq 1872 / KdV) solitary wave with Rayleigh's speed
c = sqrt(g (d + H)). u is the depth-averaged velocity that carries the permanent form's mass
flux exactly, (d + eta) u = c eta; taking it uniform over depth is the shallow-water (long-wave)
approximation, good while k d = sqrt(3 H / (4 d)) << 1 (0.12-0.19 for H/d 0.02-0.05, 0.47 at
H/d 0.3). It is not an exact solution of the Euler equations: a wave made from it sheds a
small dispersive tail whose size grows with H/d. Reference: C. E. Synolakis (1987), "The runup
of solitary waves", J. Fluid Mech. 185, 523-545.

The wave has no period; ``period`` is its time scale 2 pi / (k c) (about the time for which
eta > H/100 at a point), used where a consumer needs one: the coupling window default
(period / 50) and an open boundary's absorption filter.
"""

from __future__ import annotations

import math

import numpy as np

from wave_client.theories.base import G, WaveTheory, require_positive

# depth-limited height of a solitary wave (McCowan 1894): beyond it there is no wave to impose
MAX_HEIGHT_OVER_DEPTH = 0.78
# default t0: the crest is far enough upstream at t = 0 that eta(x = 0) = H * START_FRACTION
START_FRACTION = 1e-3


class SolitaryWave(WaveTheory):
    """Solitary wave of height H [m] on depth d [m], crest at x = 0 at time ``t0`` [s].

    ``t0`` defaults to arccosh(1/sqrt(1e-3)) / (k c), so eta(0, 0) = 1e-3 H: the record at the
    model's origin starts from rest without a ramp. ``ramp_time`` is accepted for the common
    contract but defaults to 0 (a ramp would distort the single hump).
    """

    _repr_fields = ("height", "depth", "t0")

    def __init__(self, height: float, period: float | None = None, depth: float = 1.0, *,
                 t0: float | None = None, ramp_time: float = 0.0, g: float = G) -> None:
        super().__init__(ramp_time)
        if period is not None:
            raise ValueError("period: a solitary wave has none (its time scale 2 pi/(k c) "
                             "follows from height and depth); give height and depth only")
        self.height = require_positive("height", height)
        self.depth = require_positive("depth", depth)
        self.g = require_positive("g", g)
        if self.height > MAX_HEIGHT_OVER_DEPTH * self.depth:
            raise ValueError(f"height={self.height} m exceeds {MAX_HEIGHT_OVER_DEPTH} x depth="
                             f"{self.depth} m: a solitary wave breaks before reaching it")
        self.k = math.sqrt(3.0 * self.height / (4.0 * self.depth**3))
        self.c = math.sqrt(self.g * (self.depth + self.height))
        self.period = 2.0 * math.pi / (self.k * self.c)
        if t0 is None:
            t0 = math.acosh(1.0 / math.sqrt(START_FRACTION)) / (self.k * self.c)
        t0 = float(t0)
        if not math.isfinite(t0):
            raise ValueError(f"t0 must be finite, got {t0!r}")
        self.t0 = t0

    def _eta(self, x: np.ndarray, t: float) -> np.ndarray:
        return self.height / np.cosh(self.k * (x - self.c * (t - self.t0))) ** 2

    def _uw(self, x, z, t, eta):
        d = self.depth
        th = np.tanh(self.k * (x - self.c * (t - self.t0)))
        u = self.c * eta / (d + eta)
        deta_dx = -2.0 * self.k * eta * th
        du_dx = self.c * d / (d + eta) ** 2 * deta_dx
        return u, -(z + d) * du_dx
