"""The run-up probe (scene kind "runup"): the shoreline of a constructed wet slope, and still
water on a beach in SPH, whose run-up must stay at the still-water level."""

from __future__ import annotations

import numpy as np
import pytest

from sph_core.probes import bed_elevation, shoreline
from sph_core.scene import SceneError, make_scene
from sph_core.simulation import Simulation

BED = [[(0.3, 0.0), (1.3, 0.1)]]   # 1:10 beach from x = 0.3 m


def wet_slope(dp: float, swl: float) -> tuple[np.ndarray, np.ndarray]:
    """Lattice points above the bed and below still water (the still shoreline at x = 0.3 + 10 swl)."""
    x, z = np.meshgrid((np.arange(int(1.3 / dp)) + 0.5) * dp, (np.arange(int(swl / dp)) + 0.5) * dp)
    x, z = x.ravel(), z.ravel()
    keep = z - bed_elevation(BED, 0.0, x) >= 0.5 * dp
    return x[keep], z[keep]


def test_bed_elevation_is_the_highest_bed_else_the_floor():
    beds = [*BED, [(0.9, 0.0), (1.0, 0.2)]]
    np.testing.assert_allclose(bed_elevation(beds, -0.1, [0.0, 0.8, 0.95, 1.2, 2.0]),
                               [-0.1, 0.05, 0.1, 0.09, -0.1])


def test_shoreline_of_a_wet_slope_skips_drops_and_spray():
    dp, swl = 0.01, 0.05
    x, z = wet_slope(dp, swl)
    counts = np.full(x.size, 12)
    x_wet = x.max()
    # the top row (centre swl - dp/2) is dp/2 above the bed up to x = 0.3 + 10 (swl - dp)
    assert x_wet == pytest.approx(0.3 + 10 * (swl - dp), abs=dp)
    # a drop further up the beach (alone) and a wet clump of spray 5 dp above the bed
    x = np.r_[x, 1.2, 1.0, 1.0 + dp]
    z = np.r_[z, 0.095, 0.07 + 5 * dp, 0.07 + 5 * dp]
    counts = np.r_[counts, 0, 4, 4]
    counts[0] = -1   # a non-fluid particle never counts
    xs, zs = shoreline(x, z, counts, 3, BED, 0.0)
    assert xs == pytest.approx(1.0 + dp) and zs == pytest.approx(0.07 + 5 * dp)  # the spray
    xs, zs = shoreline(x, z, counts, 3, BED, 0.0, near_bed=2 * dp)
    assert xs == pytest.approx(x_wet) and zs == pytest.approx(swl - 0.5 * dp)  # the top row
    assert shoreline(x, z, np.zeros(x.size, int), 3, BED, 0.0) is None


def test_runup_probe_needs_still_water_level():
    with pytest.raises(SceneError, match="still_water_level"):
        make_scene({"dp": 0.01, "t_end": 0.1, "tank": {"x0": 0, "x1": 1, "z0": 0, "z1": 0.3},
                    "water_blocks": [{"x0": 0, "x1": 0.5, "z0": 0, "z1": 0.1}],
                    "probes": [{"kind": "runup", "name": "r"}]})


@pytest.mark.parametrize("layout", ["lattice", "along_slope"])
def test_still_water_on_a_beach_runs_up_to_the_still_water_level(layout):
    """d = 0.1 m, dp = 0.01 m, a 1:5 beach of either layout: for 0.3 s the shoreline stays within
    dp of still water (the layout fills the wedge to the still shoreline x = 0.8 m), R is the
    running max, and no water goes into the bed."""
    dp, d = 0.01, 0.1
    scene = make_scene({
        "dp": dp, "t_end": 0.3, "still_water_level": d,
        "tank": {"x0": 0.0, "x1": 1.0, "z0": 0.0, "z1": 0.2},
        "water_blocks": [{"x0": 0.0, "x1": 0.8, "z0": 0.0, "z1": d}],
        "beds": [{"points": [[0.3, 0.0], [1.0, 0.14]], "layout": layout}],
        "constants": {"wall_slip": "no_slip"},
        "output": {"probe_every": 0.05},
        "probes": [{"kind": "runup", "name": "shore", "near_bed": 2 * dp}]})
    sim = Simulation(scene)
    assert sim.probe_columns() == ["shore_x", "shore_z", "shore_R"]
    sim.advance_to(scene.t_end)
    rows = sim.history
    assert len(rows) >= 6
    z = np.array([r["shore_z"] for r in rows])
    xs = np.array([r["shore_x"] for r in rows])
    R = np.array([r["shore_R"] for r in rows])
    assert np.all((z - 0.2 * (xs - 0.3) > 0) & (z - 0.2 * (xs - 0.3) <= 2 * dp))  # near_bed
    np.testing.assert_allclose(R, np.maximum.accumulate(z - d), atol=1e-12)
    assert np.all(np.abs(z - d) <= dp), z - d
    st = sim.fluid_state()
    # the layouts put water up to the line (the lattice's lowest points 0.0-1 dp above it)
    assert (st["z"] - bed_elevation([scene.beds[0].points], 0.0, st["x"])).min() > 0.0
