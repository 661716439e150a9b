"""Three dimensions: the same walk, terms and step with y (scene ``dim = 3``).

The 3D step is the 2D one with three components: these tests check what only 3D exercises
(cells across y, the 3D kernel's normalisation, the box walls, forces with a y component) and
that a 3D scene is validated and refused like a 2D one."""

import math

import numpy as np
import pytest

from sph_core.kernels import wendland_alpha
from sph_core.neighbours import CellGrid, brute_force_neighbours, sort_by_cell
from sph_core.particles import FLUID, M, N_SORTED_KDK, RHO, WALL, X, Y, Z, ParticleSet
from sph_core.probes import fluid_neighbour_counts
from sph_core.scene import SceneError, make_scene
from sph_core.simulation import Simulation


def _box(dim: int, **extra) -> dict:
    d = dict(dim=dim, dp=0.02, t_end=0.4,
             tank=dict(x0=0.0, x1=0.4, z0=0.0, z1=0.4),
             water_blocks=[dict(x0=0.0, x1=0.4, z0=0.0, z1=0.2)], output=dict(probe_every=0.1))
    if dim == 3:
        d["tank"].update(y0=0.0, y1=0.3)
    d.update(extra)
    return d


def test_cells_across_y_find_exactly_the_brute_force_neighbours():
    rng = np.random.default_rng(7)
    n, h = 900, 0.04
    ps = ParticleSet(n + 4)
    ps.add(rng.uniform(0, 0.6, n), rng.uniform(0, 0.4, n), FLUID, np.ones(n), np.ones(n),
           y=rng.uniform(-0.1, 0.3, n))
    grid = CellGrid.covering(0, 0.6, 0, 0.4, 2 * h, reach=2, y0=-0.1, y1=0.3)
    assert grid.ncy > 1
    cells = grid.lists(ps.capacity)
    n_sorted = sort_by_cell(ps.view, ps.view2, N_SORTED_KDK, ps.n, cells)
    ps.swap()
    counts = np.zeros(ps.capacity, dtype=np.int64)
    fluid_neighbour_counts(ps.view, n_sorted, cells, h, counts)
    x, y, z = ps.f[X, :n_sorted], ps.f[Y, :n_sorted], ps.f[Z, :n_sorted]
    expected = brute_force_neighbours(x, z, 2 * h, y=y)
    assert [len(s) for s in expected] == counts[:n_sorted].tolist()
    assert sum(len(s) for s in expected) > 10 * n   # a real test: ~20 neighbours each


def test_kernel_sums_to_one_on_a_3d_lattice():
    dp, h = 0.01, 0.02
    k = np.arange(-5, 6) * dp
    gx, gy, gz = np.meshgrid(k, k, k)
    q = np.sqrt(gx**2 + gy**2 + gz**2) / h
    t = np.clip(1 - q / 2, 0, None)
    s = np.sum(wendland_alpha(h, 3) * t**4 * (2 * q + 1)) * dp**3
    assert s == pytest.approx(1.0, abs=2e-3)


def test_still_water_in_a_box_holds_its_hydrostatic_force_like_the_plane():
    """A 3D tank at rest: the force on the right wall per metre of width is the 2D tank's (both
    within 7 % of rho g H^2 / 2: the wall's pressure at its dummy particles, not at its face), no
    particle moves off its place and the y walls hold the water as the x walls do."""
    per_width = {}
    for dim in (2, 3):
        probe = dict(kind="force", name="wall", x0=0.4, x1=0.6, z0=0.0, z1=0.4)
        if dim == 3:
            probe.update(y0=-0.1, y1=0.4)   # the whole wall, its edges too
        sim = Simulation(make_scene(_box(dim, probes=[probe])))
        sim.advance_to(0.4, progress=None)
        f = np.array([r["wall_fx"] for r in sim.history[1:]])
        per_width[dim] = float(f.mean()) / (0.3 if dim == 3 else 1.0)
        assert sim.v_max < 0.05
        assert not sim.excluded
        if dim == 3:
            fl = sim.particles.mask(FLUID)
            y = sim.particles.field(Y)[fl]
            assert y.min() > 0.0 and y.max() < 0.3
            assert abs(sim.history[-1]["wall_fy"]) < 0.02 * abs(sim.history[-1]["wall_fx"])
    exact = 0.5 * 1000 * 9.81 * 0.2**2
    assert per_width[2] == pytest.approx(exact, rel=0.07)
    assert per_width[3] == pytest.approx(per_width[2], rel=0.03)


def test_a_3d_checkpoint_restores_bit_for_bit():
    sim = Simulation(make_scene(_box(3, t_end=0.05)))
    sim.advance_to(0.01, progress=None)
    cp = sim.checkpoint()
    sim.advance_to(0.03, progress=None)
    a = sim.particles.f[:, : sim.particles.n].copy()
    sim.restore(cp)
    sim.advance_to(0.03, progress=None)
    np.testing.assert_array_equal(a, sim.particles.f[:, : sim.particles.n])


