"""Test helper: particle rows sorted by the cells of a grid, as the simulation's sort leaves them,
and the Cells the kernels walk."""

from __future__ import annotations

import numpy as np

from sph_core.neighbours import CellGrid
from sph_core.particles import X, Z
from sph_core.state import Cells


def sort_into_cells(f: np.ndarray, kind: np.ndarray, h: float,
                    box: tuple[float, float, float, float]):
    """Sort the rows f[:, k] and kinds k by cell of a grid of side h (reach 2, as the simulation's)
    covering box = (x0, x1, z0, z1); returns (f, kind, cell, cells, order): the sorted copies, the
    cell of each slot, the Cells, and order (slot s holds the input's particle order[s])."""
    grid = CellGrid.covering(*box, 2.0 * h, reach=2)
    cell = ((np.floor((f[Z] - grid.zmin) / grid.cs).astype(np.int64)) * grid.ncx
            + np.floor((f[X] - grid.xmin) / grid.cs).astype(np.int64))
    order = np.argsort(cell, kind="stable")
    f, kind, cell = f[:, order].copy(), kind[order].copy(), cell[order].copy()
    start = np.searchsorted(cell, np.arange(grid.ncell + 2)).astype(np.int64)
    n = kind.size
    cells = Cells(start, np.zeros(grid.ncell + 1, dtype=np.int64), np.zeros(n, dtype=np.int64),
                  grid.ncx, grid.ncz, grid.xmin, grid.zmin, 1.0 / grid.cs, grid.reach)
    return f, kind, cell, cells, order
