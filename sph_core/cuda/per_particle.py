"""Per-particle bodies of the CUDA step's kernels, one ``@njit(inline="always")`` function per pass.

Each is the loop body of its CPU twin in ``sph_core/wcsph.py`` / ``neighbours.py`` for one
particle slot ``i``; the passes' pairs are the CPU's own: ``pairs.gather`` folding the pair
terms of ``terms.py`` (``adami_pair``, ``wcsph_pair``, ``riemann_pair``), so a term changed
there changes on both devices. The schemes' bodies (predictor, corrector, shifting, MUSCL
gradients) live beside their CPU passes (``gpu_schemes.py`` lists them). numba
compiles these for whichever target calls them: as device functions inside the CUDA kernels
of ``gpu_kernels.py`` and as ordinary CPU code under the CUDA simulator (compiled speed).
"""

from __future__ import annotations

from numba import njit

from ..neighbours import cell_at
from ..wcsph import _guard, _outside, kdk_pressure


@njit(cache=True, inline="always")
def cell_of(i, ps, cells):
    """ps.cell of slot i as ``neighbours.compute_cells`` sets it: clamped to the grid, inactive
    slots in the extra bin ncx * ncy * ncz."""
    if ps.kind[i] < 0:
        return cells.ncx * cells.ncy * cells.ncz
    return cell_at(ps.x[i], ps.y[i], ps.z[i], cells)


@njit(cache=True, inline="always")
def kick_drift_particle(i, ps, dt, prm):
    """``wcsph.kdk_kick_drift`` for fluid slot i; True if it ends outside the fluid box."""
    hdt = 0.5 * dt
    ps.vx[i] += hdt * ps.ax[i]
    ps.vz[i] += hdt * ps.az[i]
    r = ps.rho[i] + hdt * ps.drho[i]
    ps.rho[i] = r
    ps.p[i] = kdk_pressure(r, ps.drho[i], dt, prm)
    xi = ps.x[i] + dt * ps.vx[i]
    zi = ps.z[i] + dt * ps.vz[i]
    ps.x[i] = xi
    ps.z[i] = zi
    yi = 0.0
    if prm.three is not None:   # 2D (when compiled): the y rows stay zero
        ps.vy[i] += hdt * ps.ay[i]
        yi = ps.y[i] + dt * ps.vy[i]
        ps.y[i] = yi
    return _outside(xi, yi, zi, prm) == 1


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
    v = ay = 0.0
    if prm.three is not None:   # 2D (when compiled): the y rows stay zero
        ay = ps.ay[i]
        v = ps.vy[i] + hdt * ay + ps.dvny[i]
        ps.vy[i] = v
    bad, band, v2, a2 = _guard(u, v, w, r, ax, ay, az, prm.rho_lo * prm.rho0,
                               prm.rho_hi * prm.rho0)
    return v2, a2, r, 1 if bad else (2 if band else 0)


@njit(cache=True, inline="always")
def permute_slot(buf, buf2, i, k, nrows):
    """``neighbours.permute`` for sorted position k: the first ``nrows`` rows, kind, ids and cell
    of slot i of buffer ``buf`` into position k of its twin (buffers as (f, kind, ids, cell))."""
    f = buf[0]
    f2 = buf2[0]
    for r in range(nrows):
        f2[r, k] = f[r, i]
    buf2[1][k] = buf[1][i]
    buf2[2][k] = buf[2][i]
    buf2[3][k] = buf[3][i]


@njit(cache=True, inline="always")
def clear_rows(f, i, r0, r1):
    """Rows r0..r1 (inclusive) of slot i of the storage f set to zero (a pass's scratch rows)."""
    for r in range(r0, r1 + 1):
        f[r, i] = 0.0
