"""Particle layout of a sloped bed (docs/SHORELINE_JET.md): the fluid lattice meets the bed's
dummies at the flat floor's spacing dp in every lattice column, with no void between them."""

from __future__ import annotations

import numpy as np
import pytest

from sph_core.geometry import _polyline_distance, build_layout
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
