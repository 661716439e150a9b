"""No penetration at wall faces: a fluid particle that comes within dp/4 of a wall face loses
its velocity towards the wall (the no-penetration correction DualSPHysics 5.4 adds to its mDBC
walls, "NoPenetration"; read, not copied: JSphCpu.cpp ComputeNoPenVel).

Why (docs/studies/wall_pressure.md, 2026-11-23 "the dry-bed front"): the Adami wall (wcsph.wall_pass)
resists a fluid particle only through the particle's density, and a particle can approach the
wall at constant density: in a thin film stretched along a bed (a dam break's front) continuity
keeps the bottom particle's density only if it approaches the wall particles at
w = -(du/dx) / sum_s V_s F_is z_is (~ -h du/dx, 5x the continuum's -z du/dx), and it sinks at
that speed between the wall particles and out of the tank.

Rule, for fluid particle i and its wall neighbours s (V_s = m_s / rho0):
    g_i = sum_s V_s W_is            the wall's share of i's kernel: a distance to the face
    n_i = sum_s V_s F_is r_is / |.| the wall normal at i, into the fluid (r_is = r_i - r_s)
    u_n = (v_i - sum_s V_s W_is v_s / g_i) . n_i     the approach speed (< 0: towards the wall)
    if u_n < 0:  dv_i = -f(g_i) u_n n_i,
f = 0 until dp/4 in front of the face, 1 at the face (the approach stopped), 2 from dp/4 behind
it (reflected), linear in between in g; the shares at those three distances (``face_shares``)
are those of a flat wall of the run's layers. The correction is a velocity change added by the
kick (kdk) or corrector (symplectic_pc) after the force pass; it needs no wall normals or face
positions stored, so it holds for beds, structures and bodies alike. Its impulse is not passed
to bodies or force probes (it is zero unless a particle is within dp/4 of a face: never in the
still or wave runs measured, whose fluid stays >= 0.4 dp from the faces).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


def face_shares(h: float, dp: float, n_layers: int, alpha_w: float,
                dim: int = 2) -> tuple[float, float, float]:
    """The wall share sum_s V_s W_is of a point dp/4 in front of a flat wall face, at it and
    dp/4 behind it (wall particles on the dp lattice, n_layers deep, first row dp/2 behind; in
    3D a plane of such rows)."""
    k = math.ceil(2.0 * h / dp) + 2
    xs = (np.arange(-k, k + 1)) * dp
    zs = -(np.arange(n_layers) + 0.5) * dp
    ys = xs if dim == 3 else np.zeros(1)
    gx, gy, gz = np.meshgrid(xs, ys, zs)
    vol = dp ** dim
    out = []
    for d in (0.25 * dp, 0.0, -0.25 * dp):
        q = np.sqrt(gx * gx + gy * gy + (gz - d) ** 2) / h
        t = np.clip(1.0 - 0.5 * q, 0.0, None)
        out.append(float(np.sum(alpha_w * t ** 4 * (2.0 * q + 1.0)) * vol))
    return out[0], out[1], out[2]


@njit(cache=True, inline="always")
def approach_speed(g, nx, ny, nz, gvx, gvy, gvz, vx, vy, vz):
    """u_n of a fluid particle with velocity (vx, vy, vz) against its walls (< 0: towards
    them); 0 without wall neighbours. g, n, gv as in ``no_penetration``."""
    nn = math.sqrt(nx * nx + ny * ny + nz * nz)
    if g <= 0.0 or nn <= 0.0:
        return 0.0
    return ((vx - gvx / g) * nx + (vy - gvy / g) * ny + (vz - gvz / g) * nz) / nn


@njit(cache=True, inline="always")
def no_penetration(g, nx, ny, nz, gvx, gvy, gvz, vx, vy, vz, ga, g0, gb):
    """Velocity change (dvx, dvy, dvz) of a fluid particle with velocity v, wall share g,
    unnormalised normal n and sum_s V_s W_is v_s = gv; zero if g <= ga."""
    if g <= ga:
        return 0.0, 0.0, 0.0
    un = approach_speed(g, nx, ny, nz, gvx, gvy, gvz, vx, vy, vz)
    if un >= 0.0:
        return 0.0, 0.0, 0.0
    nn = math.sqrt(nx * nx + ny * ny + nz * nz)
    if g <= g0:
        f = (g - ga) / (g0 - ga)
    else:
        f = min(1.0 + (g - g0) / (gb - g0), 2.0)
    return -f * un * nx / nn, -f * un * ny / nn, -f * un * nz / nn
