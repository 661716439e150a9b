"""The fluid-wall pair's tension (wcsph.fluid_pass): a fluid particle in tension (p < 0) feels
no tension across a wall while it approaches the wall, and keeps it while it moves away.

Why both (docs/studies/wall_pressure.md): without the clamp a dry-bed front's particles in
tension are pulled into the bed and sink through it; with it everywhere, a thin swash film on a
beach loses the bed's pull and tears (the coupled flume at dp 0.01 went unstable)."""

import numpy as np
import pytest
from cell_sorted import sort_into_cells

from sph_core.kernels import wendland_alpha
from sph_core.particles import FLUID, M, N_FIELDS, P, RHO, VZ, WALL, X, Z
from sph_core.state import Params, particles_view
from sph_core.wall_contact import face_shares
from sph_core.wcsph import fluid_pass

DP = 0.01
H = 2.0 * DP
RHO0 = 1000.0
C0 = 15.0
P_TENSION = -500.0


def _one_particle_over_a_bed(vz: float, p: float):
    """One fluid particle 0.6 dp above the face of a flat bed (4 rows, face at z = 0) with
    velocity (0, vz) and pressure p, walls at p = 0; returns (az, pw) of the particle."""
    xs = [(i + 0.5) * DP for i in range(-8, 8) for _ in range(4)]
    zs = [-(k + 0.5) * DP for _ in range(-8, 8) for k in range(4)]
    xs.append(0.0)
    zs.append(0.6 * DP)
    n = len(xs)
    kind = np.full(n, WALL, dtype=np.int8)
    kind[-1] = FLUID
    f = np.zeros((N_FIELDS, n))
    f[X] = xs
    f[Z] = zs
    f[RHO] = RHO0
    f[M] = RHO0 * DP * DP
    f[P, -1] = p
    f[VZ, -1] = vz
    f, kind, cell, cells, order = sort_into_cells(f, kind, H, (-10 * DP, 10 * DP, -6 * DP, 4 * DP))
    aw = wendland_alpha(H)
    ga, g0, gb = face_shares(H, DP, 4, aw)
    prm = Params(h=H, alpha_w=aw, alpha_f=5.0 * aw / (H * H), rho0=RHO0, c0=C0,
                 b=C0 * C0 * RHO0 / 7.0, gamma=7.0, gx=0.0, gz=-9.81, alpha=0.0, nu=0.0,
                 delta=0.0, cfl=0.25, rho_lo=0.7, rho_hi=1.3, noslip=False, fx0=-1.0, fx1=1.0,
                 fz0=-1.0, fz1=1.0, alpha_wall=0.0, shift_a=0.0, shift_fs_div=1.8,
                 wall_ga=ga, wall_g0=g0, wall_gb=gb)
    ps = particles_view(f, kind, np.arange(n, dtype=np.int64), cell)
    fluid_pass(ps, n, cells, prm, None)
    i = int(np.flatnonzero(order == n - 1)[0])
    return ps.az[i], ps.pw[i]


def test_a_particle_in_tension_approaching_a_wall_feels_no_pull():
    az, pw = _one_particle_over_a_bed(vz=-0.05, p=P_TENSION)
    assert az == pytest.approx(-9.81, abs=1e-9)   # walls at p = 0, p_i clamped: no pair force
    assert pw == 0.0


def test_a_particle_in_tension_moving_away_keeps_the_walls_pull():
    az, pw = _one_particle_over_a_bed(vz=0.05, p=P_TENSION)
    assert az < -9.81 - 1.0                       # pulled towards the bed
    assert pw == P_TENSION
    # the pull is the pair force m_s p_i / (rho_i rho_s) F r summed over the bed: it scales with p
    az2, _ = _one_particle_over_a_bed(vz=0.05, p=2 * P_TENSION)
    assert az2 + 9.81 == pytest.approx(2 * (az + 9.81), rel=1e-12)


def test_a_particle_in_compression_is_pushed_off_whichever_way_it_moves():
    up, pw_up = _one_particle_over_a_bed(vz=0.05, p=500.0)
    down, pw_down = _one_particle_over_a_bed(vz=-0.05, p=500.0)
    assert up == pytest.approx(down, rel=1e-12) and up > -9.81 + 1.0
    assert pw_up == pw_down == 500.0
