"""Cell lists: the counting sort keeps every particle, and cell ranges find exactly the neighbours."""

import numpy as np

from sph_core.neighbours import CellGrid, brute_force_neighbours, sort_by_cell
from sph_core.particles import INACTIVE, N_SORTED_KDK, X, Z, ParticleSet, FLUID


def test_sorted_cells_give_brute_force_neighbours():
    rng = np.random.default_rng(3)
    n, h = 700, 0.03
    ps = ParticleSet(n + 10)
    ps.add(rng.uniform(0, 1, n), rng.uniform(0, 0.5, n), FLUID, np.ones(n), np.ones(n))
    ps.kind[[5, 17, 300]] = INACTIVE
    grid = CellGrid.covering(0, 1, 0, 0.5, 2 * h)
    cells = grid.lists(ps.capacity)
    cell_start = cells.start
    ids_before = set(ps.ids[: ps.n].tolist())
    x_by_id = dict(zip(ps.ids[: n].tolist(), ps.f[X, :n].tolist()))
    n_active = sort_by_cell(ps.view, ps.view2, N_SORTED_KDK, ps.n, cells)
    ps.swap()
    cell = ps.cell
    assert n_active == ps.n - 3                                          # inactive dropped
    assert set(ps.ids[: ps.n].tolist()) == ids_before                 # a permutation
    assert all(x_by_id[i] == x for i, x in zip(ps.ids[:n].tolist(), ps.f[X, :n].tolist()))
    assert np.all(np.diff(cell[: ps.n]) >= 0)                            # sorted by cell
    assert np.all(ps.kind[ps.n - 3: ps.n] == INACTIVE)                   # inactive at the end
    active = ps.n - 3
    x, z = ps.f[X, :active], ps.f[Z, :active]
    expected = brute_force_neighbours(x, z, 2 * h)
    for i in range(0, active, 7):
        c = cell[i]
        cz, cx = divmod(c, grid.ncx)
        found = set()
        for zz in range(cz - 1, cz + 2):
            lo = cell_start[zz * grid.ncx + cx - 1]
            hi = cell_start[zz * grid.ncx + cx + 2]
            found |= {j for j in range(lo, hi)
                      if j != i and (x[i] - x[j]) ** 2 + (z[i] - z[j]) ** 2 < 4 * h * h}
        assert found == expected[i]


def _cells_for(cell: np.ndarray, ncx: int, ncz: int):
    grid = CellGrid(0.0, 0.0, 1.0, ncx, ncz)
    return grid.lists(cell.size)


def _jitter(rng, ncx: int, ncz: int, n: int, inactive: int) -> np.ndarray:
    """Cells of a set sorted at the last step, each particle moved by at most one cell."""
    cell = np.sort(rng.integers(0, ncx * ncz, n))
    cell = np.clip(cell + rng.integers(-1, 2, n) + ncx * rng.integers(-1, 2, n), 0, ncx * ncz - 1)
    cell[rng.choice(n, inactive, replace=False)] = ncx * ncz
    return cell


def test_chunked_counting_sort_gives_the_serial_order():
    """The parallel sort's order and cell starts are the serial sort's, slot for slot (stable
    by slot index), for several chunk counts; an unsorted set is refused, nothing written."""
    from sph_core.neighbours import _counting_sort_chunks, _counting_sort_serial
    rng = np.random.default_rng(7)
    ncx, ncz, n = 40, 30, 5000
    cell = _jitter(rng, ncx, ncz, n, inactive=3)
    ref = _cells_for(cell, ncx, ncz)
    _counting_sort_serial(cell, n, ref)
    for nt in (2, 3, 7, 16, 64):
        got = _cells_for(cell, ncx, ncz)
        assert _counting_sort_chunks(cell, n, got, nt)
        assert np.array_equal(got.order[:n], ref.order[:n])
        assert np.array_equal(got.start, ref.start)
    shuffled = rng.integers(0, ncx * ncz + 1, n)    # every chunk spans the whole grid
    got = _cells_for(shuffled, ncx, ncz)
    assert not _counting_sort_chunks(shuffled, n, got, 16)
    assert not got.start.any()


def test_kind_ranges_share_a_kind_evenly():
    """Every range holds the same count of the kind (to one), the ranges tile [0, n) in order."""
    from sph_core.neighbours import kind_ranges
    from sph_core.particles import WALL
    rng = np.random.default_rng(5)
    n = 3001
    kind = np.full(n, FLUID, dtype=np.int8)
    kind[:500] = WALL                                  # walls crowd at the ends of a sorted tank
    kind[2700:] = WALL
    kind[rng.choice(n, 40, replace=False)] = WALL
    for k in (FLUID, WALL):
        for nr in (1, 2, 5, 16):
            b = kind_ranges(kind, n, k, nr)
            assert b[0] == 0 and b[-1] == n and np.all(np.diff(b) >= 0)
            counts = [np.count_nonzero(kind[b[r]:b[r + 1]] == k) for r in range(nr)]
            assert sum(counts) == np.count_nonzero(kind == k)
            assert max(counts) - min(counts) <= 1
    b = kind_ranges(kind, n, INACTIVE, 4)              # none of the kind: still a tiling
    assert b[0] == 0 and b[-1] == n and np.all(np.diff(b) >= 0)
