"""Cell-list neighbour search: cubic cells of side 2h / reach, counting sort, reorder.

After ``sort_by_cell`` the particles of cell c are the contiguous slots
``start[c] : start[c + 1]`` (cell index c = (cz * ncy + cy) * ncx + cx; a 2D scene has ncy = 1),
so the block of cells that covers a particle's support 2h is (2 reach + 1)^(dim - 1) contiguous
runs of slots (``block_of``). Inactive particles go to an extra bin at the end.
reach = 1 (cells of 2h, 3 x 3 block) tests 36 h^2 of area for a support of 4 pi h^2 (35 % hits);
reach = 2 (cells of h, 5 x 5) tests 25 h^2 (50 % hits): fewer distance tests per neighbour, the
default (bench/sph_throughput.py --cells-per-support measures it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit, prange

from .particles import N_SORTED_PC, N_SORTED_Y_KDK, N_SORTED_Y_PC, Y
from .state import Cells


@dataclass(frozen=True)
class CellGrid:
    """A uniform grid of cubic cells of side ``cs`` covering [xmin, xmin + ncx cs] x
    [ymin, ymin + ncy cs] x [zmin, ...]; ncy = 1 (and ymin 0): a 2D scene's single layer."""

    xmin: float
    zmin: float
    cs: float
    ncx: int
    ncz: int
    reach: int = 1  # cells per support radius: the search block is (2 reach + 1)^dim cells
    ncy: int = 1
    ymin: float = 0.0

    @classmethod
    def covering(cls, x0: float, x1: float, z0: float, z1: float, support: float,
                 reach: int = 1, y0: float | None = None, y1: float | None = None) -> "CellGrid":
        """A grid of cells of side support / reach over the box, one spare cell on every side
        (in y too when [y0, y1] is given: a 3D scene)."""
        if reach < 1:
            raise ValueError(f"reach: must be >= 1 cell per support, got {reach}")
        cs = support / reach
        ncx = int(math.ceil((x1 - x0) / cs)) + 3
        ncz = int(math.ceil((z1 - z0) / cs)) + 3
        if y0 is None or y1 is None:
            return cls(x0 - cs, z0 - cs, cs, ncx, ncz, reach)
        ncy = int(math.ceil((y1 - y0) / cs)) + 3
        return cls(x0 - cs, z0 - cs, cs, ncx, ncz, reach, ncy, y0 - cs)

    @property
    def ncell(self) -> int:
        return self.ncx * self.ncy * self.ncz

    def lists(self, capacity: int) -> Cells:
        """Empty cell lists on this grid for ``capacity`` particle slots."""
        return Cells(np.zeros(self.ncell + 2, dtype=np.int64), np.zeros(self.ncell + 1, dtype=np.int64),
                     np.zeros(capacity, dtype=np.int64), self.ncx, self.ncz, float(self.xmin),
                     float(self.zmin), 1.0 / self.cs, self.reach, self.ncy, float(self.ymin),
                     None if self.ncy == 1 else True)


@njit(cache=True, inline="always")
def block_of(c, cells):
    """(cxl, cxh, cyl, cyh, czl, czh): the block of cells within reach of cell c, clipped to the
    grid; its particles are the slots start[r + cxl] : start[r + cxh + 1] of the rows
    r = (zz * ncy + yy) * ncx, yy in cyl..cyh, zz in czl..czh."""
    ncx = cells.ncx
    r = cells.reach
    if cells.three is None:   # 2D (when compiled): one layer, y = 0
        cz = c // ncx
        cx = c - cz * ncx
        return max(cx - r, 0), min(cx + r, ncx - 1), 0, 0, max(cz - r, 0), min(cz + r, cells.ncz - 1)
    ncy = cells.ncy
    cx = c % ncx
    cyz = c // ncx
    cy = cyz % ncy
    cz = cyz // ncy
    return (max(cx - r, 0), min(cx + r, ncx - 1), max(cy - r, 0), min(cy + r, ncy - 1),
            max(cz - r, 0), min(cz + r, cells.ncz - 1))


