"""Kernel gradient correction (renormalised gradients; Bonet & Lok 1999, Randles & Libersky 1996):
the correction matrix L_i of every fluid and buffer particle, one neighbour pass before the forces.

    M_i = sum_j V_j (r_j - r_i) (x) grad_i W_ij = sum_j V_j F_ij r_ji (x) r_ji,   L_i = M_i^-1

over the neighbours the pressure sum of ``wcsph.fluid_pass`` sees (fluid, active buffer, wall;
V_j = m_j / rho_j, grad_i W_ij = F_ij r_ji with r_ji = r_j - r_i). With it the gradient
sum_j V_j (phi_j - phi_i) L_i grad_i W_ij is exact for a linear field phi wherever M_i is
invertible: in the bulk (M = I up to the particles' disorder) and where the kernel is cut by the
free surface (the top rows at h/dp 2: M_zz ~ 0.5-0.7).

fluid_pass uses it in the pressure term of the momentum equation in the symmetric (conservative)
form of Bonet & Lok: grad_i W_ij -> (L_i + L_j)/2 grad_i W_ij for fluid and buffer neighbours j,
antisymmetric in i, j, so the fluid's total momentum is kept (a wall neighbour, which has no L,
takes L_i). Variants (scene ``constants.kernel_correction``, Params.kgc):

- ``all``: L_i for every fluid particle;
- ``weighted``: gamma_i L_i for every fluid particle, gamma_i = sum_j V_j W_ij (self included)
  the Shepard sum (1 in the bulk and beside walls, ~0.6 in the top row): our reading of the
  "parameter-free weighting based on kernel support" of Schulze et al. 2025 (arXiv 2511.10064),
  whose full text was not available here. Where the support is cut, M ~ gamma I, so gamma L ~ I
  plus the anisotropic part: the truncation is left to the plain SPH surface, the disorder is
  corrected;
- ``surface``: localised near the free surface (in the spirit of Schulze et al. 2025,
  who correct only a band below the surface): L_i blended with the identity by the Shepard sum
  gamma_i: weight 1 below SURFACE_GAMMA_FULL, 0 above SURFACE_GAMMA_OFF, linear between.
  Deeper particles keep the plain gradient.

Measured (docs/wave_decay_study.md, "Kernel gradient correction"): experimental, none of the
three holds still water in this WCSPH (``all`` and ``surface`` lose particles through the bed;
``weighted`` grows particle noise, though it lowers the closed tank's decay 1.80 -> 0.68 %/m).

M_i comes from the walk shared with the shifting laws and ISPH (renormalisation.py).
Where M_i is near singular (a splash particle with a few neighbours in a line) L_i = I: there
the correction would amplify noise, not fix a truncation.
"""

from __future__ import annotations

from numba import njit, prange

from .kernels import w_of_q
from .particles import FLUID, OUTLET, WALL
from .renormalisation import moments

# scene constants.kernel_correction -> Params.kgc
KERNEL_CORRECTIONS = {"off": 0, "all": 1, "surface": 2, "weighted": 3}
KGC_OFF = 0
KGC_ALL = 1
KGC_SURFACE = 2
KGC_WEIGHTED = 3
# "surface": full correction where the Shepard sum is below GAMMA_FULL (within ~h of the surface
# at h/dp 2), none above GAMMA_OFF (the bulk: disorder moves gamma by ~1 %)
SURFACE_GAMMA_FULL = 0.9
SURFACE_GAMMA_OFF = 0.97
# M_i is inverted where det M > MIN_DET_RATIO (tr M)^2, i.e. above 5 % of an isotropic matrix's
# determinant (tr M / 2)^2 (as riemann_gradients)
MIN_DET_RATIO = 0.0125
_FASTMATH = {"nsz", "arcp", "contract", "afn", "reassoc"}


@njit(parallel=True, cache=True, fastmath=_FASTMATH)
def correction_matrices(ps, n, cells, prm):
    """L_i (rows lxx, lxz, lzz) of every fluid and buffer particle; the identity elsewhere."""
    lxx = ps.lxx
    lxz = ps.lxz
    lzz = ps.lzz
    kind = ps.kind
    w0 = w_of_q(0.0, prm.alpha_w)
    surface = prm.kgc == KGC_SURFACE
    weighted = prm.kgc == KGC_WEIGHTED
    ramp = 1.0 / (SURFACE_GAMMA_OFF - SURFACE_GAMMA_FULL)
    for i in prange(n):
        ki = kind[i]
        cxx = 1.0
        cxz = 0.0
        czz = 1.0
        if ki >= FLUID and ki <= OUTLET and ki != WALL:   # WALL (1) lies inside that range
            # M_i and the Shepard sum (the field sums of ``moments`` are not read: compiled away)
            s = moments(i, ps, cells, prm, ps.p, ps.vx, ps.vz, True)
            mxx = s.mxx
            mxz = s.mxz
            mzz = s.mzz
            gam = ps.m[i] / ps.rho[i] * w0 + s.shepard
            det = mxx * mzz - mxz * mxz
            tr = mxx + mzz
            if tr > 0.0 and det > MIN_DET_RATIO * tr * tr:
                inv = 1.0 / det
                if surface:
                    wt = min(max((SURFACE_GAMMA_OFF - gam) * ramp, 0.0), 1.0)
                    cxx = 1.0 + wt * (mzz * inv - 1.0)
                    cxz = -wt * mxz * inv
                    czz = 1.0 + wt * (mxx * inv - 1.0)
                else:
                    if weighted:
                        # gamma_i L_i: M ~ gamma I where the support is cut, so what stays
                        # corrected there is the anisotropy, not the truncation
                        inv *= min(gam, 1.0)
                    cxx = mzz * inv
                    cxz = -mxz * inv
                    czz = mxx * inv
        lxx[i] = cxx
        lxz[i] = cxz
        lzz[i] = czz
