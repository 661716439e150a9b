"""Per-particle bodies of the CUDA step's kernels, one ``@njit(inline="always")`` function per pass.

Each is the loop body of its CPU twin in ``sph_core/wcsph.py`` / ``neighbours.py`` for one
particle slot ``i``; the passes' pairs are the CPU's own: ``pairs.gather`` folding the pair
terms of ``terms.py`` (``adami_pair``, ``wcsph_pair``), so a term changed there changes on
both devices. Riemann SPH is not carried yet (the GPU step refuses such scenes). numba
compiles these for whichever target calls them: as device functions inside the CUDA kernels
of ``gpu_kernels.py`` and as ordinary CPU code under the CUDA simulator (compiled speed).
"""

from __future__ import annotations

import math

from numba import njit

from ..eos import density, pressure
from ..neighbours import cell_at
from ..pairs import fluidlike, gather, interacting
from ..terms import (FLUID_SUMS_ZERO, WALL_SUMS_ZERO, adami_pair, fluid_consts, fluid_i,
                     wcsph_pair)
from ..wall_contact import approach_speed, no_penetration


@njit(cache=True, inline="always")
def cell_of(i, ps, cells):
    """ps.cell of slot i as ``neighbours.compute_cells`` sets it: clamped to the grid, inactive
    slots in the extra bin ncx * ncz."""
    if ps.kind[i] < 0:
        return cells.ncx * cells.ncz
    return cell_at(ps.x[i], ps.z[i], cells)


@njit(cache=True, inline="always")
def wall_particle(i, ps, cells, prm):
    """``wcsph.wall_pass`` for wall slot i: Adami pressure, density and no-slip velocity, from
    the shared pair term ``terms.adami_pair``."""
    h = prm.h
    ctx = (1.0 / h, prm.alpha_w, prm.gx - ps.ax[i], prm.gz - ps.az[i])
    s = gather(i, ps.x[i], ps.z[i], ps.cell[i], ps, cells, 4.0 * h * h, fluidlike, adami_pair,
               ctx, WALL_SUMS_ZERO)
    if s.sw > 0.0:
        pi = max(s.sp / s.sw, 0.0)   # no suction (wcsph.wall_pass)
        ps.p[i] = pi
        ps.rho[i] = density(pi, prm.rho0, prm.b, prm.gamma)
        ps.vwx[i] = 2.0 * ps.vx[i] - s.svx / s.sw
        ps.vwz[i] = 2.0 * ps.vz[i] - s.svz / s.sw
    else:
        ps.p[i] = 0.0
        ps.rho[i] = prm.rho0
        ps.vwx[i] = ps.vx[i]
        ps.vwz[i] = ps.vz[i]


# terms.fluid_consts / fluid_i are plain (not inlined) @njit functions: their same source,
# inlined, so every device callee is inlined (the form compile_ptx verifies without a GPU)
_fluid_consts = njit(inline="always")(fluid_consts.py_func)
_fluid_i = njit(inline="always")(fluid_i.py_func)


@njit(cache=True, inline="always")
def fluid_particle(i, ps, cells, prm):
    """``wcsph.fluid_pass`` for fluid slot i in its delta-SPH form (the shared pair term
    ``terms.wcsph_pair``): writes ax, az, drho, pw and, with the no-penetration correction on,
    dvnx, dvnz."""
    k = _fluid_consts(prm)
    fi = _fluid_i(i, ps, k)
    a = gather(i, fi.x, fi.z, ps.cell[i], ps, cells, k.s2, interacting, wcsph_pair, (k, fi),
               FLUID_SUMS_ZERO)
    fx = a.fx
    fz = a.fz
    # the approach-gated wall tension (wcsph.fluid_pass)
    pwi = fi.p
    if fi.p < 0.0 and approach_speed(a.gw, a.gnx, a.gnz, a.gvx, a.gvz, fi.vx, fi.vz) < 0.0:
        fx += a.tx
        fz += a.tz
        pwi = 0.0
    ps.pw[i] = pwi
    ps.ax[i] = fx + prm.gx
    ps.az[i] = fz + prm.gz
    ps.drho[i] = fi.rho * a.cont + k.ddiff * a.diff
    if prm.wall_g0 > 0.0:
        ps.dvnx[i], ps.dvnz[i] = no_penetration(a.gw, a.gnx, a.gnz, a.gvx, a.gvz, fi.vx, fi.vz,
                                                prm.wall_ga, prm.wall_g0, prm.wall_gb)


@njit(cache=True, inline="always")
def kick_drift_particle(i, ps, dt, prm):
    """``wcsph.kdk_kick_drift`` for fluid slot i; True if it ends outside the fluid box."""
    hdt = 0.5 * dt
    ps.vx[i] += hdt * ps.ax[i]
    ps.vz[i] += hdt * ps.az[i]
    r = ps.rho[i] + hdt * ps.drho[i]
    ps.rho[i] = r
    ps.p[i] = pressure(r + hdt * ps.drho[i], prm.rho0, prm.b, prm.gamma)
    xi = ps.x[i] + dt * ps.vx[i]
    zi = ps.z[i] + dt * ps.vz[i]
    ps.x[i] = xi
    ps.z[i] = zi
    return not (xi >= prm.fx0 and xi <= prm.fx1 and zi >= prm.fz0 and zi <= prm.fz1)


@njit(cache=True, inline="always")
def kick_particle(i, ps, dt, prm):
    """``wcsph.kdk_kick`` for fluid slot i; returns (v^2, a^2, rho, guard) with guard 0 ok,
    1 non-finite, 2 outside the density band."""
    hdt = 0.5 * dt
    ax = ps.ax[i]
    az = ps.az[i]
    u = ps.vx[i] + hdt * ax + ps.dvnx[i]
    w = ps.vz[i] + hdt * az + ps.dvnz[i]
    r = ps.rho[i] + hdt * ps.drho[i]
    ps.vx[i] = u
    ps.vz[i] = w
    ps.rho[i] = r
    v2 = u * u + w * w
    a2 = ax * ax + az * az
    guard = 0
    if not (math.isfinite(v2) and math.isfinite(r) and math.isfinite(a2)):
        guard = 1
    elif r < prm.rho_lo * prm.rho0 or r > prm.rho_hi * prm.rho0:
        guard = 2
    return v2, a2, r, guard
