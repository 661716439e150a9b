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