def test_a_3d_box_has_walls_on_every_side():
    sim = Simulation(make_scene(_box(3)), spare=0.0)
    ps = sim.particles
    w = ps.mask(WALL)
    x, y, z = ps.field(X)[w], ps.field(Y)[w], ps.field(Z)[w]
    assert x.min() < 0 < 0.4 < x.max() and y.min() < 0 < 0.3 < y.max() and z.min() < 0
    fl = ps.mask(FLUID)
    assert fl.sum() == round(0.4 / 0.02) * round(0.3 / 0.02) * round(0.2 / 0.02)
    assert np.allclose(ps.field(M)[fl] / ps.field(RHO)[fl], 0.02**3)   # volume dp^3


@pytest.mark.parametrize("extra, field", [
    (dict(bodies=[dict(name="b", shape="box", x0=0.1, x1=0.2, z0=0.1, z1=0.15, motion="fixed")]),
     "bodies"),
    (dict(scheme=dict(kind="isph")), "scheme.kind"),
    (dict(scheme=dict(kind="riemann")), "scheme.kind"),
    (dict(constants=dict(shifting="fickian")), "constants.shifting"),
    (dict(run=dict(device="cuda")), "run.device"),
])
def test_a_3d_scene_refuses_what_the_3d_step_lacks_in_one_line(extra, field):
    with pytest.raises(SceneError) as e:
        make_scene(_box(3, **extra))
    msg = str(e.value)
    assert field in msg and "3D" in msg and "\n" not in msg.strip()


def test_y_needs_a_3d_scene_and_a_3d_tank_needs_y():
    with pytest.raises(SceneError, match="tank.y0"):
        make_scene(_box(2, tank=dict(x0=0, x1=0.4, y0=0, y1=0.3, z0=0, z1=0.4)))
    d = _box(3)
    del d["tank"]["y0"], d["tank"]["y1"]
    with pytest.raises(SceneError, match="tank.y0"):
        make_scene(d)
    with pytest.raises(SceneError, match=r"probes.0.y"):
        make_scene(_box(3, probes=[dict(kind="point", name="p", x=0.2, y=0.5, z=0.1)]))
    sc = make_scene(_box(3))
    assert (sc.water_blocks[0].y0, sc.water_blocks[0].y1) == (0.0, 0.3)   # across the tank
    assert math.isclose(sc.h, 0.04)


def test_a_vertical_cylinder_is_rings_of_wall_particles_with_the_fluid_outside():
    from sph_core.geometry3d import build_layout_3d

    d = _box(3, structures=[dict(shape="cylinder", x0=0.1, x1=0.3, y0=0.05, y1=0.25, z0=0.0,
                                 z1=0.4)])
    lay = build_layout_3d(make_scene(d))
    r_w = np.hypot(lay.wall_x - 0.2, lay.wall_y - 0.15)
    on = (r_w < 0.1) & (lay.wall_z > 0.0)
    radii = np.unique(np.round(r_w[on], 9))
    np.testing.assert_allclose(radii, [0.01, 0.03, 0.05, 0.07, 0.09])   # R - (k + 1/2) dp
    outer = on & (np.abs(r_w - 0.09) < 1e-9) & (np.abs(lay.wall_z - 0.21) < 0.011)
    gaps = np.diff(np.sort(np.arctan2(lay.wall_y[outer] - 0.15, lay.wall_x[outer] - 0.2)))
    assert gaps.max() * 0.09 == pytest.approx(0.02, rel=0.05)          # ~dp along the ring
    r_f = np.hypot(lay.fluid_x - 0.2, lay.fluid_y - 0.15)
    assert r_f.min() >= 0.1 + 0.01 - 1e-9                              # R + dp/2
    with pytest.raises(SceneError, match="diameter"):
        make_scene(_box(3, structures=[dict(shape="cylinder", x0=0.1, x1=0.3, y0=0.05, y1=0.2,
                                            z0=0.0, z1=0.4)]))
    with pytest.raises(SceneError, match="3D scene"):
        make_scene(_box(2, structures=[dict(shape="cylinder", x0=0.1, x1=0.3, z0=0.0, z1=0.4)]))


def test_an_along_slope_bed_is_its_2d_rows_in_every_y_column():
    from sph_core.geometry import _polyline_distance
    from sph_core.geometry3d import build_layout_3d

    bed = dict(points=[[0.1, 0.0], [0.4, 0.1]], layout="along_slope")
    sc = make_scene(_box(3, beds=[bed]))
    lay = build_layout_3d(sc)
    dist, below = _polyline_distance(sc.beds[0], lay.wall_x, lay.wall_z)
    inside = (lay.wall_y > 0.0) & (lay.wall_y < 0.3) & (lay.wall_z > 0.0)   # not the y walls
    on = inside & below & (lay.wall_x > 0.25) & (lay.wall_x < 0.4) & (dist < 0.04)
    rows = dist[on] / 0.02 - 0.5
    np.testing.assert_allclose(rows, np.round(rows), atol=1e-9)   # (k + 1/2) dp below the line
    ys = np.unique(np.round(lay.wall_y[on], 9))
    assert ys.size == round(0.3 / 0.02)                          # every column across the width
    per_y = [np.sum(np.isclose(lay.wall_y[on], y)) for y in ys]
    assert min(per_y) == max(per_y) > 10
