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
Run-up: the same wet-particle rule for the shoreline on a beach, its elevation read on the bed.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange
from numpy.typing import ArrayLike

from .kernels import w_of_q
from .neighbours import cell_at
from .pairs import fluid_only, fluidlike, gather
from .particles import FLUID
from .terms import fluid_consts, kernel_f, mass_pair, pressure_factor


@njit(cache=True, inline="always")
def _point_pair(i, j, dx, dy, dz, r2, ps, ctx, a):
    """Shepard sums (sum V W, sum u V W, sum w V W, sum p V W, sum v V W) at a point;
    ctx = (h, alpha_w)."""
    vw = ps.m[j] / ps.rho[j] * w_of_q(math.sqrt(r2) / ctx[0], ctx[1])
    return (a[0] + vw, a[1] + ps.vx[j] * vw, a[2] + ps.vz[j] * vw, a[3] + ps.p[j] * vw,
            a[4] + ps.vy[j] * vw)


@njit(cache=True, inline="always")
def _count_pair(i, j, dx, dy, dz, r2, ps, ctx, a):
    return a + 1


@njit(cache=True, inline="always")
def _wall_pressure_pair(i, j, dx, dy, dz, r2, ps, k, a):
    """Wall particle i and fluid neighbour j: the fluid-wall pair's pressure force on j,
    m_j V_i (max(p_j, 0) + p_i) / rho_j F_ij r_ji, summed with the opposite sign (the wall's
    reaction). a = (fx, fy, fz)."""
    rhoj = ps.rho[j]
    pf = ps.m[j] * pressure_factor(ps.m[i] / ps.rho[i], max(ps.p[j], 0.0), ps.p[i], 1.0 / rhoj)
    fij = kernel_f(r2, k)
    # dx = x_i - x_j: the force on j is +pf F (x_j - x_i), the wall gets minus it
    return a[0] + pf * fij * dx, a[1] + pf * fij * dy, a[2] + pf * fij * dz


@njit(cache=True)
def interpolate_points(ps, cells, xs, ys, zs, h, alpha_w, out):
    """out[k] = (u, w, p, sum V W, v) at point (xs, ys, zs)[k] (Shepard-normalised; zeros where
    sum V W = 0); ys is ignored in a 2D scene."""
    s2 = 4.0 * h * h
    for k in range(xs.size):
        sv, su, sw_, sp, sv_ = gather(-1, xs[k], ys[k], zs[k], cell_at(xs[k], ys[k], zs[k], cells),
                                      ps, cells, s2, fluid_only, _point_pair, (h, alpha_w),
                                      (0.0, 0.0, 0.0, 0.0, 0.0))
        if sv > 0.0:
            out[k, 0] = su / sv
            out[k, 1] = sw_ / sv
            out[k, 2] = sp / sv
            out[k, 4] = sv_ / sv
        else:
            out[k, 0] = 0.0
            out[k, 1] = 0.0
            out[k, 2] = 0.0
            out[k, 4] = 0.0
        out[k, 3] = sv


@njit(cache=True)
def line_mass_density(ps, cells, xp, yp, zs, h, alpha_w, out):
    """out[k] = sum_j m_j W at (xp, yp, zs[k]) over fluid particles (seed 004, eq. 23)."""
    s2 = 4.0 * h * h
    for k in range(zs.size):
        out[k] = gather(-1, xp, yp, zs[k], cell_at(xp, yp, zs[k], cells), ps, cells, s2,
                        fluid_only, mass_pair, (h, alpha_w), 0.0)


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
    kind = ps.kind
    s2 = 4.0 * h * h
    for i in prange(n):
        if kind[i] != FLUID:
            counts[i] = -1
        else:
            counts[i] = gather(i, ps.x[i], ps.y[i], ps.z[i], ps.cell[i], ps, cells, s2, fluid_only,
                               _count_pair, 0, 0)


@njit(cache=True)
def wall_force(ps, cells, slots, xm, ym, zm, prm):
    """(F_x, F_y, F_z, M_x, M_y, M_z) the fluid exerts on the wall particles ``slots``: the
    reaction of the pressure part of the fluid pass's fluid-wall pair (terms.wall_momentum) with
    max(p_f, 0), on fluid and buffer neighbours; the moment about (xm, ym, zm) (2D: M_y alone).
    No tension across a wall: the fluid pass drops it only while p_f approaches the wall (its pw
    row), but a probe reads the state after the step's sort, where that row is not carried."""
    k = fluid_consts(prm)
    fx = 0.0
    fy = 0.0
    fz = 0.0
    mx = 0.0
    my = 0.0
    mz = 0.0
    for q in range(slots.size):
        s = slots[q]
        xs = ps.x[s]
        ys = ps.y[s]
        zs = ps.z[s]
        sx, sy, sz = gather(s, xs, ys, zs, cell_at(xs, ys, zs, cells), ps, cells, k.s2, fluidlike,
                            _wall_pressure_pair, k, (0.0, 0.0, 0.0))
        fx += sx
        fy += sy
        fz += sz
        rx = xs - xm
        ry = ys - ym
        rz = zs - zm
        mx += ry * sz - rz * sy
        my += rz * sx - rx * sz
        mz += rx * sy - ry * sx
    return fx, fy, fz, mx, my, mz


def bed_elevation(beds: list[list[tuple[float, float]]], z_floor: float, x: ArrayLike) -> np.ndarray:
    """Top of the bed at x [m]: the highest of the bed polylines ``beds`` that span x (linear
    between their points), else the tank floor ``z_floor``."""
    xa = np.asarray(x, dtype=float)
    top = np.full(xa.shape, float(z_floor))
    for pts in beds:
        bx, bz = np.asarray(pts, dtype=float).T
        inside = (xa >= bx[0]) & (xa <= bx[-1])
        top = np.where(inside, np.maximum(top, np.interp(xa, bx, bz)), top)
    return top


def shoreline(x: np.ndarray, z: np.ndarray, counts: np.ndarray, min_neighbours: int,
              beds: list[list[tuple[float, float]]], z_floor: float,
              near_bed: float | None = None) -> tuple[float, float] | None:
    """(x, z) [m] of the shoreline particle: of the particles with ``counts`` >= ``min_neighbours``
    fluid neighbours (counts < 0 marks non-fluid) and, with ``near_bed``, at most that height
    above the bed, the one of largest x. None: nothing wet.

    Its centre z is the estimate: the true water line lies within about dp/2 of it (still water
    on the lattice: the top row's centre, dp/2 below the surface; a one-particle film running up:
    dp/2 above the bed)."""
    sel = counts >= max(min_neighbours, 0)
    if near_bed is not None:
        sel &= z - bed_elevation(beds, z_floor, x) <= near_bed
    if not sel.any():
        return None
    k = int(np.argmax(np.where(sel, x, -np.inf)))
    return float(x[k]), float(z[k])
