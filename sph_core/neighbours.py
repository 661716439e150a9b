"""Cell-list neighbour search: cells of side 2h (the kernel support), counting sort, reorder.

After ``sort_by_cell`` the particles of cell c are the contiguous slots
``cell_start[c] : cell_start[c + 1]`` (cell index c = cz * ncx + cx), so the 3 x 3 block around a
particle is three contiguous runs of slots. Inactive particles go to an extra bin at the end.
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

    @classmethod
    def covering(cls, x0: float, x1: float, z0: float, z1: float, cs: float) -> "CellGrid":
        """A grid over the box with one spare cell on every side."""
        ncx = int(math.ceil((x1 - x0) / cs)) + 3
        ncz = int(math.ceil((z1 - z0) / cs)) + 3
        return cls(x0 - cs, z0 - cs, cs, ncx, ncz)

    @property
    def ncell(self) -> int:
        return self.ncx * self.ncz

    def lists(self, capacity: int) -> Cells:
        """Empty cell lists on this grid for ``capacity`` particle slots."""
        return Cells(np.zeros(self.ncell + 2, dtype=np.int64), np.zeros(self.ncell + 1, dtype=np.int64),
                     np.zeros(capacity, dtype=np.int64), self.ncx, self.ncz, float(self.xmin),
                     float(self.zmin), 1.0 / self.cs)


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
