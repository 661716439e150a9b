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


@njit(parallel=True, cache=True)
def compute_cells(x, z, kind, n, xmin, zmin, inv_cs, ncx, ncz, cell):
    """cell[i] = cz*ncx + cx of particle i (clamped to the grid); inactive -> ncx*ncz."""
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
def counting_sort(cell, n, ncell, cell_start, cursor, order):
    """Stable counting sort of slots by cell: order[k] = slot that goes to position k.

    cell_start (size ncell + 2) receives the first position of each cell (bin ncell = inactive)."""
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
def permute(f, f2, nrows, kind, kind2, ids, ids2, cell, cell2, order, n):
    """Gather particle k of the sorted set from slot order[k] into the twin buffers."""
    for k in prange(n):
        i = order[k]
        for r in range(nrows):
            f2[r, k] = f[r, i]
        kind2[k] = kind[i]
        ids2[k] = ids[i]
        cell2[k] = cell[i]


@njit(cache=True)
def sort_by_cell(f, f2, nrows, kind, kind2, ids, ids2, cell, cell2, order, cell_start, cursor,
                 n, xmin, zmin, inv_cs, ncx, ncz):
    """Bin, counting-sort and gather all particles into the twin buffers (caller swaps)."""
    compute_cells(f[0], f[1], kind, n, xmin, zmin, inv_cs, ncx, ncz, cell)
    counting_sort(cell, n, ncx * ncz, cell_start, cursor, order)
    permute(f, f2, nrows, kind, kind2, ids, ids2, cell, cell2, order, n)


def brute_force_neighbours(x: np.ndarray, z: np.ndarray, radius: float) -> list[set[int]]:
    """Reference O(N^2) neighbour sets (for tests)."""
    d2 = (x[:, None] - x[None, :]) ** 2 + (z[:, None] - z[None, :]) ** 2
    return [set(np.nonzero((row < radius * radius))[0].tolist()) - {i} for i, row in enumerate(d2)]
