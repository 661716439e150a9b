"""Nonlinear regular waves through `raschii`: Stokes 2nd-5th order and stream-function waves.

- Stokes: J. D. Fenton (1985), "A fifth-order Stokes theory for steady waves",
  J. Waterway, Port, Coastal and Ocean Eng. 111(2), 216-234 (`raschii.StokesWave`).
- Stream function: M. M. Rienecker & J. D. Fenton (1981), "A Fourier approximation method for
  steady water waves", J. Fluid Mech. 104, 119-137 (`raschii.FentonWave`).

raschii measures z from the bed (z = 0 at the bed, z = d at still water) and returns the
earth-frame velocity with zero Eulerian mean current (Stokes' first definition of celerity);
it is given the period and solves for the wavelength. We convert z explicitly:
z_raschii = z + d.
"""

from __future__ import annotations

import numpy as np
import raschii

from wave_client.theories.base import G, RegularWaveTheory, require_integer


class _RaschiiWave(RegularWaveTheory):
    """Adapter from a raschii wave object to the `WaveModel` contract."""

    def _build(self, raschii_class: type, name: str, n: int, lo: int, hi: int) -> int:
        """Build the raschii wave of ``n`` terms (raschii's ``N``, the parameter ``name``, an
        integer in [lo, hi]) for this height, period and depth; returns n."""
        n = require_integer(name, n, lo, hi)
        try:
            wave = raschii_class(self.height, self.depth, period=self.period, N=n, g=self.g)
        except raschii.RaschiiError as exc:  # includes NonConvergenceError
            raise ValueError(
                f"{type(self).__name__} did not converge for height={self.height} m, "
                f"period={self.period} s, depth={self.depth} m: {exc}"
            ) from exc
        if not np.isfinite(wave.length) or abs(wave.period - self.period) > 1e-6 * self.period:
            raise ValueError(
                f"{type(self).__name__}: raschii returned period {wave.period} s for the requested "
                f"period={self.period} s (height={self.height} m, depth={self.depth} m)"
            )
        self.raschii_wave = wave
        self.length = float(wave.length)
        self.k = float(wave.k)
        self.celerity = float(wave.c)
        return n

    def _eta(self, x: np.ndarray, t: float) -> np.ndarray:
        eta = self.raschii_wave.surface_elevation(x.ravel(), t, include_depth=False)
        return np.asarray(eta, dtype=float).reshape(x.shape)

    def _uw(self, x, z, t, eta):
        # z is already clamped to the surface, so every point is wet for raschii
        vel = self.raschii_wave.velocity(x.ravel(), (z + self.depth).ravel(), t, all_points_wet=True)
        vel = np.asarray(vel, dtype=float).reshape(-1, 2)
        return vel[:, 0].reshape(x.shape), vel[:, 1].reshape(x.shape)


class StokesWave(_RaschiiWave):
    """Stokes wave of order 2 to 5 (Fenton 1985) through ``raschii.StokesWave``."""

    _repr_fields = ("height", "period", "depth", "order", "ramp_time")

    def __init__(self, height: float, period: float, depth: float, *, order: int = 5,
                 ramp_time: float = 0.0, g: float = G) -> None:
        super().__init__(height, period, depth, ramp_time=ramp_time, g=g)
        self.order = self._build(raschii.StokesWave, "order", order, 2, 5)


class StreamFunctionWave(_RaschiiWave):
    """Stream-function (Fourier) wave of Rienecker & Fenton (1981) through ``raschii.FentonWave``.

    ``n_fourier`` is the number of Fourier modes; raise it for steep or shallow-water waves.
    """

    _repr_fields = ("height", "period", "depth", "n_fourier", "ramp_time")

    def __init__(self, height: float, period: float, depth: float, *, n_fourier: int = 10,
                 ramp_time: float = 0.0, g: float = G) -> None:
        super().__init__(height, period, depth, ramp_time=ramp_time, g=g)
        self.n_fourier = self._build(raschii.FentonWave, "n_fourier", n_fourier, 2, 64)
