"""The seed-004 3D case at a coarse dp: the dam break against a tall square column runs to its
end with no particle through a wall, and its force history is compared with Yeh & Petroff's
measurement (the finer dp, and what limits the agreement: bench/tall_structure.py and
docs/developer/three_dimensions.md)."""

import numpy as np
import pytest

from sph_core.simulation import Simulation
from wavesph.cases.tall_structure import TALL_COLUMN, force_errors, measured_force, tall_structure_scene


def test_measured_force_is_the_digitised_record():
    t, f = measured_force()
    assert t.size > 300 and np.all(np.diff(t) >= 0)
    assert 32.0 < f.max() < 34.0 and 0.38 < t[np.argmax(f)] < 0.42   # the impact peak


@pytest.fixture(scope="module")
def coarse_run():
    sim = Simulation(tall_structure_scene(dp=0.04, t_end=1.5))
    sim.advance_to(1.5, progress=None)
    return sim


def test_the_3d_dam_break_runs_to_its_end_inside_the_tank(coarse_run):
    sim = coarse_run
    assert sim.t == pytest.approx(1.5) and not sim.excluded    # no particle through a wall
    assert sim.n_fluid == sim.n_fluid0
    ps = sim.particles
    from sph_core.particles import FLUID, X, Y, Z
    fl = ps.mask(FLUID)
    x, y, z = ps.field(X)[fl], ps.field(Y)[fl], ps.field(Z)[fl]
    # none through the column: no centre past its first layer of particles, dp/2 inside its
    # faces (the tank's own rule: sph_core.simulation's fluid box)
    x0, x1, y0, y1 = TALL_COLUMN
    depth = np.minimum.reduce([x - x0, x1 - x, y - y0, y1 - y])
    assert depth.max() < 0.5 * 0.04
    assert x.max() < 1.6 and y.min() > 0.0 and y.max() < 0.61 and z.min() > 0.0


def test_the_column_force_against_the_measurement_at_coarse_dp(coarse_run):
    """dp 0.04 m: 1050 fluid particles, the column 3 particles wide. The surge reaches the
    column when the measured force rises (the dry bed here brings it a few hundredths of a
    second early: the experiment's bed was wet), pushes it downstream with a plateau after
    the impact, and the mean y force stays small against x (the column sits near mid-width). The
    peak is underestimated at this dp (-67 %; -39 % at dp 0.02): the bounds below hold that
    measured state, so a change that loses the surge fails here."""
    h = coarse_run.history
    t = np.array([r["t"] for r in h])
    fx = np.array([r["column_fx"] for r in h])
    fy = np.array([r["column_fy"] for r in h])
    onset = t[np.argmax(fx > 2.0)]
    assert 0.25 < onset < 0.36                     # measured 0.34 s
    assert fx[t < 0.2].max() < 0.5                 # nothing before the surge could arrive
    plateau = fx[(t > 0.5) & (t < 0.9)].mean()
    assert 4.0 < plateau < 17.0                    # measured 16.6 N (0.5-0.9 s mean)
    wet = (t > 0.3) & (t < 1.2)
    assert abs(fy[wet].mean()) < 0.2 * fx[wet].mean()   # no mean side force (instants: eddies)
    err = force_errors(t, fx, 0.0, 1.5)
    assert -0.8 < err["peak_force_error"] < 0.0
    assert err["rms_force_error"] < 0.4
