"""Fickian particle shifting with free-surface detection (Lind et al. 2012; Skillen et al. 2013).

After each step every fluid particle i moves by
    dr_i = -D_i grad C_i,   D_i = A h |v_i| dt   (A = Constants.shift_a),
    grad C_i = sum_j V_j grad_i W_ij = -sum_j V_j F_ij r_ij
(j: fluid, wall and active buffer neighbours; V_j = m_j / rho_j), towards lower particle
concentration: a disordered lattice relaxes back to a regular one, which keeps the kernel sums
(and so the pressure gradient's zeroth-order error) small. Near the free surface the
concentration falls because the fluid ends, not because of disorder: a particle whose position
divergence
    div r_i = trace B_i,   B_i = sum_j V_j F_ij r_ij r_ij^T    (div r = 2 in 2D, full support)
is below ``shift_fs_div`` keeps only the component of dr_i tangent to the surface (Lind et al.
2012: no shifting normal to the surface). The normal is the renormalised
n_i = -B_i^-1 grad C_i / |B_i^-1 grad C_i| (Marrone et al. 2010; Sun et al. 2017): grad C_i itself
is parallel to dr_i and could not split it. The shifted particle's density and velocity are
carried to its new position to first order (Lind et al. 2012), rho_i += dr_i . grad rho_i,
v_i += dr_i . grad v_i, grad phi_i = sum_j V_j (phi_j - phi_i) grad_i W_ij: without it a vertical
shift would keep the hydrostatic density of its old height. |dr_i| is capped at 0.05 h.

The displacement and the carried increments are gathered into the scratch rows xn, zn, vxn,
vzn, rhon (kdk does not use them; symplectic_pc rewrites them at its next predictor) and applied
in a second loop, so no particle reads a neighbour that has already moved. Measured effect on
the wave of bench/wave_decay.py: none for the better at h/dp 2 (docs/wave_decay_study.md).
"""

from __future__ import annotations

import math

from numba import njit, prange

from .kernels import f_of_q
from .neighbours import block_of
from .particles import FLUID, OUTLET, WALL

@njit(parallel=True, cache=True)
def shift_particles(ps, n, cells, prm, dt):
    """Shift every fluid particle of the sorted state ``ps`` by A = ``prm.shift_a`` (see the
    module docstring); |dr| <= 0.05 h << the cell size, so the cell lists stay valid."""
    x = ps.x
    z = ps.z
    vx = ps.vx
    vz = ps.vz
    rho = ps.rho
    m = ps.m
    kind = ps.kind
    cell = ps.cell
    cell_start = cells.start
    ncx = cells.ncx
    h = prm.h
    alpha_f = prm.alpha_f
    coef = prm.shift_a
    fs_div = prm.shift_fs_div
    max_shift = 0.05 * h
    s2 = 4.0 * h * h
    inv_h = 1.0 / h
    sxr = ps.xn    # scratch rows (see the module docstring)
    szr = ps.zn
    srho = ps.rhon
    svx = ps.vxn
    svz = ps.vzn
    for i in prange(n):
        sxr[i] = 0.0
        szr[i] = 0.0
        srho[i] = 0.0
        svx[i] = 0.0
        svz[i] = 0.0
        if kind[i] != FLUID:
            continue
        xi = x[i]
        zi = z[i]
        gcx = 0.0
        gcz = 0.0
        bxx = bxz = bzz = 0.0
        # velocity and density gradients (for the first-order carry of v and rho)
        gux = guz = gwx = gwz = grx = grz = 0.0
        cxl, cxh, czl, czh = block_of(cell[i], cells)
        for zz in range(czl, czh + 1):
            row = zz * ncx
            for j in range(cell_start[row + cxl], cell_start[row + cxh + 1]):
                kj = kind[j]
                if j == i or kj < FLUID or kj > OUTLET:
                    continue
                dx = xi - x[j]
                dz = zi - z[j]
                r2 = dx * dx + dz * dz
                if r2 >= s2:
                    continue
                fv = f_of_q(math.sqrt(r2) * inv_h, alpha_f) * m[j] / rho[j]
                # grad_i W_ij = -F r_ij
                gcx -= fv * dx
                gcz -= fv * dz
                bxx += fv * dx * dx
                bxz += fv * dx * dz
                bzz += fv * dz * dz
                if kj != WALL:  # walls carry no flow field of their own
                    du = vx[j] - vx[i]
                    dw = vz[j] - vz[i]
                    gux -= fv * du * dx
                    guz -= fv * du * dz
                    gwx -= fv * dw * dx
                    gwz -= fv * dw * dz
                dr = rho[j] - rho[i]
                grx -= fv * dr * dx
                grz -= fv * dr * dz
        dcoef = coef * h * math.sqrt(vx[i] * vx[i] + vz[i] * vz[i]) * dt
        sx = -dcoef * gcx
        sz = -dcoef * gcz
        if bxx + bzz < fs_div:  # div r = trace B
            # renormalised normal n = -B^-1 grad C / |.| (Marrone et al. 2010; Sun et al. 2017):
            # grad C itself is parallel to the shift and cannot split it
            det = bxx * bzz - bxz * bxz
            if det > 1e-6:
                lx = (bzz * gcx - bxz * gcz) / det
                lz = (bxx * gcz - bxz * gcx) / det
            else:
                lx = gcx
                lz = gcz
            gn = math.sqrt(lx * lx + lz * lz)
            if gn > 0.0:
                nx = -lx / gn
                nz = -lz / gn
                sn = sx * nx + sz * nz
                sx -= sn * nx
                sz -= sn * nz
        s = math.sqrt(sx * sx + sz * sz)
        if s > max_shift:
            sx *= max_shift / s
            sz *= max_shift / s
        sxr[i] = sx
        szr[i] = sz
        # first-order carry of rho and v to the new position
        srho[i] = sx * grx + sz * grz
        svx[i] = sx * gux + sz * guz
        svz[i] = sx * gwx + sz * gwz
    for i in prange(n):
        if kind[i] == FLUID:
            x[i] += sxr[i]
            z[i] += szr[i]
            rho[i] += srho[i]
            vx[i] += svx[i]
            vz[i] += svz[i]
