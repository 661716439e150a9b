"""The linear potential-flow heave reference (wavesph/cases/heave_potential.py) in limits it must meet."""

from __future__ import annotations

import math

import pytest

from wavesph.cases.heave_potential import heave_release


def test_heavy_box_oscillates_quasi_statically_with_the_tank_level_coupling():
    """M >> added mass: T = 2 pi sqrt((M + a) / (rho g B (1 + B / (L - B)))) (the closed tank's
    level rises as the box sinks), and the outer surface conserves volume."""
    m = 1.0e5
    ts, zs = heave_release(3.2, 0.3, 0.4, 0.1, m, -0.01, 10.0, dx=0.01, dt=5e-3)
    a = heave_release.last["a_inf"]
    period = 2 * math.pi * math.sqrt((m + a) / (1000 * 9.81 * 0.4 * (1 + 0.4 / 2.8)))
    assert zs[-1] / zs[0] == pytest.approx(math.cos(2 * math.pi * ts[-1] / period), abs=2e-3)
    assert 50.0 < a < 200.0   # infinite-frequency added mass [kg/m] of this box, positive
    assert abs(heave_release.last["volume_rate_check"]) < 0.01 * 0.4
