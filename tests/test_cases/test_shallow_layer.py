"""Still water only a few particles deep (a beach's shallows, a swash film) under the c0 of deeper
water: wavesph's stability scenario ``shallow_water`` (5 dp deep, dp 0.02, c0 of a 0.3 m tank,
3 s). When the leapfrog (kdk) read its pressure from the density only half a step past its
half-kicked value, the layer broke up at the default delta-SPH coefficient 0.1 (0.32 sqrt(g d) at
3 s; the run-up beach at d/dp 40 burst at rest within 0.5 s): that read amplifies sound by
(k c dt)^2/4 a step, more than delta 0.1 damps (``wcsph.kdk_pressure``, docs/physics/wcsph.md).
Each integrator must hold the layer as still as deep water at the default delta and above."""

import pytest

from wavesph.studies.stability import _shallow_water


@pytest.mark.parametrize("constants", [
    {},
    {"delta": 0.2},
    {"integrator": "symplectic_pc"},
])
def test_a_layer_five_particles_deep_stays_still(constants):
    rec = _shallow_water(dict(constants), quick=True)
    assert rec["status"] == "stable", rec["reason"]
    assert rec["value"] < 0.02
