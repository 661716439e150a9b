"""What all analytic wave theories share: the clock, the start-up ramp, input checks and the
policy for points above the instantaneous surface.

Datum: z is measured up from the still-water level (z = 0 at rest, z = -depth at the bed).
Waves travel towards +x; the crest is at x = 0 at t = 0 for regular waves.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import raschii
from numpy.typing import ArrayLike

from wave_client import G  # noqa: F401 (re-exported: the theories take g = G by default)


def require_positive(name: str, value: float) -> float:
    """Return ``value`` as float, or raise ValueError naming the parameter."""
    v = float(value)
    if not math.isfinite(v) or v <= 0.0:
        raise ValueError(f"{name} must be a positive finite number, got {value!r}")
    return v


def require_integer(name: str, value: int, lo: int, hi: int | None = None) -> int:
    """Return ``value`` as int if it is an integer in [lo, hi], or raise ValueError naming it."""
    if int(value) != value or value < lo or (hi is not None and value > hi):
        rng = f"from {lo} to {hi}" if hi is not None else f">= {lo}"
        raise ValueError(f"{name} must be an integer {rng}, got {value!r}")
    return int(value)


def check_not_breaking(height: float, period: float, depth: float, name: str = "height") -> None:
    """Raise ValueError naming the height parameter (``name``) if the wave exceeds a breaking limit.

    Uses raschii's ``check_breaking_criteria``: H <= 0.14 L (steepness, Miche's deep-water limit),
    H <= 0.78 d (depth-limited, McCowan) and H <= 0.142 L tanh(k d) (Miche), with L from
    linear dispersion. A breaking wave has no steady-wave solution to impose at a boundary.
    """
    err, _ = raschii.check_breaking_criteria(height, depth, period=period)
    if err:
        raise ValueError(
            f"{name}={height} m breaks for period={period} s, depth={depth} m: "
            + err.strip().replace("\n", "; ")
        )


def ramp_factor(t: float, duration: float) -> float:
    """Half-cosine start-up ramp r(t) = (1 - cos(pi t / T_r)) / 2 on [0, T_r], 0 before, 1 after;
    identically 1 when there is no ramp (T_r = 0).

    A flume starts from rest: multiplying elevation and velocity by r(t) avoids the impulsive
    start that would otherwise launch a spurious transient from the wavemaker boundary.
    r is C1 (zero slope at both ends).
    """
    if duration <= 0.0:  # no ramp: the theory holds at all times, negative ones included
        return 1.0
    if t <= 0.0:
        return 0.0
    if t >= duration:
        return 1.0
    return 0.5 * (1.0 - math.cos(math.pi * t / duration))


class WaveTheory:
    """Base of the analytic theories; satisfies `wave_client.model.WaveModel`.

    Subclasses implement ``_eta(x, t)`` and ``_uw(x, z, t, eta)`` (unramped, z already clamped
    to the surface) and set ``depth``, ``period`` and ``g``.

    Above the instantaneous surface (z > eta) the velocity returned is the **surface value**
    (z clamped to eta). Coupling data must never contain NaN, and zero would put a velocity
    jump right at the crest: SPH buffer particles whose centre lies a fraction of a particle
    spacing above the interpolated surface would be stopped dead while their neighbours move.
    The surface value is the continuous extension. Points below the bed (z < -depth) are
    refused: they mean a datum mix-up (absolute SPH z passed instead of z from still water).
    """

    depth: float
    period: float
    g: float
    _repr_fields: tuple[str, ...] = ("height", "period", "depth", "ramp_time")

    def __init__(self, ramp_time: float = 0.0) -> None:
        ramp_time = float(ramp_time)
        if not math.isfinite(ramp_time) or ramp_time < 0.0:
            raise ValueError(f"ramp_time must be a finite number >= 0 s, got {ramp_time!r}")
        self.ramp_time = ramp_time
        self.t = 0.0

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={getattr(self, k)!r}" for k in self._repr_fields)
        return f"{type(self).__name__}({args})"

    # --- WaveModel contract -------------------------------------------------------------
    def advance_to(self, t: float) -> None:
        """Set the theory's clock to ``t`` [s] (analytic: no state to integrate)."""
        t = float(t)
        if not math.isfinite(t):
            raise ValueError(f"t must be finite, got {t!r}")
        self.t = t

    def elevation(self, x: ArrayLike) -> np.ndarray:
        """Surface elevation eta(x, t) [m] above still water, including the start-up ramp."""
        xa = np.asarray(x, dtype=float)
        return ramp_factor(self.t, self.ramp_time) * self._eta(xa, self.t)

    def velocity(self, x: ArrayLike, z: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """(u, w) [m/s] at (x, z), z up from still water; surface value above the surface."""
        xa, za = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(z, dtype=float))
        if not (np.all(np.isfinite(xa)) and np.all(np.isfinite(za))):
            raise ValueError("x and z must be finite")
        # tolerance: nodes placed exactly on the bed may carry round-off
        if np.any(za < -self.depth * (1.0 + 1e-9)):
            raise ValueError(
                f"z below the bed: min(z) = {za.min():.6g} m < -depth = {-self.depth:.6g} m "
                "(z is measured up from the still-water level, not from the tank floor)"
            )
        r = ramp_factor(self.t, self.ramp_time)
        eta = r * self._eta(xa, self.t)
        zc = np.clip(za, -self.depth, eta)
        u, w = self._uw(xa, zc, self.t, eta)
        return r * u, r * w

    def impose(self, x: float, eta: float, u_ref: float) -> None:
        """Analytic theories are not driven by SPH: feedback is ignored."""

    # --- to implement -------------------------------------------------------------------
    def _eta(self, x: np.ndarray, t: float) -> np.ndarray:
        raise NotImplementedError

    def _uw(
        self, x: np.ndarray, z: np.ndarray, t: float, eta: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        raise NotImplementedError


class RegularWaveTheory(WaveTheory):
    """A regular wave of height H [m] and period T [s] on depth d [m]: validated parameters,
    refused if it breaks (there is no steady wave to impose)."""

    def __init__(self, height: float, period: float, depth: float, *, ramp_time: float = 0.0,
                 g: float = G) -> None:
        super().__init__(ramp_time)
        self.height = require_positive("height", height)
        self.period = require_positive("period", period)
        self.depth = require_positive("depth", depth)
        self.g = require_positive("g", g)
        check_not_breaking(self.height, self.period, self.depth)

    def front_factor(self, x: ArrayLike) -> np.ndarray:
        """How much of the wave has reached x [m] at ``self.t``, as a fraction of the ramp in
        force: the start-up ramp delayed by the travel max(x, 0) / c_g at the linear group
        velocity (x = 0 the ramp's origin, the wavemaker), over the ramp at x = 0. 1 without a
        ramp or once the front has passed, 0 ahead of it. The theory's own ramp holds at every x
        at once; a wavemaker's wave takes time to arrive, and what stands inside a flume
        (ISPH's relaxation zones' targets, sph_core.boundary_data) is the arriving wave."""
        xa = np.maximum(np.asarray(x, dtype=float), 0.0)
        r0 = ramp_factor(self.t, self.ramp_time)
        if self.ramp_time <= 0.0 or r0 <= 0.0:
            return np.full(xa.shape, 1.0 if self.ramp_time <= 0.0 else 0.0)
        delayed = np.vectorize(ramp_factor)(self.t - xa / self.group_velocity, self.ramp_time)
        return np.asarray(delayed / r0, dtype=float)

    @functools.cached_property
    def group_velocity(self) -> float:
        """Linear theory's group velocity [m/s] at this period and depth (the front's speed)."""
        from wave_client.theories.linear import wavenumber   # linear.py imports this module
        omega = 2.0 * math.pi / self.period
        kd = float(wavenumber(omega, self.depth, self.g)) * self.depth
        return 0.5 * omega * self.depth / kd * (1.0 + 2.0 * kd / math.sinh(2.0 * kd))
