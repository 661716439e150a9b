"""Irregular long-crested sea from a JONSWAP spectrum, as a linear superposition.

Spectrum (Hasselmann et al. 1973), frequency f [Hz], peak fp = 1/Tp:

    S(f) = alpha g^2 (2 pi)^-4 f^-5 exp(-5/4 (fp/f)^4) gamma^r,
    r = exp(-(f - fp)^2 / (2 sigma^2 fp^2)),  sigma = 0.07 (f <= fp), 0.09 (f > fp)

alpha is not taken from fetch: it is scaled so that the *discretised* components carry the
requested significant height, Hs = 4 sqrt(m0) with m0 = sum_i S(f_i) df.

Sea state (random-phase model), component i with amplitude a_i = sqrt(2 S(f_i) df),
phase phi_i uniform on [0, 2 pi) from a seeded RNG, k_i from the linear dispersion relation:

    eta = sum_i a_i cos(k_i x - omega_i t + phi_i)
    u   = sum_i a_i omega_i cosh(k_i (z' + d)) / sinh(k_i d) cos(k_i x - omega_i t + phi_i)
    w   = sum_i a_i omega_i sinh(k_i (z' + d)) / sinh(k_i d) sin(k_i x - omega_i t + phi_i)

with Wheeler (1970) stretching z' = d (z + d) / (d + eta) - d, which maps the wet column
[-d, eta] onto [-d, 0]. Without it the short components' exp(k z) growth above z = 0
contaminates crest kinematics (the well-known overprediction of linear extrapolation).
Frequencies are equally spaced bin centres, so the record repeats after 1/df
(``repeat_period``).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from wave_client.theories.base import G, WaveTheory, check_not_breaking, require_integer, require_positive
from wave_client.theories.linear import depth_profiles, wavenumber


def jonswap_shape(f: ArrayLike, fp: float, gamma: float = 3.3, g: float = G) -> np.ndarray:
    """JONSWAP S(f) [m^2/Hz] with alpha = 1 (shape only), f and fp in Hz."""
    f = np.asarray(f, dtype=float)
    sigma = np.where(f <= fp, 0.07, 0.09)
    r = np.exp(-((f - fp) ** 2) / (2.0 * sigma**2 * fp**2))
    return g**2 * (2.0 * np.pi) ** -4 * f**-5 * np.exp(-1.25 * (fp / f) ** 4) * gamma**r


class JonswapSea(WaveTheory):
    """Irregular sea: ``n_components`` linear waves with JONSWAP amplitudes and random phases.

    Parameters: significant height ``hs`` [m], peak period ``tp`` [s], still-water ``depth`` [m],
    peak enhancement ``gamma`` (1 gives Pierson-Moskowitz), frequency band
    [``f_min_factor`` fp, ``f_max_factor`` fp], RNG ``seed`` (same seed, same sea).
    """

    _repr_fields = ("hs", "tp", "depth", "gamma", "n_components", "seed", "ramp_time")

    def __init__(
        self,
        hs: float,
        tp: float,
        depth: float,
        *,
        gamma: float = 3.3,
        n_components: int = 200,
        f_min_factor: float = 0.5,
        f_max_factor: float = 3.0,
        seed: int = 0,
        ramp_time: float = 0.0,
        g: float = G,
    ) -> None:
        super().__init__(ramp_time)
        self.hs = require_positive("hs", hs)
        self.tp = require_positive("tp", tp)
        self.period = self.tp
        self.depth = require_positive("depth", depth)
        self.g = require_positive("g", g)
        self.gamma = require_positive("gamma", gamma)
        n_components = require_integer("n_components", n_components, 1)
        f_lo = require_positive("f_min_factor", f_min_factor)
        f_hi = require_positive("f_max_factor", f_max_factor)
        if not f_lo < 1.0 < f_hi:
            raise ValueError(
                f"f_min_factor < 1 < f_max_factor is required so the band holds the peak, "
                f"got f_min_factor={f_min_factor}, f_max_factor={f_max_factor}"
            )
        # Hs against a regular wave of the peak period: the highest waves of the record
        # (~1.9 Hs) may break locally, which the SPH zone handles; Hs itself must not.
        check_not_breaking(self.hs, self.tp, self.depth, name="hs")

        fp = 1.0 / self.tp
        edges = np.linspace(f_lo * fp, f_hi * fp, int(n_components) + 1)
        self.df = float(edges[1] - edges[0])
        self.frequencies = 0.5 * (edges[:-1] + edges[1:])  # [Hz]
        shape = jonswap_shape(self.frequencies, fp, self.gamma, self.g)
        self.alpha = (self.hs / 4.0) ** 2 / float(np.sum(shape) * self.df)
        self.spectrum = self.alpha * shape  # S(f_i) [m^2/Hz]
        self.amplitudes = np.sqrt(2.0 * self.spectrum * self.df)
        self.phases = np.random.default_rng(seed).uniform(0.0, 2.0 * np.pi, int(n_components))
        self.omegas = 2.0 * np.pi * self.frequencies
        self.wavenumbers = wavenumber(self.omegas, self.depth, self.g)
        self.repeat_period = 1.0 / self.df
        self.n_components = int(n_components)
        self.seed = seed

    @property
    def m0(self) -> float:
        """Zeroth spectral moment sum_i S(f_i) df [m^2]; Hs = 4 sqrt(m0)."""
        return float(np.sum(self.spectrum) * self.df)

    def _phase(self, x: np.ndarray, t: float) -> np.ndarray:
        # (..., N): one column per component
        return x[..., None] * self.wavenumbers - self.omegas * t + self.phases

    def _eta(self, x: np.ndarray, t: float) -> np.ndarray:
        return np.cos(self._phase(x, t)) @ self.amplitudes

    def _uw(self, x, z, t, eta):
        d = self.depth
        # Wheeler stretching, z' in [-d, 0]; the floor on the column height guards a dry trough
        zs = d * (z + d) / np.maximum(d + eta, 1e-9 * d) - d
        phase = self._phase(x, t)
        ch, sh = depth_profiles(self.wavenumbers, zs[..., None], d)
        s = self.amplitudes * self.omegas
        return (s * ch * np.cos(phase)).sum(axis=-1), (s * sh * np.sin(phase)).sum(axis=-1)
