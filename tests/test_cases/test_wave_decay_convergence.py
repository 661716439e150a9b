"""The SPH wave's own loss falls with resolution (slow: about 10 min on one loaded core).

The closed-tank standing wave of wavesph.cases.standing_wave (the wave of bench/wave_decay.py without
inlet, outlet or gauge; docs/studies/wave_decay_study.md) at three resolutions with the scene's
defaults: h/dp 2, alpha 0.01, no artificial viscosity against the walls (alpha_wall_factor 0:
with it the loss does not converge, 6.09 -> 4.73 %/m). Measured on the study's machine
(6 periods): equivalent decay 2.28, 1.80 and 1.24 %/m at dp 0.025, 0.02 and 0.01 (order 0.67
overall, 0.54 over the last halving), noise <= 0.23 % of the wave's kinetic energy -- far from
the issue's target of 1.5: the remaining loss converges slowly (see the study). The
assertions hold what was measured as achievable, with margin for round-off and load only.
"""

import math

import pytest

from wavesph.cases.standing_wave import standing_wave_decay
from wavesph.cases.wave_decay import convergence_orders, convergence_record
from sph_core.scene import Constants

DPS = [0.025, 0.02, 0.01]   # tank 1.0 m long: whole numbers of spacings (no gap at the wall)


@pytest.mark.slow
def test_standing_wave_loss_converges_with_resolution():
    # the scene defaults: h/dp 2, alpha 0.01, alpha_wall_factor 0 (pinned by the first assertion)
    c = Constants()
    assert (c.h_over_dp, c.alpha, c.alpha_wall_factor) == (2.0, 0.01, 0.0)
    runs = [standing_wave_decay(dp=dp, periods=6.0) for dp in DPS]
    decays = [r.equiv_decay_per_m for r in runs]
    for r in runs:
        # particle-scale noise stays a small share of the wave's kinetic energy
        assert r.noise_ke_fraction < 0.02, r
    assert decays[0] > decays[1] > decays[2] > 0, decays
    orders = convergence_orders(DPS, decays)
    overall = math.log(decays[0] / decays[2]) / math.log(DPS[0] / DPS[2])
    assert overall >= 0.4, (decays, orders, overall)
    # H/dp 4 (dp 0.01): <= 3 % per wavelength (measured 2.4 %; issue target 2 %)
    assert runs[2].loss_per_wavelength(2.0) <= 0.03, decays


def test_convergence_record_is_the_benches_summary_line():
    # decay halves when dp halves: order 1; a non-positive decay has no order
    record = convergence_record([0.02, 0.01, 0.005], [0.040004, 0.02, -0.01], "decay_per_m")
    assert list(record) == ["dp", "decay_per_m", "convergence_order"]
    assert record["decay_per_m"] == [0.04, 0.02, -0.01]
    assert record["convergence_order"] == [1.0, None]