@njit(cache=True, inline="always")
def cell_at(x, y, z, cells):
    """Cell index of the point (x, y, z), clamped to the grid (y is ignored in 2D)."""
    cx = min(max(int((x - cells.xmin) * cells.inv_cs), 0), cells.ncx - 1)
    cz = min(max(int((z - cells.zmin) * cells.inv_cs), 0), cells.ncz - 1)
    if cells.three is None:   # 2D (when compiled)
        return cz * cells.ncx + cx
    cy = min(max(int((y - cells.ymin) * cells.inv_cs), 0), cells.ncy - 1)
    return (cz * cells.ncy + cy) * cells.ncx + cx


@njit(parallel=True, cache=True)
def compute_cells(ps, n, cells):
    """ps.cell[i] = cell_at(x, y, z) of particle i (clamped to the grid); inactive -> the extra
    bin ncx * ncy * ncz."""
    x = ps.x
    y = ps.y
    z = ps.z
    kind = ps.kind
    cell = ps.cell
    ncell = cells.ncx * cells.ncy * cells.ncz
    for i in prange(n):
        if kind[i] < 0:
            cell[i] = ncell
        else:
            cell[i] = cell_at(x[i], y[i], z[i], cells)


# Parallel loops below split their work into a fixed number of pieces, not one per thread:
# numba's get_num_threads() in a jitted function stops it caching, and a fixed count that is a
# multiple of every usual thread count splits as evenly under numba's static schedule.
SORT_CHUNKS = 64       # chunks of slots of the parallel counting sort
PASS_RANGES = 480      # slot ranges of a pass balanced by kind (kind_ranges): 1..16, 20, 24, 32 threads


@njit(cache=True)
def counting_sort(cell, n, cells):
    """Stable counting sort of slots by cell: cells.order[k] = slot that goes to position k.

    cells.start (size ncell + 2) receives the first position of each cell (bin ncell = inactive).
    A large set whose chunks of slots each span few cells (the sorted order of the last step,
    moved by a cell or so: every step but the first) takes the parallel
    ``_counting_sort_chunks``, others the serial sort; both give the same order."""
    if n >= 512 * SORT_CHUNKS:
        if _counting_sort_chunks(cell, n, cells, SORT_CHUNKS):
            return
    _counting_sort_serial(cell, n, cells)


@njit(cache=True)
def _counting_sort_serial(cell, n, cells):
    ncell = cells.ncx * cells.ncy * cells.ncz
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
def _counting_sort_chunks(cell, n, cells, nt):
    """The counting sort in ``nt`` chunks of slots, each with a histogram over the span of bins
    it touches (lo[t]..hi[t]); a bin's slots go chunk by chunk, so the order is the serial one.
    Returns False, having written nothing, when the spans together exceed 2 (nbins + n) (an
    unsorted set: the first sort, appended inflow): the caller then sorts serially."""
    ncell = cells.ncx * cells.ncy * cells.ncz
    nb = ncell + 1                      # bins: the cells and the inactive bin
    start = cells.start
    order = cells.order
    blk = (n + nt - 1) // nt
    lo = np.empty(nt, np.int64)
    hi = np.empty(nt, np.int64)
    for t in prange(nt):
        cl = nb
        ch = -1
        for i in range(t * blk, min(t * blk + blk, n)):
            c = cell[i]
            cl = min(cl, c)
            ch = max(ch, c)
        lo[t] = cl
        hi[t] = max(ch, cl - 1)         # an empty chunk spans no bin
    off = np.empty(nt + 1, np.int64)    # chunk t's histogram: hist[off[t] : off[t + 1]]
    off[0] = 0
    for t in range(nt):
        off[t + 1] = off[t] + hi[t] - lo[t] + 1
    if off[nt] > 2 * (nb + n):
        return False
    hist = np.empty(off[nt], np.int64)
    for t in prange(nt):
        h0 = off[t] - lo[t]
        for k in range(off[t], off[t + 1]):
            hist[k] = 0
        for i in range(t * blk, min(t * blk + blk, n)):
            hist[h0 + cell[i]] += 1
    # per range of bins: the count of each bin (into start[c + 1]) and each chunk's histogram
    # turned into the chunk's offset inside the bin (the counts of the chunks before it)
    bblk = (nb + nt - 1) // nt
    part = np.empty(nt + 1, np.int64)
    part[0] = 0
    for s in prange(nt):
        c0 = s * bblk
        c1 = min(c0 + bblk, nb)
        t0 = nt
        t1 = -1
        for t in range(nt):             # the chunks whose span meets this range of bins
            if lo[t] < c1 and hi[t] >= c0:
                t0 = min(t0, t)
                t1 = max(t1, t)
        acc = 0
        for c in range(c0, c1):
            tot = 0
            for t in range(t0, t1 + 1):
                if lo[t] <= c and c <= hi[t]:
                    k = off[t] - lo[t] + c
                    m = hist[k]
                    hist[k] = tot
                    tot += m
            acc += tot
            start[c + 1] = acc          # running count inside the range
        part[s + 1] = acc
    for s in range(nt):
        part[s + 1] += part[s]
    start[0] = 0
    for s in prange(nt):
        base = part[s]
        for c in range(s * bblk, min(s * bblk + bblk, nb)):
            start[c + 1] += base
    for t in prange(nt):
        h0 = off[t] - lo[t]
        for i in range(t * blk, min(t * blk + blk, n)):
            c = cell[i]
            k = h0 + c
            order[start[c] + hist[k]] = i
            hist[k] += 1
    return True


