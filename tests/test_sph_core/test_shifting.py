"""Particle shifting (sph_core.shifting), Fickian and delta-plus: a disordered particle moves back
towards the lattice, a surface particle never moves along the surface normal, delta-plus finds the
free surface (Marrone et al. 2010) and leaves an isolated particle alone, and still water with
shifting on stays still for 100 sqrt(d/g) (no surface drift; mass and momentum conserved; slow:
~100 s per law on a loaded core)."""

import math

import numpy as np
import pytest
from cell_sorted import sort_into_cells

from sph_core.kernels import w_of_q, wendland_alpha
from sph_core.particles import FLUID, GUZ, INLET, M, N_FIELDS, RHO, VX, WALL, X, Z
from sph_core.scene import SceneError, make_scene
from sph_core.shifting import (FS_SURFACE, SHIFT_OPEN_END, shift_particles,
                               shift_particles_dplus)
from sph_core.simulation import Simulation
from sph_core.state import Params, particles_view


def _lattice_run(nx: int, nz: int, dp: float, h: float, moved: tuple[int, float, float],
                 coef: float = 2.0, fs_div: float = 1.8, speed: float = 1.0,
                 dplus: bool = False, extra: tuple[float, float] | None = None,
                 buffer_cols: int = 0, shift_open: int = 0):
    """Shift a lattice of nx x nz fluid particles (one moved by (dx, dz); ``extra``: one more
    fluid particle there) above 4 wall rows by the Fickian or (``dplus``) the delta-plus law;
    returns (x, z before, x, z after, kinds, the sort order, the delta-plus surface flags).
    ``buffer_cols``: the left-most columns are an open end's active buffer (INLET), moving with
    the fluid; ``shift_open``: Params.shift_open."""
    xs, zs, kinds = [], [], []
    for j in range(-4, nz):
        for i in range(nx):
            xs.append((i + 0.5) * dp)
            zs.append((j + 0.5) * dp)
            kinds.append(WALL if j < 0 else INLET if i < buffer_cols else FLUID)
    if extra is not None:
        xs.append(extra[0])
        zs.append(extra[1])
        kinds.append(FLUID)
    n = len(xs)
    f = np.zeros((N_FIELDS, n))
    f[X], f[Z] = xs, zs
    f[RHO] = 1000.0
    f[M] = 1000.0 * dp * dp
    f[VX] = np.where(np.array(kinds) != WALL, speed, 0.0)
    k, ddx, ddz = moved
    f[X, k] += ddx
    f[Z, k] += ddz
    kind = np.array(kinds, dtype=np.int8)
    f, kind, cell, cells, order = sort_into_cells(f, kind, h, (-3 * h, nx * dp + 3 * h,
                                                               -6 * dp - 3 * h, nz * dp + 3 * h))
    aw = wendland_alpha(h)
    prm = Params(h=h, alpha_w=aw, alpha_f=5.0 * aw / (h * h), rho0=1000.0, c0=10.0, b=1.0,
                 gamma=7.0, gx=0.0, gz=-9.81, alpha=0.01, nu=1e-6, delta=0.1, cfl=0.25,
                 rho_lo=0.7, rho_hi=1.3, noslip=True, fx0=-1.0, fx1=1.0, fz0=-1.0, fz1=1.0,
                 alpha_wall=1.0, shift_a=coef, shift_fs_div=fs_div, shift_dplus=dplus,
                 shift_inv_wdp=1.0 / w_of_q(dp / h, aw), shift_open=shift_open)
    before = (f[X].copy(), f[Z].copy())
    ps = particles_view(f, kind, np.arange(n, dtype=np.int64), cell)
    if dplus:
        shift_particles_dplus(ps, n, cells, prm, 1e-3, speed)
    else:
        shift_particles(ps, n, cells, prm, 1e-3)
    return before, (f[X], f[Z]), kind, order, f[GUZ].copy()


LAWS = [pytest.param({}, id="fickian"), pytest.param({"dplus": True, "coef": 4.0}, id="dplus")]


