"""The shared renormalisation walk (sph_core.renormalisation.moments) against a brute-force numpy
reference on a jittered block with a free surface, walls (one at suction pressure), an inlet
buffer column and a splash particle; its lambda and M^-1 against numpy's linear algebra."""

import numpy as np
import pytest
from cell_sorted import sort_into_cells
from numba import njit

from sph_core.kernels import f_of_q, w_of_q, wendland_alpha
from sph_core.particles import FLUID, INLET, M, N_FIELDS, OUTLET, P, RHO, VX, VZ, WALL, X, Z
from sph_core.renormalisation import DPLUS_R, moments, smallest_eigenvalue, solve
from sph_core.state import Params, particles_view

DP, H, RHO0 = 0.02, 0.04, 1000.0
NX, NZ = 14, 8
SUMS = ("mxx", "mxz", "mzz", "gx", "gz", "acx", "acz", "shepard", "phix", "phiz", "ux", "uz",
        "wx", "wz", "mfxx", "mfxz", "mfzz")


@njit
def _all_moments(ps, n, cells, prm, suction_walls, out):
    """moments of every fluid and buffer particle (phi = p, u, w = v) into out[:17], with
    lambda and M^-1 (e_x) in out[17:20]."""
    for i in range(n):
        k = ps.kind[i]
        if k >= FLUID and k <= OUTLET and k != WALL:
            s = moments(i, ps, cells, prm, ps.p, ps.vx, ps.vz, suction_walls)
            out[0, i] = s.mxx
            out[1, i] = s.mxz
            out[2, i] = s.mzz
            out[3, i] = s.gx
            out[4, i] = s.gz
            out[5, i] = s.acx
            out[6, i] = s.acz
            out[7, i] = s.shepard
            out[8, i] = s.phix
            out[9, i] = s.phiz
            out[10, i] = s.ux
            out[11, i] = s.uz
            out[12, i] = s.wx
            out[13, i] = s.wz
            out[14, i] = s.mfxx
            out[15, i] = s.mfxz
            out[16, i] = s.mfzz
            out[17, i] = smallest_eigenvalue(s.mxx, s.mxz, s.mzz)
            det = s.mxx * s.mzz - s.mxz * s.mxz
            if det > 0.0:
                out[18, i], out[19, i] = solve(s.mxx, s.mxz, s.mzz, det, 1.0, 0.0)


