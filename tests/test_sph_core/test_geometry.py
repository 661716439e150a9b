"""Particle layout: a sloped bed meets the fluid lattice at spacing dp in every column
(docs/studies/SHORELINE_JET.md); the wall's dummy rows close the corners whatever the tank length
(docs/studies/wall_pressure.md)."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import cKDTree

from sph_core.geometry import _polyline_distance, build_layout, wall_dx
from sph_core.scene import make_scene


def beach_scene(dp: float, slope: float) -> dict:
    return {"name": "beach", "dp": dp, "t_end": 0.1, "still_water_level": 0.24,
            "tank": {"x0": 0.0, "x1": 5.4, "z0": 0.0, "z1": 0.6},
            "water_blocks": [{"x0": 0.0, "x1": 2.0 + 0.24 / slope, "z0": 0.0, "z1": 0.24}],
            "beds": [{"points": [[2.0, 0.0], [5.4, 3.4 * slope]]}]}


@pytest.mark.parametrize("dp,slope", [(0.02, 0.1), (0.04, 0.1), (0.02, 0.3), (0.01, 1 / 12)])
def test_every_column_on_a_slope_meets_the_bed_at_spacing_dp(dp, slope):
    scene = make_scene(beach_scene(dp, slope))
    lay = build_layout(scene)
    bed = scene.beds[0]
    # no fluid below the bed line, and every fluid-free lattice point below it is a dummy
    _, below = _polyline_distance(bed, lay.fluid_x, lay.fluid_z)
    assert not below.any()
    gaps = []
    for x in np.unique(np.round(lay.fluid_x, 9)):
        if not 2.0 + dp < x < 2.0 + 0.24 / slope - dp:
            continue
        fz = lay.fluid_z[np.isclose(lay.fluid_x, x)]
        wz = lay.wall_z[np.isclose(lay.wall_x, x)]
        gaps.append(fz.min() - wz[wz < fz.min()].max())
    assert len(gaps) > 10
    # the void of the old layout (a band of dp/2 kept fluid-free) made about half the gaps 2 dp
    assert np.allclose(gaps, dp, rtol=1e-6), sorted(set(np.round(np.array(gaps) / dp, 3)))


@pytest.mark.parametrize("dp,slope", [(0.02, 0.1), (0.01, 1 / 19.85), (0.02, 0.3)])
def test_an_along_slope_bed_is_rows_parallel_to_it_that_leave_no_hole(dp, slope):
    """``layout = along_slope``: along the slope the dummy particles are rows (k + 1/2) dp below
    the line (a smooth bed, not the lattice's staircase); where the slope meets the floor, a
    crest (a convex joint) and the right wall, no two are closer than 0.7 dp and no point
    of the walls' thickness below the line is 0.9 dp or farther from one (no hole)."""
    x_crest = 2.0 + 0.3 / slope
    scene = make_scene({"dp": dp, "t_end": 0.1, "tank": {"x0": 0.0, "x1": x_crest + 0.5,
                                                         "z0": 0.0, "z1": 0.6},
                        "water_blocks": [{"x0": 0.0, "x1": 2.0 + 0.24 / slope, "z0": 0.0,
                                          "z1": 0.24}],
                        "beds": [{"points": [[2.0, 0.0], [x_crest, 0.3], [x_crest + 0.5, 0.3]],
                                  "layout": "along_slope"}]})
    lay = build_layout(scene)
    bed, th = scene.beds[0], lay.n_layers * dp
    wx, wz = lay.wall_x, lay.wall_z
    dist, below = _polyline_distance(bed, wx, wz)
    # the rows away from the toe's wedge (where the floor's rows take over) and the crest
    mid = below & (wx > 2.0 + 2 * dp / slope) & (wx < x_crest - 0.1) & (dist < th) & (wz > 0.0)
    rows = dist[mid] / dp - 0.5
    assert mid.sum() > 20 * lay.n_layers
    assert np.allclose(rows, np.round(rows), atol=1e-9), sorted(set(np.round(rows, 3)))
    tree = cKDTree(np.column_stack([wx, wz]))
    assert tree.query(tree.data, k=2)[0][:, 1].min() > 0.7 * dp   # nearest other dummy
    sx, sz = np.meshgrid(np.linspace(1.9, x_crest + 0.5, 400), np.linspace(0.0, 0.31, 80))
    sx, sz = sx.ravel(), sz.ravel()
    d, under = _polyline_distance(bed, sx, sz)
    band = under & (d > 0.5 * dp) & (d < th - 0.5 * dp) & (sx < x_crest + 0.5 - dp)
    reach = tree.query(np.column_stack([sx, sz])[band])[0]
    assert reach.max() < 0.9 * dp, reach.max() / dp   # the lattice's: 0.71 dp; seams ~0.85 dp
    _, fluid_below = _polyline_distance(bed, lay.fluid_x, lay.fluid_z)
    assert not fluid_below.any()


def tank_scene(length: float, dp: float, h_over_dp: float = 1.4142, beds=()):
    return make_scene({"dp": dp, "t_end": 1.0,
                       "tank": {"x0": 0.0, "x1": length, "z0": 0.0, "z1": 0.4},
                       "water_blocks": [{"x0": 0.0, "x1": 0.3, "z0": 0.0, "z1": 0.2}],
                       "beds": [{"points": list(b)} for b in beds],
                       "constants": {"h_over_dp": h_over_dp}})


@pytest.mark.parametrize("cells", [100.0, 100.5, 100.25, 100.75])
@pytest.mark.parametrize("h_over_dp", [1.4142, 2.0])
def test_bottom_rows_meet_both_side_walls_without_a_gap(cells, h_over_dp):
    """Every bottom layer runs from the left wall's columns to the right wall's with spacings
    within 1 % of dp. A tank 100.5 dp long used to leave a 1.5 dp gap at the right corner in
    every layer (the dam-break leak of docs/studies/wall_pressure.md)."""
    dp = 0.01
    lay = build_layout(tank_scene(cells * dp, dp, h_over_dp))
    for k in range(lay.n_layers):
        row = np.sort(lay.wall_x[np.isclose(lay.wall_z, -(k + 0.5) * dp)])
        gaps = np.diff(row)
        assert row[0] < 0 and row[-1] > cells * dp        # the side columns reach down here
        assert gaps.max() < 1.01 * dp and gaps.min() > 0.99 * dp, (k, gaps.min() / dp, gaps.max() / dp)


def test_wall_spacing_is_dp_for_a_whole_number_of_spacings():
    assert wall_dx(tank_scene(1.0, 0.01)) == pytest.approx(0.01, rel=1e-12)
    assert wall_dx(tank_scene(1.005, 0.01)) == pytest.approx(1.005 / 100, rel=1e-12)


def test_sloping_bed_rows_share_the_bottom_spacing_near_the_right_wall():
    """A bed reaching the right wall of a tank 100.5 dp long: its dummy particles and the right
    wall's first column leave no gap wider than the lattice diagonal."""
    dp = 0.01
    L = 1.005
    lay = build_layout(tank_scene(L, dp, beds=[[(0.5, 0.0), (L, 0.1)]]))
    x, z = lay.wall_x, lay.wall_z
    # the wall particles near the bed's end at the right wall (within the dummy thickness)
    near = (x > L - 0.1) & (z > 0.03) & (z < 0.09)
    pts = np.column_stack([x[near], z[near]])
    d = np.sqrt(((pts[:, None, :] - pts[None, :, :]) ** 2).sum(-1))
    np.fill_diagonal(d, np.inf)
    assert d.min(axis=1).max() < 1.01 * dp   # every particle has a neighbour one spacing away
    bed_right = np.sort(x[np.isclose(z, 0.095) & (x < L)])   # a dummy row just below the bed top
    assert bed_right.size and L - bed_right[-1] < 0.51 * dp + 1e-12


def test_geometry_vtu_is_line_cells_that_meshio_reads(tmp_path):
    """geometry.vtu (`wavesph run --preview`): poly-line cells and pyevtk's NumberOfCells="5.0"
    made meshio refuse it; two-point line cells (VTK type 3) with integer counts open anywhere."""
    import re

    from sph_core.output import write_geometry_vtk
    from sph_core.scene import load_scene

    scene = load_scene(Path(__file__).resolve().parents[2] / "examples/scenes/demo_beach_flume.toml")
    path = write_geometry_vtk(scene, tmp_path / "geometry")
    head = path.read_bytes().split(b"<AppendedData")[0].decode()
    assert re.search(r'NumberOfCells="5"', head)   # tank 3 segments, the bed 1, the inlet 1
    meshio = pytest.importorskip("meshio")
    mesh = meshio.read(path)
    assert [c.type for c in mesh.cells] == ["line"] and len(mesh.cells[0].data) == 5
    assert mesh.cell_data["part"][0].ravel().tolist() == [0, 0, 0, 1, 3]


def full_tank(length: float) -> dict:
    return {"name": "tank", "dp": 0.02, "t_end": 0.1, "still_water_level": 0.24,
            "tank": {"x0": 0.0, "x1": length, "z0": 0.0, "z1": 0.36},
            "water_blocks": [{"x0": 0.0, "x1": length, "z0": 0.0, "z1": 0.24}]}


def test_water_short_of_the_right_wall_by_a_fraction_of_dp_is_warned():
    # 1.99 m = 99.5 dp: the lattice from x0 leaves 0.5 dp at the right wall (a slump at the start)
    with pytest.warns(UserWarning, match=r"0\.50 dp short of the right wall"):
        build_layout(make_scene(full_tank(1.99)))


def test_a_whole_number_of_dp_a_dam_break_column_and_a_beach_are_not_warned():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        build_layout(make_scene(full_tank(2.0)))
        column = full_tank(1.99)
        column["water_blocks"][0]["x1"] = 0.5   # the water does not reach the wall
        build_layout(make_scene(column))
        beach = full_tank(1.99)                 # a beach up to the wall holds the corner
        beach["beds"] = [{"points": [[1.0, 0.0], [1.99, 0.3]]}]
        build_layout(make_scene(beach))


def open_flume(**end) -> dict:
    """A flume 0.6 m long in 0.3 m of water, open at both ends (``end``: the left end's extra
    settings)."""
    return {"name": "open", "dp": 0.02, "t_end": 1.0, "still_water_level": 0.3,
            "tank": {"x0": 0.0, "x1": 0.6, "z0": 0.0, "z1": 0.42},
            "water_blocks": [{"x0": 0.0, "x1": 0.6, "z0": 0.0, "z1": 0.3}],
            "open_boundaries": [{"side": "left", **end}, {"side": "right",
                                                          "elevation": "extrapolated"}]}


def test_orbit_diameter_is_linear_theorys():
    from sph_core.open_ends import orbit_diameter
    # deep water: the orbit is the wave height; shallow: H / kd, longer than H
    assert orbit_diameter(0.1, 1.0, 10.0) == pytest.approx(0.1, rel=1e-9)
    # kd from the diameter satisfies the dispersion relation omega^2 = g k tanh kd
    t = 0.06 / orbit_diameter(0.06, 2.0, 0.3)
    assert (2 * np.pi / 2.0) ** 2 == pytest.approx(9.81 * np.arctanh(t) / 0.3 * t, rel=1e-6)
    assert orbit_diameter(0.01, 20.0, 0.3) > 10 * 0.01


def test_buffer_width_is_the_scenes_else_the_kernel_support():
    from sph_core.open_ends import buffer_widths
    from wavesph.cases.wave_flume import buffer_width_for, wave_flume_scene

    scene = make_scene(open_flume(buffer_width=0.3))
    assert buffer_widths(scene) == {"left": 0.3, "right": pytest.approx(2 * scene.h)}
    with pytest.raises(ValueError, match="buffer_width"):
        make_scene(open_flume(buffer_width=0.0))
    # a wave flume's builders size it from the wave: the orbit plus 4 dp, in whole dp
    w = buffer_width_for(0.06, 2.0, 0.3, 0.0075)
    assert w == pytest.approx(0.0075 * 20)            # case V at H/dp 8: 0.115 m + 0.03 m
    flume = wave_flume_scene(depth=0.3, wavelength=3.3, height=0.06, dp=0.015, t_end=1.0,
                             period=2.0)
    assert buffer_widths(flume) == {"left": pytest.approx(0.18), "right": pytest.approx(0.18)}


def test_a_wider_open_end_gets_whole_columns_outside_its_face():
    from sph_core.geometry import buffer_layers, wall_layers
    from sph_core.geometry3d import build_layout_3d

    scene = make_scene(open_flume())
    nl = wall_layers(scene)
    assert buffer_layers(scene, None) == nl
    assert buffer_layers(scene, 0.01) == nl                 # never below the walls' layers
    assert buffer_layers(scene, 0.25) == 13                 # 12.5 dp, rounded up
    plain, wide = build_layout(scene), build_layout(scene, {"left": 13})
    column = np.sum(np.isclose(plain.wall_x, -0.01))        # the first column outside x0
    assert wide.wall_x.size - plain.wall_x.size == (13 - nl) * column
    xs = np.unique(np.round(wide.wall_x[wide.wall_x < 0] / 0.02 - 0.5))
    np.testing.assert_array_equal(xs, -np.arange(13, 0, -1))   # no gap between the columns
    np.testing.assert_array_equal(wide.fluid_x, plain.fluid_x)
    # 3D: the extra columns span the y walls too (the buffer's sides)
    s3 = make_scene({**open_flume(), "dim": 3, "dp": 0.05, "still_water_level": 0.3,
                     "tank": {"x0": 0.0, "x1": 0.6, "y0": 0.0, "y1": 0.2, "z0": 0.0, "z1": 0.4},
                     "water_blocks": [{"x0": 0.0, "x1": 0.6, "y0": 0.0, "y1": 0.2, "z0": 0.0,
                                       "z1": 0.3}]})
    p3, w3 = build_layout_3d(s3), build_layout_3d(s3, {"right": wall_layers(s3) + 2})
    face = np.sum(np.isclose(p3.wall_x, 0.6 + 0.025))
    assert w3.wall_x.size - p3.wall_x.size == 2 * face
    assert w3.wall_x.max() == pytest.approx(0.6 + (wall_layers(s3) + 1.5) * 0.05)
