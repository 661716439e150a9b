"""Probes: kernel-interpolated velocity and pressure at points, free-surface gauges, dam-break front.

Point values are Shepard-normalised kernel interpolations over fluid particles:
    f(x) = sum_j f_j V_j W(x - x_j) / sum_j V_j W(x - x_j),  V_j = m_j / rho_j.
Elevation (seed 004, "second method"): fixed interpolation points on a vertical line at spacing
dp/2 carry the kernel mass density rho_f(z) = sum_j m_j W (the "fake density" of seed 004, eq. 23);
the surface is the highest z where rho_f falls through ``threshold * rho0`` (linear interpolation
between line points). For a flat surface rho_f drops to rho0/2 exactly at the surface, hence the
default threshold 0.5; seed 004's free-surface criterion rho_f <= 0.9 rho0 marks a level about
half a particle below it. No point above the threshold: the gauge is dry (reported as None).
Front: the largest x of the fluid particles that have at least ``min_neighbours`` fluid
neighbours within the kernel support 2h, so isolated droplets ahead of the surge do not count.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from .kernels import f_of_q, w_of_q
from .neighbours import block_of, cell_at
from .particles import FLUID, INLET, OUTLET


@njit(cache=True)
def interpolate_points(ps, cells, xs, zs, h, alpha_w, out):
    """out[k] = (u, w, p, sum V W) at point k (Shepard-normalised; zeros where sum V W = 0)."""
    x = ps.x
    z = ps.z
    kind = ps.kind
    cell_start = cells.start
    ncx = cells.ncx
    s2 = 4.0 * h * h
    for k in range(xs.size):
        cxl, cxh, czl, czh = block_of(cell_at(xs[k], zs[k], cells), cells)
        su = 0.0
        sw_ = 0.0
        sp = 0.0
        sv = 0.0
        for zz in range(czl, czh + 1):
            row = zz * ncx
            for j in range(cell_start[row + cxl], cell_start[row + cxh + 1]):
                if kind[j] == FLUID:
                    dx = xs[k] - x[j]
                    dz = zs[k] - z[j]
                    r2 = dx * dx + dz * dz
                    if r2 < s2:
                        vw = ps.m[j] / ps.rho[j] * w_of_q(math.sqrt(r2) / h, alpha_w)
                        sv += vw
                        su += ps.vx[j] * vw
                        sw_ += ps.vz[j] * vw
                        sp += ps.p[j] * vw
        if sv > 0.0:
            out[k, 0] = su / sv
            out[k, 1] = sw_ / sv
            out[k, 2] = sp / sv
        else:
            out[k, 0] = 0.0
            out[k, 1] = 0.0
            out[k, 2] = 0.0
        out[k, 3] = sv


@njit(cache=True)
def line_mass_density(ps, cells, xp, zs, h, alpha_w, out):
    """out[k] = sum_j m_j W at (xp, zs[k]) over fluid particles (seed 004, eq. 23)."""
    x = ps.x
    z = ps.z
    kind = ps.kind
    cell_start = cells.start
    ncx = cells.ncx
    s2 = 4.0 * h * h
    for k in range(zs.size):
        cxl, cxh, czl, czh = block_of(cell_at(xp, zs[k], cells), cells)
        s = 0.0
        for zz in range(czl, czh + 1):
            row = zz * ncx
            for j in range(cell_start[row + cxl], cell_start[row + cxh + 1]):
                if kind[j] == FLUID:
                    dx = xp - x[j]
                    dz = zs[k] - z[j]
                    r2 = dx * dx + dz * dz
                    if r2 < s2:
                        s += ps.m[j] * w_of_q(math.sqrt(r2) / h, alpha_w)
        out[k] = s


def surface_from_line(zs: np.ndarray, rho_f: np.ndarray, level: float) -> float | None:
    """Highest z where rho_f crosses ``level`` from above (linear between points); None if dry."""
    above = np.nonzero(rho_f >= level)[0]
    if above.size == 0:
        return None
    k = above[-1]
    if k == zs.size - 1:
        return float(zs[-1])
    a, b = rho_f[k], rho_f[k + 1]
    return float(zs[k] + (a - level) / (a - b) * (zs[k + 1] - zs[k]))


@njit(parallel=True, cache=True)
def fluid_neighbour_counts(ps, n, cells, h, counts):
    """counts[i] = number of fluid neighbours within 2h of fluid particle i (-1 for others)."""
    x = ps.x
    z = ps.z
    kind = ps.kind
    cell = ps.cell
    cell_start = cells.start
    ncx = cells.ncx
    s2 = 4.0 * h * h
    for i in prange(n):
        if kind[i] != FLUID:
            counts[i] = -1
        else:
            cxl, cxh, czl, czh = block_of(cell[i], cells)
            k = 0
            for zz in range(czl, czh + 1):
                row = zz * ncx
                for j in range(cell_start[row + cxl], cell_start[row + cxh + 1]):
                    if j != i and kind[j] == FLUID:
                        dx = x[i] - x[j]
                        dz = z[i] - z[j]
                        if dx * dx + dz * dz < s2:
                            k += 1
            counts[i] = k


@njit(cache=True)
def wall_force(ps, cells, slots, xm, zm, h, alpha_f):
    """(F_x, F_z, M_y) the fluid exerts on the wall particles ``slots``: minus the pressure pair
    forces m_f m_s (max(p_f, 0) + p_s)/(rho_f rho_s) F_fs r_fs of wcsph.fluid_pass; M_y about (xm, zm).
    No tension across a wall: fluid_pass drops it only while p_f approaches the wall (its pw row),
    but a probe reads the state after the step's sort, where that row is not carried."""
    x = ps.x
    z = ps.z
    kind = ps.kind
    cell_start = cells.start
    ncx = cells.ncx
    s2 = 4.0 * h * h
    fx = 0.0
    fz = 0.0
    my = 0.0
    for k in range(slots.size):
        s = slots[k]
        xs = x[s]
        zs = z[s]
        cxl, cxh, czl, czh = block_of(cell_at(xs, zs, cells), cells)
        p_s = ps.p[s]
        c_s = ps.m[s] / ps.rho[s]  # m_s / rho_s
        sx = 0.0
        sz = 0.0
        for zz in range(czl, czh + 1):
            row = zz * ncx
            for j in range(cell_start[row + cxl], cell_start[row + cxh + 1]):
                kj = kind[j]
                if kj == FLUID or kj == INLET or kj == OUTLET:
                    dx = x[j] - xs
                    dz = z[j] - zs
                    r2 = dx * dx + dz * dz
                    if r2 < s2:
                        pf = c_s * ps.m[j] * (max(ps.p[j], 0.0) + p_s) / ps.rho[j]
                        fij = f_of_q(math.sqrt(r2) / h, alpha_f)
                        # force on the fluid particle is +pf F r_fs; the wall gets the reaction
                        sx -= pf * fij * dx
                        sz -= pf * fij * dz
        fx += sx
        fz += sz
        my += (zs - zm) * sx - (xs - xm) * sz
    return fx, fz, my
