"""EurOtop (2018) smooth-slope formulas (wavesph.eurotop): the governing equation switches where
eq. 5.10 meets its maximum eq. 5.11, the band is the coefficients' one standard deviation (its
upper edge is EurOtop's design value), and hand-worked values hold."""

from __future__ import annotations

import math

import pytest

from wavesph.eurotop import breaker_parameter, smooth_slope_overtopping, smooth_slope_ru2

from wave_client import G  # the value wavesph.eurotop uses


def test_breaker_parameter_by_hand():
    # Hm0 0.1 m, T_m-1,0 1.5 s: L0 = 9.81 x 1.5^2 / 2 pi = 3.5129 m; 1:3 slope
    assert breaker_parameter(0.1, 1.5, 1 / 3) == pytest.approx((1 / 3) / math.sqrt(0.1 / 3.512947), rel=1e-4)


def test_breaking_waves_on_a_gentle_slope_follow_eq_5_10():
    hm0, tm10, rc, tan_a = 0.1, 1.5, 0.15, 1 / 4
    o = smooth_slope_overtopping(hm0, tm10, rc, tan_a)
    xi = breaker_parameter(hm0, tm10, tan_a)
    by_hand = 0.023 / math.sqrt(tan_a) * xi * math.exp(-((2.7 * rc / (xi * hm0)) ** 1.3))
    assert o.regime.startswith("breaking") and o.xi == pytest.approx(xi)
    assert o.q == pytest.approx(by_hand * math.sqrt(G * hm0**3), rel=1e-12)
    design = 0.026 / math.sqrt(tan_a) * xi * math.exp(-((2.5 * rc / (xi * hm0)) ** 1.3))
    assert o.q_hi == pytest.approx(design * math.sqrt(G * hm0**3), rel=1e-12)
    assert o.q_lo < o.q < o.q_hi


def test_steep_slopes_reach_the_maximum_eq_5_11():
    hm0, rc = 0.075, 0.1
    o = smooth_slope_overtopping(hm0, 1.27, rc, 1 / 2)
    assert o.regime.startswith("non-breaking")
    assert o.q == pytest.approx(0.09 * math.exp(-((1.5 * rc / hm0) ** 1.3)) * math.sqrt(G * hm0**3),
                                rel=1e-12)
    # more freeboard, less water; zero freeboard gives the formula's largest value
    assert smooth_slope_overtopping(hm0, 1.27, 2 * rc, 0.5).q < o.q
    assert smooth_slope_overtopping(hm0, 1.27, 0.0, 0.5).q == pytest.approx(0.09 * math.sqrt(G * hm0**3))


def test_ru2_rises_with_xi_then_saturates():
    # xi = 1.5 (gentle): 1.65 xi; xi = 5 (steep): the maximum 4 - 1.5 / sqrt(xi)
    hm0 = 0.1
    l0 = G * 1.5**2 / (2 * math.pi)
    gentle = 1.5 * math.sqrt(hm0 / l0)
    assert smooth_slope_ru2(hm0, 1.5, gentle) == pytest.approx(hm0 * 1.65 * 1.5, rel=1e-9)
    steep = 5.0 * math.sqrt(hm0 / l0)
    assert smooth_slope_ru2(hm0, 1.5, steep) == pytest.approx(hm0 * (4 - 1.5 / math.sqrt(5)), rel=1e-9)


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="hm0"):
        smooth_slope_overtopping(0.0, 1.5, 0.1, 0.5)
    with pytest.raises(ValueError, match="rc"):
        smooth_slope_overtopping(0.1, 1.5, -0.1, 0.5)
