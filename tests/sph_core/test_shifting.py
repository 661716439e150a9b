"""Particle shifting (sph_core.shifting): a disordered particle moves back towards the lattice,
a surface particle never moves along the surface normal, and still water with shifting on stays
still for 100 sqrt(d/g) (no surface drift; mass and momentum conserved)."""

import math

import numpy as np
import pytest

from sph_core.kernels import wendland_alpha
from sph_core.neighbours import CellGrid
from sph_core.particles import FLUID, M, N_FIELDS, RHO, VX, VZ, WALL, X, Z
from sph_core.scene import make_scene
from sph_core.shifting import shift_particles
from sph_core.simulation import Simulation


def _lattice_run(nx: int, nz: int, dp: float, h: float, moved: tuple[int, float, float],
                 coef: float = 2.0, fs_div: float = 1.8, speed: float = 1.0):
    """Shift a lattice of nx x nz fluid particles (one moved by (dx, dz)) above 4 wall rows;
    returns (x, z before, x, z after, kinds)."""
    xs, zs, kinds = [], [], []
    for j in range(-4, nz):
        for i in range(nx):
            xs.append((i + 0.5) * dp)
            zs.append((j + 0.5) * dp)
            kinds.append(WALL if j < 0 else FLUID)
    n = len(xs)
    f = np.zeros((N_FIELDS, n))
    f[X], f[Z] = xs, zs
    f[RHO] = 1000.0
    f[M] = 1000.0 * dp * dp
    f[VX] = np.where(np.array(kinds) == FLUID, speed, 0.0)
    k, ddx, ddz = moved
    f[X, k] += ddx
    f[Z, k] += ddz
    kind = np.array(kinds, dtype=np.int8)
    # one cell holding everything: the pass loops over its 3 x 3 block of cells
    grid = CellGrid.covering(-3 * h, nx * dp + 3 * h, -6 * dp - 3 * h, nz * dp + 3 * h, 2.0 * h)
    cell = ((np.floor((f[Z] - grid.zmin) / grid.cs).astype(np.int64)) * grid.ncx
            + np.floor((f[X] - grid.xmin) / grid.cs).astype(np.int64))
    order = np.argsort(cell, kind="stable")
    f, kind, cell = f[:, order].copy(), kind[order].copy(), cell[order].copy()
    cell_start = np.searchsorted(cell, np.arange(grid.ncell + 1)).astype(np.int64)
    before = (f[X].copy(), f[Z].copy())
    aw = wendland_alpha(h)
    shift_particles(f, kind, cell, cell_start, n, grid.ncx, grid.ncz, h, 5.0 * aw / (h * h),
                    1e-3, coef, fs_div, 0.05 * h)
    return before, (f[X], f[Z]), kind, order


def test_displaced_interior_particle_moves_back_towards_its_lattice_site():
    dp, h = 0.02, 0.04
    nx, nz = 12, 10
    k = 4 * nx + 6 + 4 * nx  # row 4 of the fluid (above 4 wall rows), column 6
    (x0, z0), (x1, z1), kind, order = _lattice_run(nx, nz, dp, h, (k, 0.2 * dp, 0.1 * dp))
    i = int(np.nonzero(order == k)[0][0])
    site = np.array([6.5 * dp, 4.5 * dp])
    before = np.hypot(x0[i] - site[0], z0[i] - site[1])
    after = np.hypot(x1[i] - site[0], z1[i] - site[1])
    assert after < before, f"shifted away from its site: {before:.3g} -> {after:.3g} m"


def test_surface_particle_does_not_move_along_the_normal():
    dp, h = 0.02, 0.04
    nx, nz = 12, 6
    k = (nz - 1 + 4) * nx + 6  # top fluid row, column 6, moved sideways
    (x0, z0), (x1, z1), kind, order = _lattice_run(nx, nz, dp, h, (k, 0.2 * dp, 0.0))
    i = int(np.nonzero(order == k)[0][0])
    assert x1[i] != x0[i], "the tangential shift should act"
    # flat surface: the normal is z; the top row keeps its height (away from the block's lateral
    # edges, which are free surfaces too, with a tilted normal at the corners)
    top = (np.isclose(z0, (nz - 0.5) * dp) & (kind == FLUID) & (x0 > 3 * dp)
           & (x0 < (nx - 3) * dp))
    assert np.all(np.abs(z1[top] - z0[top]) < 1e-3 * dp)


D = 0.16            # still-water depth [m]
DP = D / 8          # 8 layers: coarse, so that 100 sqrt(d/g) runs in seconds
T_END = 100.0 * math.sqrt(D / 9.81)


@pytest.fixture(scope="module")
def still_shifted():
    scene = make_scene({
        "name": "still_shifted", "dp": DP, "t_end": T_END, "still_water_level": D,
        "tank": {"x0": 0.0, "x1": 2 * D, "z0": 0.0, "z1": 1.6 * D},
        "water_blocks": [{"x0": 0.0, "x1": 2 * D, "z0": 0.0, "z1": D}],
        "constants": {"h_over_dp": 2.0, "shifting": "fickian", "alpha_wall_factor": 0.0},
        "output": {"probe_every": 0.1},
        "probes": [{"kind": "elevation", "name": "g", "x": 0.7 * D}],
    })
    sim = Simulation(scene)
    st0 = sim.fluid_state()
    rng = np.random.default_rng(7)
    ps = sim.particles
    fl = np.nonzero(ps.kind[: ps.n] == FLUID)[0]
    # disorder the lattice (0.1 dp) so that spurious currents arise and the shifting acts
    ps.f[X, fl] += rng.uniform(-0.1, 0.1, fl.size) * DP
    ps.f[Z, fl] += rng.uniform(-0.1, 0.1, fl.size) * DP
    mom = []
    while sim.t < T_END - 1e-9:
        sim.advance_to(min(sim.t + 0.5, T_END))
        st = sim.fluid_state()
        mom.append((np.sum(st["m"] * st["vx"]), np.sum(st["m"] * st["vz"])))
    return sim, st0, np.array(mom)


def test_still_water_with_shifting_keeps_its_mass_and_level(still_shifted):
    sim, st0, _ = still_shifted
    st = sim.fluid_state()
    np.testing.assert_array_equal(st["m"], st0["m"])
    assert st["z"].max() < D + 0.5 * DP, "a surface particle lifted off"
    # the centre of mass stays (shifting must not carry fluid up or down)
    drift = abs(np.sum(st["m"] * st["z"]) / np.sum(st["m"]) - np.sum(st0["m"] * st0["z"]) / np.sum(st0["m"]))
    assert drift < 0.05 * DP, f"centre of mass moved {drift:.3g} m"
    late = [r["g_eta"] for r in sim.history if r["t"] >= 0.5 * T_END]
    assert max(abs(e) for e in late) < 0.25 * DP, "surface gauge drifted"


def test_still_water_with_shifting_keeps_zero_momentum(still_shifted):
    sim, st0, mom = still_shifted
    scale = np.sum(st0["m"]) * math.sqrt(9.81 * D)
    assert np.abs(mom).max() / scale < 1e-3
