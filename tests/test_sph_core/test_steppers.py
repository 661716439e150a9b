"""The schemes behind one stepper (sph_core.steppers): each scheme's Params from the scene, and
the Python time loop ``drive`` (stop conditions, status codes, no sliver steps). No numba here:
the steppers' passes run in test_isph.py, test_simulation.py and the refactor check."""

import math

import pytest

from sph_core.isph import IsphStepper
from sph_core.scene import make_scene
from sph_core.steppers import WcsphStepper, drive, make_stepper
from sph_core.wcsph import ST_CAPACITY, ST_NONFINITE, ST_REACHED_T, ST_STEP_LIMIT

BASE = dict(h=0.014, alpha_w=1.0, alpha_f=2.0, rho0=1000.0, c0=20.0, b=1e5, gamma=7.0, gx=0.0,
            gz=-9.81, nu=1e-6, delta=0.1, rho_lo=0.9, rho_hi=1.1, noslip=True, fx0=0.0, fx1=1.0,
            fz0=0.0, fz1=1.0, alpha_wall=1.0, shift_fs_div=1.5, shift_inv_wdp=1.0, shift_open=0)


def scene(scheme=None, **constants):
    return make_scene({"dp": 0.01, "t_end": 1.0, "tank": {"x0": 0, "x1": 0.5, "z0": 0, "z1": 0.4},
                       "water_blocks": [{"x0": 0, "x1": 0.5, "z0": 0, "z1": 0.2}],
                       "scheme": scheme or {}, "constants": constants})


def test_each_scheme_makes_its_own_params():
    wc = make_stepper(scene(shifting="dplus", shift_dplus_scale=0.5, alpha=0.02), 10)
    assert isinstance(wc, WcsphStepper)
    p = wc.params(scene(shifting="dplus", shift_dplus_scale=0.5, alpha=0.02), BASE, 3)
    assert p.alpha == 0.02 and p.shift_dplus and p.shift_a == 2.0 and p.wall_g0 > 0.0
    assert not p.riemann and wc.prm is p
    rs = scene({"kind": "riemann"})
    assert make_stepper(rs, 10).params(rs, BASE, 3).riemann
    sc = scene({"kind": "isph", "isph_cfl": 0.15}, shifting="dplus", alpha=0.02)
    st = make_stepper(sc, 10)
    assert isinstance(st, IsphStepper) and st.passes_per_step == 1
    q = st.params(sc, BASE, 3)
    # ISPH: no artificial viscosity, the flow speed's Courant number, Fickian shifting without
    # the carry, its own no-penetration (no wall-face shares)
    assert q.alpha == 0.0 and q.cfl == 0.15 and not q.shift_dplus and not q.shift_carry
    assert q.shift_a == sc.constants.shift_a and q.wall_g0 == q.wall_ga == q.wall_gb == 0.0
    assert st.shifting and st.wscale == pytest.approx(7.0 / (1000.0 * 0.014 ** 2))


def test_initial_fluid_is_compressed_for_wcsph_and_rho0_with_hydrostatic_p_for_isph():
    import numpy as np

    z = np.array([0.0, 0.1])
    surf = np.array([0.2, 0.2])
    rho, p = make_stepper(scene(), 10).initial_fluid(z, surf)
    assert p is None and rho[0] > rho[1] > 1000.0
    rho, p = make_stepper(scene({"kind": "isph"}), 10).initial_fluid(z, surf)
    assert np.all(rho == 1000.0) and p == pytest.approx(1000.0 * 9.81 * (surf - z))


class Steps:
    """A fake step: records (t, dt), returns a fixed next dt and, at step ``fail``, a status."""

    def __init__(self, dt_next=1.0, fail=None, status=ST_NONFINITE, done=True):
        self.taken = []
        self.dt_next = dt_next
        self.fail = fail
        self.status = status
        self.done = done

    def __call__(self, t, dt):
        self.taken.append((t, dt))
        if len(self.taken) == self.fail:
            return self.status, 7, 4.0, self.dt_next, self.done
        return ST_REACHED_T, 0, 1.0, self.dt_next, True


def test_drive_stops_at_t_stop_without_a_sliver_step():
    s = Steps()
    t, dt, steps, status, swapped, n_flag, vmax = drive(s, 0.0, 1.0, 3.2, 100)
    # 1, 1, then the remainder 1.2 < 1.5 dt is shared: 0.6 + 0.6, the last one landing on t_stop
    assert [d for _, d in s.taken] == pytest.approx([1.0, 1.0, 0.6, 0.6])
    assert (t, steps, status, swapped, n_flag) == (3.2, 4, ST_REACHED_T, 0, 0) and vmax == 1.0
    # a round-off remainder (< 1e-6 dt) is not stepped
    s = Steps()
    assert drive(s, 5.0 - 1e-9, 1.0, 5.0, 100)[:3] == (5.0, 1.0, 0) and s.taken == []


def test_drive_reports_the_step_limit_and_a_tripped_guard():
    s = Steps(dt_next=0.5)
    t, dt, steps, status, swapped, _, _ = drive(s, 0.0, 1.0, math.inf, 3)
    assert (t, dt, steps, status, swapped) == (2.0, 0.5, 3, ST_STEP_LIMIT, 1)
    s = Steps(fail=2)
    t, dt, steps, status, swapped, n_flag, vmax = drive(s, 0.0, 1.0, 10.0, 100)
    assert (t, dt, steps, status, swapped, n_flag, vmax) == (2.0, 1.0, 2, ST_NONFINITE, 0, 7, 2.0)
    # a step that could not finish (out of capacity) is neither counted nor swapped
    s = Steps(fail=2, status=ST_CAPACITY, done=False)
    t, _, steps, status, swapped, n_flag, _ = drive(s, 0.0, 1.0, 10.0, 100)
    assert (t, steps, status, swapped, n_flag) == (1.0, 1, ST_CAPACITY, 1, 7)