@pytest.mark.parametrize("law", LAWS)
def test_displaced_interior_particle_moves_back_towards_its_lattice_site(law):
    dp, h = 0.02, 0.04
    nx, nz = 12, 10
    k = 4 * nx + 6 + 4 * nx  # row 4 of the fluid (above 4 wall rows), column 6
    (x0, z0), (x1, z1), kind, order, _ = _lattice_run(nx, nz, dp, h, (k, 0.2 * dp, 0.1 * dp),
                                                      **law)
    i = int(np.nonzero(order == k)[0][0])
    site = np.array([6.5 * dp, 4.5 * dp])
    before = np.hypot(x0[i] - site[0], z0[i] - site[1])
    after = np.hypot(x1[i] - site[0], z1[i] - site[1])
    assert after < before, f"shifted away from its site: {before:.3g} -> {after:.3g} m"


@pytest.mark.parametrize("law", LAWS)
def test_surface_particle_does_not_move_along_the_normal(law):
    dp, h = 0.02, 0.04
    nx, nz = 12, 6
    k = (nz - 1 + 4) * nx + 6  # top fluid row, column 6, moved sideways
    (x0, z0), (x1, z1), kind, order, _ = _lattice_run(nx, nz, dp, h, (k, 0.2 * dp, 0.0), **law)
    i = int(np.nonzero(order == k)[0][0])
    assert x1[i] != x0[i], "the tangential shift should act"
    # flat surface: the normal is z; the top row keeps its height (away from the block's lateral
    # edges, which are free surfaces too, with a tilted normal at the corners)
    top = (np.isclose(z0, (nz - 0.5) * dp) & (kind == FLUID) & (x0 > 3 * dp)
           & (x0 < (nx - 3) * dp))
    assert np.all(np.abs(z1[top] - z0[top]) < 1e-3 * dp)


@pytest.mark.parametrize("law", LAWS)
@pytest.mark.parametrize("rule", ["full", "none"])
def test_shift_beside_an_open_end_follows_the_rule(law, rule):
    # a fluid particle two columns from an inlet buffer (3 columns), displaced: "full" shifts it
    # as anywhere, "none" not at all (a shift there would move fluid in or out that the imposed
    # flow did not carry); a particle more than 2h from the buffer shifts in every case
    dp, h = 0.02, 0.04
    nx, nz = 14, 10
    near = (4 + 4) * nx + 4          # fluid row 4, column 4: 1.5 dp from the buffer's last column
    far = (4 + 4) * nx + 10
    out = {}
    for k in (near, far):
        (x0, z0), (x1, z1), kind, order, _ = _lattice_run(
            nx, nz, dp, h, (k, 0.2 * dp, 0.1 * dp), buffer_cols=3,
            shift_open=SHIFT_OPEN_END[rule], **law)
        i = int(np.nonzero(order == k)[0][0])
        out[k] = (x1[i] - x0[i], z1[i] - z0[i])
    (nxs, nzs), (fxs, fzs) = out[near], out[far]
    assert abs(fxs) > 1e-4 * dp and abs(fzs) > 1e-4 * dp, "far from the end: shifted"
    if rule == "full":
        assert abs(nxs) > 1e-4 * dp and abs(nzs) > 1e-4 * dp
    else:
        assert nxs == 0.0 and nzs == 0.0


def test_dplus_finds_the_free_surface_and_leaves_an_isolated_particle_alone():
    dp, h = 0.02, 0.04
    nx, nz = 16, 10
    k = 4 * nx + 8 + 4 * nx  # an interior particle, displaced so that the lattice is not at rest
    drop = (8.5 * dp, (nz + 6) * dp)  # a drop 6 dp above the surface: no neighbour within 2h
    (x0, z0), (x1, z1), kind, order, flag = _lattice_run(
        nx, nz, dp, h, (k, 0.2 * dp, 0.1 * dp), dplus=True, coef=4.0, extra=drop)
    fluid = kind == FLUID
    inner = fluid & (x0 > 3 * dp) & (x0 < (nx - 3) * dp)
    top = inner & np.isclose(z0, (nz - 0.5) * dp)
    deep = inner & (z0 < (nz - 3) * dp)
    assert np.all(flag[top] == FS_SURFACE), "the top row is the free surface"
    assert not np.any(flag[deep] == FS_SURFACE), "a particle 3 rows down is not"
    i = int(np.nonzero(np.isclose(x0, drop[0]) & np.isclose(z0, drop[1]))[0][0])
    assert x1[i] == x0[i] and z1[i] == z0[i], "the isolated particle was shifted"


