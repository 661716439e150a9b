"""The one neighbour walk of the solver, and the particle-kind selectors it filters with.

    acc = gather(i, xi, yi, zi, c, ps, cells, s2, select, term, ctx, acc)

visits every slot j != i in the cell block around cell ``c`` whose kind passes
``select(kind_j)`` and that lies within sqrt(s2) of (xi, yi, zi), and folds it into the
accumulator with ``acc = term(i, j, dx, dy, dz, r2, ps, ctx, acc)``, where dx = xi - x_j,
dy = yi - y_j, dz = zi - z_j, r2 = dx^2 + dy^2 + dz^2. ``i`` is the walking particle's slot,
or -1 around a point (probes, boundary gauges); ``ctx`` is whatever the term reads besides the
particles (Params, a tuple of per-particle values, ...); ``acc`` a number or a NamedTuple of
numbers.

Dimensions: every term is written once for three components. A 2D scene (one layer of cells
in y, ``cells.three`` None: a type, so decided when compiled) walks one layer and gets dy = the
constant 0 without reading y, so its sums are the 2D sums (to the sign of a zero).

Every pass that needs neighbours (wcsph, riemann, renormalisation, shifting, isph, bodies,
probes, open ends) walks through ``gather``; the per-pair physics lives in ``terms.py``.
``select`` and ``term`` are jitted functions passed as arguments: numba types each as a
compile-time constant and specialises ``gather`` per (select, term), so after inlining the
loop is the hand-written one (same code, same speed; bench/refactor_check.py checks the
results are bit-identical), and every pass stays a module-level ``cache=True`` function whose
cache a second process loads.

Cells (neighbours.py): cell c = (cz * ncy + cy) * ncx + cx holds slots start[c]:start[c + 1];
the block within reach of a cell is rows of contiguous slot runs (``block_of``).
"""

from __future__ import annotations

from numba import njit

from .neighbours import block_of
from .particles import FLUID, INLET, OUTLET, WALL


@njit(cache=True, inline="always")
def gather(i, xi, yi, zi, c, ps, cells, s2, select, term, ctx, acc):
    """Fold ``term`` over the neighbours of (xi, yi, zi) in cell ``c``'s block (module
    docstring)."""
    x = ps.x
    y = ps.y
    z = ps.z
    kind = ps.kind
    start = cells.start
    ncx = cells.ncx
    ncy = cells.ncy
    cxl, cxh, cyl, cyh, czl, czh = block_of(c, cells)
    for zz in range(czl, czh + 1):
        for yy in range(cyl, cyh + 1):
            row = (zz * ncy + yy) * ncx   # (2D: ncy = 1, yy = 0)
            for j in range(start[row + cxl], start[row + cxh + 1]):
                if j == i or not select(kind[j]):
                    continue
                dx = xi - x[j]
                dz = zi - z[j]
                # a 2D grid (cells.three None, decided when compiled): dy is the constant 0
                dy = 0.0 if cells.three is None else yi - y[j]
                r2 = dx * dx + dy * dy + dz * dz
                if r2 < s2:
                    acc = term(i, j, dx, dy, dz, r2, ps, ctx, acc)
    return acc


# Kind selectors. INACTIVE (-1) and idle buffer slots (> OUTLET) never interact; active buffer
# particles (INLET, OUTLET) act as fluid with an imposed velocity.

@njit(cache=True, inline="always")
def interacting(k):
    """Fluid, wall and active buffer particles: the neighbours of a fluid particle."""
    return k >= FLUID and k <= OUTLET


@njit(cache=True, inline="always")
def fluidlike(k):
    """Fluid and active buffer particles: the neighbours that carry the flow (the Adami wall
    extrapolation, probes)."""
    return k == FLUID or k == INLET or k == OUTLET


@njit(cache=True, inline="always")
def fluid_only(k):
    """Fluid particles alone."""
    return k == FLUID


@njit(cache=True, inline="always")
def wall_only(k):
    """Wall particles alone (tank, structures, bodies)."""
    return k == WALL
