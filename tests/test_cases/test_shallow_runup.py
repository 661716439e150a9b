"""The shallow-water run-up reference of bench/runup.py (wavesph.cases.shallow_runup): water at
rest stays at rest over a wet/dry beach, the scheme conserves water, and a non-breaking solitary
wave runs up as far as Synolakis' (1987) law, which is this model's own answer."""

import math

import numpy as np
import pytest

from wavesph.cases.shallow_runup import _rates, solitary_runup

COT = 19.85


def _beach(depth: float = 0.2, dx: float = 0.004):
    x = np.arange(-1.0 + dx / 2, depth * COT + 1.0, dx)
    bed = np.where(x > 0, x / COT, 0.0) - depth
    return x, bed, dx


def test_still_water_over_a_beach_stays_still():
    """The hydrostatic reconstruction balances the slope's source in the wet cells, at the
    shoreline's partly wet ones and on the dry beach above it."""
    x, bed, dx = _beach()
    h = np.maximum(-bed, 0.0)
    dh, dq, _ = _rates(h, np.zeros_like(h), bed, dx)
    assert np.abs(dh).max() < 1e-12
    assert np.abs(dq).max() < 1e-10


def test_a_wave_on_the_beach_keeps_its_water():
    """Away from the ends the volume rate is zero to round-off: what one face takes out, the
    next brings in (the wave and the shoreline both well inside the grid)."""
    x, bed, dx = _beach()
    eta = 0.01 * np.exp(-((x - 2.0) / 0.3) ** 2)
    h = np.maximum(eta - bed, 0.0) * (bed < 0)
    q = h * 0.5 * eta
    dh, _, _ = _rates(h, q, bed, dx)
    assert abs(dh.sum() * dx) < 1e-12 * h.sum() * dx
    assert np.abs(dh).max() > 1e-4       # the wave does move


def test_non_breaking_runup_meets_synolakis_law():
    """H/d 0.0185 (the canonical non-breaking case): R/d 0.0877 at 25 cells per depth against
    the law's 0.0861 (50 cells: 0.0886)."""
    ref = solitary_runup(0.0185 * 0.2, 0.2, COT, cells_per_depth=25)
    law = 2.831 * math.sqrt(COT) * 0.0185**1.25
    assert ref.runup / 0.2 == pytest.approx(law, rel=0.05)
    # the sections' excess water falls towards the shoreline: each section passes on less
    v = [ref.excess[s] for s in sorted(ref.excess, reverse=True)]
    assert all(a > b for a, b in zip(v, v[1:])) and v[-1] > 0
    # at the toe nearly the whole wave (2 H / k per unit width) is shoreward at once
    k = math.sqrt(3 * 0.0185 * 0.2 / (4 * 0.2**3))
    assert 0.8 < ref.excess[1.0] / (2 * 0.0185 * 0.2 / k) <= 1.0
    # the film under the run-up's highest point is thin, and deeper further down the beach
    assert ref.film_at(0.5 * ref.runup) > ref.film_at(0.9 * ref.runup) >= 0.0


@pytest.mark.parametrize("kw", [dict(height=0.0), dict(depth=-1.0), dict(cells_per_depth=5),
                                dict(sections=(1.5,))])
def test_bad_input_is_refused(kw):
    args = dict(height=0.01, depth=0.2)
    args.update(kw)
    with pytest.raises(ValueError):
        solitary_runup(**args)