D = 0.16            # still-water depth [m]
DP = D / 8          # 8 layers: coarse, so that 100 sqrt(d/g) runs in seconds
T_END = 100.0 * math.sqrt(D / 9.81)


def still_water_run(shifting: str = "fickian"):
    """The jittered still-water tank run to T_END; returns (sim, initial state, momentum
    record [(sum m vx, sum m vz)] every 0.5 s)."""
    scene = make_scene({
        "name": "still_shifted", "dp": DP, "t_end": T_END, "still_water_level": D,
        "tank": {"x0": 0.0, "x1": 2 * D, "z0": 0.0, "z1": 1.6 * D},
        "water_blocks": [{"x0": 0.0, "x1": 2 * D, "z0": 0.0, "z1": D}],
        "constants": {"h_over_dp": 2.0, "shifting": shifting, "alpha_wall_factor": 0.0},
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


@pytest.fixture(scope="module", params=["fickian", "dplus"])
def still_shifted(request):
    return still_water_run(request.param)


@pytest.mark.slow
def test_still_water_with_shifting_keeps_its_mass_and_level(still_shifted):
    sim, st0, _ = still_shifted
    st = sim.fluid_state()
    np.testing.assert_array_equal(st["m"], st0["m"])
    assert st["z"].max() < D + 0.5 * DP, "a surface particle lifted off"
    # the centre of mass stays (shifting must not carry fluid up or down): measured 0.036 dp
    # with shifting, 0.017 dp without
    drift = abs(np.sum(st["m"] * st["z"]) / np.sum(st["m"]) - np.sum(st0["m"] * st0["z"]) / np.sum(st0["m"]))
    assert drift < 0.05 * DP, f"centre of mass moved {drift:.3g} m"
    late = [r["g_eta"] for r in sim.history if r["t"] >= 0.5 * T_END]
    assert max(abs(e) for e in late) < 0.25 * DP, "surface gauge drifted"


@pytest.mark.slow
def test_still_water_with_shifting_keeps_zero_momentum(still_shifted):
    sim, st0, mom = still_shifted
    scale = np.sum(st0["m"]) * math.sqrt(9.81 * D)
    # the jitter sets the water sloshing (1.3e-3 of M sqrt(g d) at most, with or without
    # shifting, measured); over the second half the net momentum averages out to ~1e-5
    assert np.abs(mom).max() / scale < 3e-3
    late = mom[len(mom) // 2:]
    assert np.abs(late.mean(axis=0)).max() / scale < 1e-4


def test_open_end_rule_reaches_params():
    base = {"dp": 0.05, "t_end": 0.1, "tank": {"x0": 0, "x1": 0.5, "z0": 0, "z1": 0.4},
            "water_blocks": [{"x0": 0, "x1": 0.5, "z0": 0, "z1": 0.2}]}
    sim = Simulation(make_scene({**base, "constants": {"shifting": "dplus",
                                                       "shift_open_end": "none"}}))
    assert sim.prm.shift_open == SHIFT_OPEN_END["none"] == 1
    assert Simulation(make_scene(base)).prm.shift_open == SHIFT_OPEN_END["full"] == 0
    # "tangential" was measured and retired; the default, written explicitly, is accepted
    with pytest.raises(SceneError, match=r"constants\.shift_open_end: 'tangential' was measured "
                                         r"and retired \(see docs/decisions/shift_open_end\.md\)"):
        make_scene({**base, "constants": {"shift_open_end": "tangential"}})
    assert make_scene({**base, "constants": {"shift_open_end": "full"}}) == make_scene(base)
