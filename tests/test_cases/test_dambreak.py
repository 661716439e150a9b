"""Dam break (Martin & Moyce geometry) against the measured surge front.

Scaled column a = 0.1 m (height 2a) in a 5a tank, a/dp = 20, run to T = t sqrt(2g/a) = 3.1.
References, copied into tests/data with their sources:
- Martin & Moyce (1952), the case's own experiment;
- Koshizuka & Oka (1996), a second measurement of the same 2:1 column.
Front = largest x of fluid particles with at least 3 fluid neighbours within 2h.
"""

import math
from pathlib import Path

import numpy as np
import pytest

from wavesph.cases.dambreak import dambreak_scene, front_errors, martin_moyce_table
from sph_core.simulation import Simulation

DATA = Path(__file__).resolve().parents[1] / "data"
A = 0.1
T_END = 3.1


def run_dambreak(resolution: int, **constants):
    t_end = T_END / math.sqrt(2 * 9.81 / A)
    scene = dambreak_scene(a=A, dp=A / resolution, t_end=t_end, tank_length=5 * A, **constants)
    sim = Simulation(scene)
    m0, n0 = sim.fluid_state()["m"], sim.n_fluid
    sim.advance_to(t_end)
    hist = [(r["t"], r["front_x"]) for r in sim.history]
    t, x = np.array(hist).T
    return sim, t, x, m0, n0


# every scheme (the scene's [scheme] tables) runs the coarse case's tests
SCHEMES = {"wcsph": None, "riemann": {"kind": "riemann"}, "isph": {"kind": "isph"}}


# ISPH (a sparse solve per step) runs the case in minutes: slow
@pytest.fixture(scope="module", params=["wcsph", "riemann", pytest.param("isph", marks=pytest.mark.slow)])
def coarse(request):
    return run_dambreak(20, scheme=SCHEMES[request.param])


def test_tables_are_the_shipped_copies():
    mine = martin_moyce_table(DATA / "dambreak_martin_moyce_1952.csv")
    shipped = martin_moyce_table()
    np.testing.assert_array_equal(mine[0], shipped[0])
    np.testing.assert_array_equal(mine[1], shipped[1])


def test_mass_exactly_conserved_and_fluid_stays_in_tank(coarse):
    sim, t, x, m0, n0 = coarse
    assert sim.n_fluid == n0
    st = sim.fluid_state()
    np.testing.assert_array_equal(st["m"], m0)      # each particle's mass, compared by id
    tank = sim.scene.tank
    hd = 0.5 * sim.scene.dp   # the first dummy layer: a centre beyond it went through the wall
    assert np.all((st["x"] >= tank.x0 - hd) & (st["x"] <= tank.x1 + hd) & (st["z"] >= tank.z0 - hd))


def _isph_xfail(request, reason: str) -> None:
    """ISPH's measured shortfall on this case (docs/studies/schemes.md "## ISPH"): strict xfail."""
    if request.node.callspec.params["coarse"] == "isph":
        request.applymarker(pytest.mark.xfail(strict=True, reason="ISPH (a/dp 20, h/dp sqrt 2): "
                                              + reason + "; measured, not tuned away"))


def test_front_within_10_percent_of_koshizuka_oka(coarse, request):
    _isph_xfail(request, "max front error 15.0 % against Koshizuka & Oka")
    _, t, x, *_ = coarse
    table = martin_moyce_table(DATA / "dambreak_koshizuka_oka_1996.csv")
    keep = table[0] > 0  # T = 0 is the initial column itself
    err = front_errors(t, x, A, t_max=3.0, table=(table[0][keep], table[1][keep]))
    assert err["max_rel_error"] < 0.10, err


def test_front_within_10_percent_of_martin_moyce(coarse, request):
    """With the case's alpha = 0.1 (DualSPHysics CaseDambreak); with alpha = 0.01 the front leads
    by up to 13.8 % at T = 1.2 (measured, reported, not tuned away). Riemann SPH has no alpha:
    11.6 % (docs/studies/schemes.md); within 10 % of Koshizuka & Oka."""
    if request.node.callspec.params["coarse"] == "riemann":
        request.applymarker(pytest.mark.xfail(strict=True, reason=(
            "Riemann SPH (MUSCL, van Leer, beta 1): max front error 11.6 % against Martin & "
            "Moyce at a/dp 20; measured, not tuned away")))
    _isph_xfail(request, "max front error 14.8 % against Martin & Moyce (WCSPH 8.4 %)")
    _, t, x, *_ = coarse
    err = front_errors(t, x, A, t_max=3.0, table=martin_moyce_table(DATA / "dambreak_martin_moyce_1952.csv"))
    assert err["max_rel_error"] < 0.10, err


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason=(
    "measured: refining a/dp 20 -> 40 moves the front AWAY from Martin & Moyce (max error 8.4 % -> "
    "12.3 %, rms 4.1 % -> 6.3 %; a/dp = 100 in bench/dambreak_reference.py: 15.4 %, rms 9.1 %): "
    "less numerical viscosity, a faster early surge than the experiment, whose gate release "
    "delays it. The spec asked for 'closer at finer resolution'."))
def test_finer_resolution_closer_to_martin_moyce(coarse, request):
    if request.node.callspec.params["coarse"] != "wcsph":
        pytest.skip("the measured xfail is WCSPH's")
    table = martin_moyce_table(DATA / "dambreak_martin_moyce_1952.csv")
    _, t20, x20, *_ = coarse
    _, t40, x40, *_ = run_dambreak(40)
    e20 = front_errors(t20, x20, A, t_max=3.0, table=table)
    e40 = front_errors(t40, x40, A, t_max=3.0, table=table)
    assert e40["rms_rel_error"] < e20["rms_rel_error"]


def test_front_moves_monotonically_and_ahead_of_column(coarse, request):
    _isph_xfail(request, "the front jumps back by more than dp/2 (a fragmented surge)")
    _, t, x, *_ = coarse
    assert x[0] == pytest.approx(A - 0.5 * A / 20)      # the column's last particle row
    assert np.all(np.diff(x) > -0.5 * A / 20)            # no jumps back by more than dp/2
    assert x[-1] / A > 3.0