def _particles(seed: int = 11):
    """Jittered fluid block (free top) over 3 wall rows, an inlet buffer column on its left, a
    splash particle 1.6 h above the surface (a few neighbours below it); rho, p, v random-ish;
    one wall particle at p < 0."""
    rng = np.random.default_rng(seed)
    xs, zs, kinds = [], [], []
    for j in range(-3, NZ):
        for i in range(-2, NX):
            xs.append((i + 0.5) * DP)
            zs.append((j + 0.5) * DP)
            kinds.append(WALL if j < 0 else (INLET if i < 0 else FLUID))
    xs.append(7.3 * DP)
    zs.append(NZ * DP + 1.6 * H)
    kinds.append(FLUID)
    n = len(xs)
    kind = np.array(kinds, dtype=np.int8)
    f = np.zeros((N_FIELDS, n))
    moving = kind != WALL
    f[X] = np.array(xs) + np.where(moving, rng.uniform(-0.2, 0.2, n) * DP, 0.0)
    f[Z] = np.array(zs) + np.where(moving, rng.uniform(-0.2, 0.2, n) * DP, 0.0)
    f[RHO] = RHO0 * (1.0 + rng.uniform(-0.02, 0.02, n))
    f[M] = RHO0 * DP * DP
    f[P] = 9810.0 * (NZ * DP - f[Z]) + rng.uniform(-50.0, 50.0, n)
    f[VX] = rng.uniform(-0.3, 0.3, n)
    f[VZ] = rng.uniform(-0.3, 0.3, n)
    suction = np.nonzero((kind == WALL) & np.isclose(f[Z], -0.5 * DP))[0][NX // 2]
    f[P, suction] = -200.0
    f, kind, cell, cells, _ = sort_into_cells(f, kind, H, (-4 * DP - 3 * H, NX * DP + 3 * H,
                                                           -6 * DP - 3 * H, NZ * DP + 5 * H))
    aw = wendland_alpha(H)
    prm = Params(h=H, alpha_w=aw, alpha_f=5.0 * aw / (H * H), rho0=RHO0, c0=20.0, b=1.0,
                 gamma=7.0, gx=0.0, gz=-9.81, alpha=0.0, nu=0.0, delta=0.0, cfl=0.25,
                 rho_lo=0.7, rho_hi=1.3, noslip=True, fx0=-1.0, fx1=1.0, fz0=-1.0, fz1=1.0,
                 alpha_wall=0.0, shift_a=4.0, shift_fs_div=1.5, shift_dplus=True,
                 shift_inv_wdp=1.0 / w_of_q(DP / H, aw))
    ps = particles_view(f, kind, np.arange(n, dtype=np.int64), cell)
    return ps, n, cells, prm


def _reference(ps, n, prm, suction_walls: bool) -> dict:
    """The module docstring's sums, brute force over all pairs."""
    x, z, kind = ps.x[:n], ps.z[:n], ps.kind[:n]
    rx = x[None, :] - x[:, None]            # r_ji = r_j - r_i, [i, j]
    rz = z[None, :] - z[:, None]
    q = np.sqrt(rx * rx + rz * rz) / prm.h
    fq = np.vectorize(lambda v: f_of_q(v, prm.alpha_f))(q)
    wq = np.vectorize(lambda v: w_of_q(v, prm.alpha_w))(q)
    nb = (kind >= FLUID) & (kind <= OUTLET)
    if not suction_walls:
        nb &= ~((kind == WALL) & (ps.p[:n] < 0.0))
    pair = nb[None, :] & ~np.eye(n, dtype=bool) & (q < 2.0)
    vol = ps.m[:n] / ps.rho[:n]
    fv = np.where(pair, fq * vol[None, :], 0.0)
    gx, gz = fv * rx, fv * rz
    wr = wq * prm.shift_inv_wdp
    wgt = 1.0 + DPLUS_R * wr ** 4
    flow = pair & (kind != WALL)[None, :]

    def diff(row, mask):
        d = np.where(mask, row[None, :] - row[:, None], 0.0)
        return (d * gx).sum(1), (d * gz).sum(1)

    out = {"mxx": (gx * rx).sum(1), "mxz": (gx * rz).sum(1), "mzz": (gz * rz).sum(1),
           "gx": gx.sum(1), "gz": gz.sum(1), "acx": (wgt * gx).sum(1), "acz": (wgt * gz).sum(1),
           "shepard": np.where(pair, wq * vol[None, :], 0.0).sum(1)}
    out["phix"], out["phiz"] = diff(ps.p[:n], pair)
    out["ux"], out["uz"] = diff(ps.vx[:n], flow)
    out["wx"], out["wz"] = diff(ps.vz[:n], flow)
    fg = np.where(flow, fv, 0.0)
    out["mfxx"], out["mfxz"], out["mfzz"] = ((fg * rx * rx).sum(1), (fg * rx * rz).sum(1),
                                             (fg * rz * rz).sum(1))
    return out


@pytest.mark.parametrize("suction_walls", [True, False])
def test_moments_match_a_brute_force_reference(suction_walls):
    ps, n, cells, prm = _particles()
    out = np.zeros((20, n))
    _all_moments(ps, n, cells, prm, suction_walls, out)
    ref = _reference(ps, n, prm, suction_walls)
    kind = ps.kind[:n]
    sel = (kind == FLUID) | (kind == INLET)
    for k, name in enumerate(SUMS):
        scale = np.abs(ref[name][sel]).max()
        assert scale > 0.0, name
        np.testing.assert_allclose(out[k, sel], ref[name][sel], rtol=0, atol=1e-12 * scale,
                                   err_msg=name)
    # the particle set has what the callers' branches need: a free surface (lambda of a top-row
    # particle in Marrone's candidate band), a full support (lambda ~ 1), the splash (isolated)
    lam_ref = np.array([np.linalg.eigvalsh([[a, b], [b, c]])[0] for a, b, c in
                        zip(ref["mxx"], ref["mxz"], ref["mzz"])])
    np.testing.assert_allclose(out[17, sel], lam_ref[sel], rtol=0, atol=1e-12)
    fluid = kind == FLUID
    z, x = ps.z[:n], ps.x[:n]
    inner = (x > 3 * DP) & (x < (NX - 3) * DP)
    top = fluid & inner & (z > (NZ - 1) * DP) & (z < NZ * DP + 0.5 * DP)
    deep = fluid & inner & (z > 2 * DP) & (z < (NZ - 3) * DP)
    splash = fluid & (z > NZ * DP + H)
    assert top.any() and deep.any() and splash.sum() == 1
    assert np.all((lam_ref[top] > 0.2) & (lam_ref[top] <= 0.75))
    assert np.all(lam_ref[deep] > 0.75)
    assert 0.0 < lam_ref[splash][0] <= 0.2 and ref["mzz"][splash][0] > 0.0   # isolated
    # M^-1 e_x against numpy's solve where M is well conditioned
    for i in np.nonzero(sel & (lam_ref > 0.2))[0]:
        mi = np.array([[ref["mxx"][i], ref["mxz"][i]], [ref["mxz"][i], ref["mzz"][i]]])
        np.testing.assert_allclose(out[18:20, i], np.linalg.solve(mi, [1.0, 0.0]), rtol=1e-10)
    if not suction_walls:   # the filter took the suction wall out of its neighbours' sums
        assert not np.allclose(ref["mzz"], _reference(ps, n, prm, True)["mzz"])
