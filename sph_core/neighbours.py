"""Cell-list neighbour search: square cells of side 2h / reach, counting sort, reorder.

After ``sort_by_cell`` the particles of cell c are the contiguous slots
``start[c] : start[c + 1]`` (cell index c = cz * ncx + cx), so the (2 reach + 1)^2 block of cells
that covers a particle's support 2h is 2 reach + 1 contiguous runs of slots (``block_of``).
Inactive particles go to an extra bin at the end.
reach = 1 (cells of 2h, 3 x 3 block) tests 36 h^2 of area for a support of 4 pi h^2 (35 % hits);
reach = 2 (cells of h, 5 x 5) tests 25 h^2 (50 % hits): fewer distance tests per neighbour, the
default (bench/sph_throughput.py --cells-per-support measures it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit, prange

from .state import Cells


@dataclass(frozen=True)
class CellGrid:
    """A uniform grid of square cells of side ``cs`` covering [xmin, xmin + ncx cs] x [zmin, ...]."""

    xmin: float
    zmin: float
    cs: float
    ncx: int
    ncz: int
    reach: int = 1  # cells per support radius: the search block is (2 reach + 1)^2 cells

    @classmethod
    def covering(cls, x0: float, x1: float, z0: float, z1: float, support: float,
                 reach: int = 1) -> "CellGrid":
        """A grid of cells of side support / reach over the box, one spare cell on every side."""
        if reach < 1:
            raise ValueError(f"reach: must be >= 1 cell per support, got {reach}")
        cs = support / reach
        ncx = int(math.ceil((x1 - x0) / cs)) + 3
        ncz = int(math.ceil((z1 - z0) / cs)) + 3
        return cls(x0 - cs, z0 - cs, cs, ncx, ncz, reach)

    @property
    def ncell(self) -> int:
        return self.ncx * self.ncz

    def lists(self, capacity: int) -> Cells:
        """Empty cell lists on this grid for ``capacity`` particle slots."""
        return Cells(np.zeros(self.ncell + 2, dtype=np.int64), np.zeros(self.ncell + 1, dtype=np.int64),
                     np.zeros(capacity, dtype=np.int64), self.ncx, self.ncz, float(self.xmin),
                     float(self.zmin), 1.0 / self.cs, self.reach)


@njit(cache=True, inline="always")
def block_of(c, cells):
    """(cxl, cxh, czl, czh): the block of cells within reach of cell c, clipped to the grid; its
    particles are the slots start[zz * ncx + cxl] : start[zz * ncx + cxh + 1], zz in czl..czh."""
    ncx = cells.ncx
    r = cells.reach
    cz = c // ncx
    cx = c - cz * ncx
    return max(cx - r, 0), min(cx + r, ncx - 1), max(cz - r, 0), min(cz + r, cells.ncz - 1)


@njit(cache=True, inline="always")
def cell_at(x, z, cells):
    """Cell index of the point (x, z), clamped to the grid."""
    cx = min(max(int((x - cells.xmin) * cells.inv_cs), 0), cells.ncx - 1)
    cz = min(max(int((z - cells.zmin) * cells.inv_cs), 0), cells.ncz - 1)
    return cz * cells.ncx + cx


@njit(parallel=True, cache=True)
def compute_cells(ps, n, cells):
    """ps.cell[i] = cz*ncx + cx of particle i (clamped to the grid); inactive -> ncx*ncz."""
    x = ps.x
    z = ps.z
    kind = ps.kind
    cell = ps.cell
    ncx = cells.ncx
    ncz = cells.ncz
    xmin = cells.xmin
    zmin = cells.zmin
    inv_cs = cells.inv_cs
    ncell = ncx * ncz
    for i in prange(n):
        if kind[i] < 0:
            cell[i] = ncell
        else:
            cx = int((x[i] - xmin) * inv_cs)
            cz = int((z[i] - zmin) * inv_cs)
            cx = min(max(cx, 0), ncx - 1)
            cz = min(max(cz, 0), ncz - 1)
            cell[i] = cz * ncx + cx


@njit(cache=True)
def counting_sort(cell, n, cells):
    """Stable counting sort of slots by cell: cells.order[k] = slot that goes to position k.

    cells.start (size ncell + 2) receives the first position of each cell (bin ncell = inactive)."""
    ncell = cells.ncx * cells.ncz
    cell_start = cells.start
    cursor = cells.cursor
    order = cells.order
    for c in range(ncell + 2):
        cell_start[c] = 0
    for i in range(n):
        cell_start[cell[i] + 1] += 1
    for c in range(ncell + 1):
        cell_start[c + 1] += cell_start[c]
    for c in range(ncell + 1):
        cursor[c] = cell_start[c]
    for i in range(n):
        c = cell[i]
        order[cursor[c]] = i
        cursor[c] += 1


@njit(parallel=True, cache=True)
def permute(ps, ps2, nrows, order, n):
    """Gather particle k of the sorted set from slot order[k] into the twin buffer."""
    f = ps.f
    f2 = ps2.f
    kind = ps.kind
    kind2 = ps2.kind
    ids = ps.ids
    ids2 = ps2.ids
    cell = ps.cell
    cell2 = ps2.cell
    for k in prange(n):
        i = order[k]
        for r in range(nrows):
            f2[r, k] = f[r, i]
        kind2[k] = kind[i]
        ids2[k] = ids[i]
        cell2[k] = cell[i]


@njit(cache=True)
def sort_by_cell(ps, ps2, nrows, n, cells):
    """Bin, counting-sort and gather the first ``nrows`` rows of all particles into the twin
    buffer ``ps2`` (the caller swaps); returns the slots in use after it (inactive ones dropped)."""
    compute_cells(ps, n, cells)
    counting_sort(ps.cell, n, cells)
    permute(ps, ps2, nrows, cells.order, n)
    return cells.start[cells.ncx * cells.ncz]


def brute_force_neighbours(x: np.ndarray, z: np.ndarray, radius: float) -> list[set[int]]:
    """Reference O(N^2) neighbour sets (for tests)."""
    d2 = (x[:, None] - x[None, :]) ** 2 + (z[:, None] - z[None, :]) ** 2
    return [set(np.nonzero((row < radius * radius))[0].tolist()) - {i} for i, row in enumerate(d2)]
