"""Particle-scale velocity noise: each fluid particle's velocity minus a smooth local fit.

    dke = noise_energy(x, z, u, w, m, dp)          # per particle [J/m], 0.5 m |v - v_fit|^2
    binned_noise(x, dke, edges)                    # summed per x bin

A wave resolved by 100 particles per wavelength is smooth over a few spacings; what a local
quadratic least-squares fit of the velocity over a particle's ``K_NEIGHBOURS`` nearest fluid
neighbours (itself included, ~3.5 dp radius) does not follow is particle-scale motion ("noise"):
the disorder that the artificial viscosity and the delta term then dissipate. The fit's own
truncation on a linear wave is (k r)^3 / 6 ~ 0.3 % of the velocity at k r = 0.25 (L 2 m, dp
0.02): 1e-5 of the wave's energy, below the closed tank's measured noise (1e-3). Unlike the
closed tank's "outside the first three modes" (wavesph/cases/standing_wave.py) it needs no mode shape,
so the same measure serves the progressive wave of an open flume (wavesph/cases/wave_decay.py) and the
standing wave, and can be resolved along x. Particles next to the surface get a one-sided fit.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

K_NEIGHBOURS = 40
_RIDGE = 1e-9   # relative Tikhonov term: a surface particle's one-sided fit stays solvable


def noise_energy(x: np.ndarray, z: np.ndarray, u: np.ndarray, w: np.ndarray, m: np.ndarray,
                 dp: float) -> np.ndarray:
    """Kinetic energy [J per m of width] of each particle's velocity minus the local quadratic
    fit of (u, w) over its K_NEIGHBOURS nearest particles (arrays: one entry per fluid particle)."""
    pts = np.column_stack([x, z])
    k = min(K_NEIGHBOURS, len(x))
    _, idx = cKDTree(pts).query(pts, k=k)
    dx = (x[idx] - x[:, None]) / dp
    dz = (z[idx] - z[:, None]) / dp
    basis = np.stack([np.ones_like(dx), dx, dz, dx * dx, dx * dz, dz * dz], axis=2)  # (N, K, 6)
    ata = np.einsum("nki,nkj->nij", basis, basis)
    ata += _RIDGE * np.trace(ata, axis1=1, axis2=2)[:, None, None] * np.eye(6)
    rhs = np.stack([np.einsum("nki,nk->ni", basis, u[idx]),
                    np.einsum("nki,nk->ni", basis, w[idx])], axis=2)               # (N, 6, 2)
    coef = np.linalg.solve(ata, rhs)
    du = u - coef[:, 0, 0]   # the fit at the particle itself (dx = dz = 0)
    dw = w - coef[:, 0, 1]
    return 0.5 * m * (du * du + dw * dw)


def binned_noise(x: np.ndarray, dke: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """Noise energy summed per x bin ``edges`` (len(edges) - 1 values)."""
    return np.histogram(x, bins=edges, weights=dke)[0]
