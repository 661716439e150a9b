"""Linear (Airy) progressive and standing waves, and the linear dispersion relation.

Reference: R. G. Dean & R. A. Dalrymple, *Water Wave Mechanics for Engineers and Scientists*
(1991), ch. 3-4. z is measured up from the still-water level, z = -d at the bed.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from wave_client.theories.base import G, RegularWaveTheory, require_integer, require_positive


def wavenumber(omega: ArrayLike, depth: float, g: float = G) -> np.ndarray:
    """Solve the linear dispersion relation omega^2 = g k tanh(k d) for k [rad/m].

    Vectorised over omega [rad/s]. Newton iterations from Eckart's (1952) explicit
    approximation k0 = (omega^2/g) / sqrt(tanh(omega^2 d / g)), which is within 5 %, so a
    handful of iterations reach machine precision.
    """
    depth = require_positive("depth", depth)
    w = np.asarray(omega, dtype=float)
    if np.any(~np.isfinite(w)) or np.any(w <= 0.0):
        raise ValueError("omega must be positive and finite")
    k0 = w**2 / g
    k = k0 / np.sqrt(np.tanh(k0 * depth))
    for _ in range(50):
        th = np.tanh(k * depth)
        f = g * k * th - w**2
        df = g * th + g * k * depth * (1.0 - th**2)
        step = f / df
        k = k - step
        if np.all(np.abs(step) <= 1e-14 * k):
            return k
    raise ValueError("dispersion relation did not converge (check omega and depth)")  # pragma: no cover


def depth_profiles(k: ArrayLike, z: ArrayLike, depth: float) -> tuple[np.ndarray, np.ndarray]:
    """cosh(k (z + d)) / sinh(k d) and sinh(k (z + d)) / sinh(k d), without overflow.

    Written as exp(k z) (1 +- exp(-2 k (z + d))) / (1 - exp(-2 k d)) so deep-water components
    (k d in the hundreds) stay finite; requires z >= -d. k and z broadcast.
    """
    k = np.asarray(k, dtype=float)
    z = np.asarray(z, dtype=float)
    e = np.exp(-2.0 * k * (z + depth))
    den = -np.expm1(-2.0 * k * depth)
    ez = np.exp(k * z)
    return ez * (1.0 + e) / den, ez * -np.expm1(-2.0 * k * (z + depth)) / den


class _LinearMode(RegularWaveTheory):
    """One linear mode of height H and period T on depth d: omega, k and L from linear dispersion."""

    def __init__(
        self, height: float, period: float, depth: float, *, ramp_time: float = 0.0, g: float = G
    ) -> None:
        super().__init__(height, period, depth, ramp_time=ramp_time, g=g)
        self.omega = 2.0 * np.pi / self.period
        self.k = float(wavenumber(self.omega, self.depth, self.g))
        self.length = 2.0 * np.pi / self.k


class AiryWave(_LinearMode):
    """Linear progressive wave travelling towards +x.

    eta = (H/2) cos(k x - omega t),  omega^2 = g k tanh(k d)
    u   = (H/2) omega cosh(k (z + d)) / sinh(k d) cos(k x - omega t)
    w   = (H/2) omega sinh(k (z + d)) / sinh(k d) sin(k x - omega t)

    Between z = 0 and the crest the profile is evaluated at the actual z (as raschii's
    AiryWave does); above the surface the surface value is returned (see `WaveTheory`).
    """

    def _eta(self, x: np.ndarray, t: float) -> np.ndarray:
        return 0.5 * self.height * np.cos(self.k * x - self.omega * t)

    def _uw(self, x, z, t, eta):
        a = 0.5 * self.height
        phase = self.k * x - self.omega * t
        ch, sh = depth_profiles(self.k, z, self.depth)
        return a * self.omega * ch * np.cos(phase), a * self.omega * sh * np.sin(phase)


class StandingWave(_LinearMode):
    """Standing wave, e.g. the sloshing mode of a closed tank (walls at antinodes); linear
    (``order`` 1) or to second order in the amplitude (``order`` 2).

    eta = A cos(k x) cos(omega t),  A = H/2,  omega^2 = g k tanh(k d)
    u   = A omega cosh(k (z + d)) / sinh(k d) sin(k x) sin(omega t)
    w   = -A omega sinh(k (z + d)) / sinh(k d) cos(k x) sin(omega t)

    ``height`` is the crest-to-trough range at an antinode (H = 2A; the second-order terms are
    equal at a crest and the following trough, so H stays 2A). It is the superposition of two
    progressive waves of height H/2 travelling in opposite directions. Nodes of eta at
    k x = pi/2 + n pi; u vanishes at the antinodes k x = n pi (where the walls of a tank of
    length L = n pi / k stand).

    Second order (the Stokes expansion of the free-surface conditions about z = 0; Penney &
    Price 1952 in deep water, Tadjbakhsh & Keller 1960 in finite depth), with T = tanh(k d):

        eta2 = k A^2 [ (T + 1/T)/8  cos 2kx  +  c22 cos 2kx cos 2 omega t ],
        c22  = 3T/8 - 1/(8T) + 3 T cosh(2kd) / (8 sinh^4 kd)
        phi2 = D cosh(2k (z + d)) cos 2kx sin 2 omega t,   D = -3 A^2 omega / (16 sinh^4 kd)

    The first term is the mean set-up (k A^2/4) coth(2kd) cos 2kx: the water stands higher at
    the antinodes than at the nodes; over a wavelength it integrates to zero. phi2 vanishes in
    deep water (Penney & Price's eta2 = (k A^2/2) cos 2kx cos^2 omega t) and u2 vanishes at the
    nodes and antinodes, so a flume whose faces stand at the nodes sees the second order only in
    the elevation it imposes there. The frequency keeps its linear value (its correction is of
    third order). Valid while the second-order amplitude stays well below A (seed 002's case I:
    0.08 A); tests/test_wave_client/test_theories.py checks that the exact surface conditions'
    residual falls as A^3.
    """

    _repr_fields = ("height", "period", "depth", "order", "ramp_time")

    def __init__(self, height: float, period: float, depth: float, *, order: int = 1,
                 ramp_time: float = 0.0, g: float = G) -> None:
        super().__init__(height, period, depth, ramp_time=ramp_time, g=g)
        self.order = require_integer("order", order, 1, 2)
        kd = self.k * self.depth
        th = np.tanh(kd)
        a = 0.5 * self.height
        # cosh(2kd) / sinh^4(kd) = 8 e^{-2kd} (1 + e^{-4kd}) / (1 - e^{-2kd})^4, finite in deep
        # water
        e2 = np.exp(-2.0 * kd)
        ch2_sh4 = 8.0 * e2 * (1.0 + e2 * e2) / (1.0 - e2) ** 4
        self._setup = self.k * a * a * (th + 1.0 / th) / 8.0
        self._c22 = self.k * a * a * (3.0 * th / 8.0 - 1.0 / (8.0 * th) + 3.0 * th * ch2_sh4 / 8.0)
        # -2k D sinh^4(kd): u2 = this cosh(2k(z+d)) / sinh^4(kd) sin 2kx sin 2wt (w2 alike)
        self._d2 = 2.0 * self.k * 3.0 * a * a * self.omega / 16.0

    def _eta(self, x: np.ndarray, t: float) -> np.ndarray:
        eta = 0.5 * self.height * np.cos(self.k * x) * np.cos(self.omega * t)
        if self.order == 2:
            c2 = np.cos(2.0 * self.k * x)
            eta = eta + c2 * (self._setup + self._c22 * np.cos(2.0 * self.omega * t))
        return eta

    def _uw(self, x, z, t, eta):
        s = 0.5 * self.height * self.omega * np.sin(self.omega * t)
        ch, sh = depth_profiles(self.k, z, self.depth)
        u, w = s * ch * np.sin(self.k * x), -s * sh * np.cos(self.k * x)
        if self.order == 2:
            # (cosh, sinh)(2k(z + d)) / sinh^4(kd) without overflow:
            # 8 e^{2k(z - d)} (1 +- e^{-4k(z + d)}) / (1 - e^{-2kd})^4
            kd = self.k * self.depth
            base = 8.0 * np.exp(2.0 * self.k * (z - self.depth)) / (-np.expm1(-2.0 * kd)) ** 4
            e4 = np.exp(-4.0 * self.k * (z + self.depth))
            s2 = self._d2 * np.sin(2.0 * self.omega * t)
            u = u + s2 * base * (1.0 + e4) * np.sin(2.0 * self.k * x)
            w = w - s2 * base * (1.0 - e4) * np.cos(2.0 * self.k * x)
        return u, w