@njit(parallel=True, cache=True)
def kind_ranges(kind, n, k, nr):
    """Bounds b[0] = 0 <= ... <= b[nr] = n of ``nr`` slot ranges that hold the same number of
    particles of kind ``k`` (to one): a prange over the ranges gives every thread an equal share
    of a pass that works on kind k alone (numba's static schedule splits the slots evenly, and
    in a sorted tank the walls crowd at its ends: bench/step_stages.py). ``nr``: PASS_RANGES.
    Counts per block of slots, then each bound scans one block."""
    blk = (n + nr - 1) // nr
    cnt = np.empty(nr + 1, np.int64)
    cnt[0] = 0
    for t in prange(nr):
        s = 0
        for i in range(t * blk, min(t * blk + blk, n)):
            if kind[i] == k:
                s += 1
        cnt[t + 1] = s
    for t in range(nr):
        cnt[t + 1] += cnt[t]
    b = np.empty(nr + 1, np.int64)
    b[0] = 0
    b[nr] = n
    for t in prange(1, nr):
        target = t * cnt[nr] // nr      # range t starts after the target-th particle of kind k
        c = 0                           # the last block with cnt[c] < target (or 0)
        e = nr
        while e - c > 1:
            m = (c + e) // 2
            if cnt[m] < target:
                c = m
            else:
                e = m
        s = cnt[c]
        i = c * blk
        while s < target:
            if kind[i] == k:
                s += 1
            i += 1
        b[t] = i
    return b


@njit(parallel=True, cache=True)
def permute(ps, ps2, nrows, order, n, ny=0):
    """Gather particle k of the sorted set from slot order[k] into the twin buffer: rows
    [0, nrows) and the first ``ny`` y rows (particles.Y on; 0 in a 2D scene)."""
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
        for r in range(Y, Y + ny):
            f2[r, k] = f[r, i]
        kind2[k] = kind[i]
        ids2[k] = ids[i]
        cell2[k] = cell[i]


@njit(cache=True)
def sort_by_cell(ps, ps2, nrows, n, cells):
    """Bin, counting-sort and gather the first ``nrows`` rows of all particles into the twin
    buffer ``ps2`` (the caller swaps), in a 3D scene their y rows too (N_SORTED_Y_KDK or
    N_SORTED_Y_PC with N_SORTED_PC); returns the slots in use after it (inactive ones
    dropped)."""
    compute_cells(ps, n, cells)
    counting_sort(ps.cell, n, cells)
    ny = 0
    if cells.three is not None:
        ny = N_SORTED_Y_PC if nrows >= N_SORTED_PC else N_SORTED_Y_KDK
    permute(ps, ps2, nrows, cells.order, n, ny)
    return cells.start[cells.ncx * cells.ncy * cells.ncz]


def brute_force_neighbours(x: np.ndarray, z: np.ndarray, radius: float,
                           y: np.ndarray | None = None) -> list[set[int]]:
    """Reference O(N^2) neighbour sets (for tests)."""
    d2 = (x[:, None] - x[None, :]) ** 2 + (z[:, None] - z[None, :]) ** 2
    if y is not None:
        d2 += (y[:, None] - y[None, :]) ** 2
    return [set(np.nonzero((row < radius * radius))[0].tolist()) - {i} for i, row in enumerate(d2)]
