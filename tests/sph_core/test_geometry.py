"""Wall layout: the dummy rows close the corners whatever the tank length."""

import numpy as np
import pytest

from sph_core.geometry import build_layout, wall_dx
from sph_core.scene import make_scene


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
    every layer (the dam-break leak of docs/wall_pressure.md)."""
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
