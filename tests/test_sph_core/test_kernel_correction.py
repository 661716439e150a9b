"""Kernel gradient correction (sph_core.kernel_correction): with L_i the gradient of a linear field
is exact to round-off in the bulk and in the top rows cut by the free surface (where the plain
SPH gradient is not); the "surface" variant leaves the bulk alone; the corrected pressure term
of fluid_pass keeps the fluid's total momentum (pair terms antisymmetric); still water with the
option on does not stay still yet (strict xfails: the option is experimental)."""

import math

import numpy as np
import pytest
from cell_sorted import sort_into_cells

from sph_core.kernel_correction import (KGC_ALL, KGC_OFF, KGC_SURFACE, KGC_WEIGHTED,
                                        correction_matrices)
from sph_core.kernels import f_of_q, wendland_alpha
from sph_core.particles import FLUID, M, N_FIELDS, P, RHO, WALL, X, Z
from sph_core.state import Params, particles_view
from sph_core.wcsph import fluid_pass

RHO0, C0 = 1000.0, 20.0
DP, H = 0.02, 0.04   # h/dp 2, the default


def _block(kgc: int, walls: bool = True, jitter: float = 0.15, seed: int = 3, nx: int = 16,
           nz: int = 10):
    """A jittered nx x nz fluid block (free top surface) over 4 wall rows (or none); sorted by
    cell, with the correction matrices computed. Returns (ps, n, cells, prm)."""
    rng = np.random.default_rng(seed)
    xs, zs, kinds = [], [], []
    for j in range(-4 if walls else 0, nz):
        for i in range(nx):
            xs.append((i + 0.5) * DP)
            zs.append((j + 0.5) * DP)
            kinds.append(WALL if j < 0 else FLUID)
    n = len(xs)
    kind = np.array(kinds, dtype=np.int8)
    f = np.zeros((N_FIELDS, n))
    f[X] = np.array(xs) + np.where(kind == FLUID, rng.uniform(-jitter, jitter, n) * DP, 0.0)
    f[Z] = np.array(zs) + np.where(kind == FLUID, rng.uniform(-jitter, jitter, n) * DP, 0.0)
    f[RHO] = RHO0 * (1.0 + rng.uniform(-0.01, 0.01, n))
    f[M] = RHO0 * DP * DP
    f, kind, cell, cells, _ = sort_into_cells(f, kind, H, (-3 * H, nx * DP + 3 * H,
                                                           -6 * DP - 3 * H, nz * DP + 3 * H))
    aw = wendland_alpha(H)
    prm = Params(h=H, alpha_w=aw, alpha_f=5.0 * aw / (H * H), rho0=RHO0, c0=C0,
                 b=C0 * C0 * RHO0 / 7.0, gamma=7.0, gx=0.0, gz=-9.81, alpha=0.0, nu=0.0,
                 delta=0.0, cfl=0.25, rho_lo=0.7, rho_hi=1.3, noslip=True, fx0=-1.0, fx1=1.0,
                 fz0=-1.0, fz1=1.0, alpha_wall=0.0, shift_a=0.0, shift_fs_div=1.8, kgc=kgc)
    ps = particles_view(f, kind, np.arange(n, dtype=np.int64), cell)
    correction_matrices(ps, n, cells, prm)
    return ps, n, cells, prm


def _gradient(ps, n, prm, phi, corrected: bool) -> np.ndarray:
    """sum_j V_j (phi_j - phi_i) [L_i] grad_i W_ij of every particle (brute force), [n, 2]."""
    x, z = ps.x[:n], ps.z[:n]
    rx = x[None, :] - x[:, None]            # r_j - r_i
    rz = z[None, :] - z[:, None]
    q = np.sqrt(rx * rx + rz * rz) / prm.h
    fq = np.array([[f_of_q(v, prm.alpha_f) for v in row] for row in q])
    np.fill_diagonal(fq, 0.0)
    keep = (ps.kind[:n] == FLUID) | (ps.kind[:n] == WALL)
    w = fq * (ps.m[:n] / ps.rho[:n] * keep)[None, :] * (phi[None, :] - phi[:, None])
    gx = (w * rx).sum(axis=1)
    gz = (w * rz).sum(axis=1)
    if not corrected:
        return np.stack([gx, gz], axis=1)
    return np.stack([ps.lxx[:n] * gx + ps.lxz[:n] * gz, ps.lxz[:n] * gx + ps.lzz[:n] * gz], axis=1)


def test_corrected_gradient_of_a_linear_field_is_exact_in_the_bulk_and_at_the_surface():
    ps, n, _, prm = _block(KGC_ALL)
    grad = np.array([150.0, -9810.0])
    phi = 2000.0 + grad[0] * ps.x[:n] + grad[1] * ps.z[:n]
    fl = ps.kind[:n] == FLUID
    top = fl & (ps.z[:n] > 8.75 * DP)            # the top row: kernel cut by the surface
    bulk = fl & (ps.z[:n] > 3 * DP) & (ps.z[:n] < 6 * DP) & (ps.x[:n] > 4 * DP) & (ps.x[:n] < 12 * DP)
    g = _gradient(ps, n, prm, phi, corrected=True)
    for sel in (bulk, top):
        np.testing.assert_allclose(g[sel, 0], grad[0], atol=1e-9 * abs(grad[1]))
        np.testing.assert_allclose(g[sel, 1], grad[1], rtol=1e-9)
    # the plain SPH gradient misses it: by the disorder in the bulk, by ~half at the surface
    g0 = _gradient(ps, n, prm, phi, corrected=False)
    assert np.abs(g0[top, 1] / grad[1] - 1.0).min() > 0.2
    assert np.abs(g0[bulk, 1] / grad[1] - 1.0).max() > 1e-3


def test_surface_variant_corrects_the_top_rows_only():
    ps, n, _, _ = _block(KGC_SURFACE, jitter=0.0)
    fl = ps.kind[:n] == FLUID
    dev = np.abs(ps.lxx[:n] - 1.0) + np.abs(ps.lxz[:n]) + np.abs(ps.lzz[:n] - 1.0)
    top = fl & (ps.z[:n] > 8.75 * DP) & (ps.x[:n] > 4 * DP) & (ps.x[:n] < 12 * DP)
    deep = fl & (ps.z[:n] < 5 * DP) & (ps.x[:n] > 4 * DP) & (ps.x[:n] < 12 * DP)
    assert dev[top].min() > 0.2                # L_zz ~ 1/0.6 in the top row
    assert dev[deep].max() == 0.0              # the bulk keeps the plain gradient
    assert np.all(ps.lxx[:n][ps.kind[:n] == WALL] == 1.0)
    ps_all, n, _, _ = _block(KGC_ALL, jitter=0.0)
    np.testing.assert_allclose(ps.lzz[:n][top], ps_all.lzz[:n][top], rtol=1e-12)


def test_weighted_variant_leaves_the_truncation_and_corrects_the_disorder():
    """gamma L: in the top row of a regular lattice close to the identity (the cut is left to the
    plain SPH surface: |gamma L_zz - 1| well below |L_zz - 1|); in the jittered bulk gamma L = L
    within the Shepard sum's ~1 % (the disorder is corrected)."""
    ps_w, n, _, _ = _block(KGC_WEIGHTED, jitter=0.0)
    ps_a, _, _, _ = _block(KGC_ALL, jitter=0.0)
    fl = ps_w.kind[:n] == FLUID
    top = fl & (ps_w.z[:n] > 8.75 * DP) & (ps_w.x[:n] > 4 * DP) & (ps_w.x[:n] < 12 * DP)
    assert np.abs(ps_w.lzz[:n][top] - 1.0).max() < 0.5 * np.abs(ps_a.lzz[:n][top] - 1.0).min()
    ps_w, n, _, _ = _block(KGC_WEIGHTED)
    ps_a, _, _, _ = _block(KGC_ALL)
    fl = ps_w.kind[:n] == FLUID
    bulk = fl & (ps_w.z[:n] > 3 * DP) & (ps_w.z[:n] < 6 * DP) & (ps_w.x[:n] > 4 * DP) & (ps_w.x[:n] < 12 * DP)
    np.testing.assert_allclose(ps_w.lxz[:n][bulk], ps_a.lxz[:n][bulk], rtol=0.03, atol=1e-3)
    np.testing.assert_allclose(ps_w.lzz[:n][bulk], ps_a.lzz[:n][bulk], rtol=0.03)


@pytest.mark.parametrize("kgc", [KGC_ALL, KGC_SURFACE, KGC_WEIGHTED])
def test_corrected_pressure_term_keeps_the_total_momentum(kgc):
    """No walls, no gravity: the fluid's pair forces must cancel (sum m_i a_i = 0) with the
    correction as without it, while the accelerations themselves change."""
    rng = np.random.default_rng(5)
    out = {}
    for k in (KGC_OFF, kgc):
        ps, n, cells, prm = _block(k, walls=False)
        ps.p[:n] = 1000.0 + 500.0 * rng.uniform(size=n) if k == KGC_OFF else p0
        p0 = ps.p[:n].copy()
        fluid_pass(ps, n, cells, prm._replace(gz=0.0))
        out[k] = (ps.ax[:n] * ps.m[:n], ps.az[:n] * ps.m[:n], ps.ids[:n].copy())
    fx, fz, ids = out[kgc]
    scale = np.abs(fz).max()
    assert abs(fx.sum()) < 1e-12 * scale * n and abs(fz.sum()) < 1e-12 * scale * n
    fx0, fz0, ids0 = out[KGC_OFF]
    assert np.array_equal(ids, ids0)
    assert np.abs(fz - fz0).max() > 0.05 * scale


def test_scene_option_reaches_params_and_is_rejected_where_it_does_not_apply():
    from sph_core.scene import SceneError, make_scene
    from sph_core.simulation import Simulation

    base = {"dp": 0.05, "t_end": 0.1, "tank": {"x0": 0, "x1": 0.5, "z0": 0, "z1": 0.4},
            "water_blocks": [{"x0": 0, "x1": 0.5, "z0": 0, "z1": 0.2}]}
    sim = Simulation(make_scene({**base, "constants": {"kernel_correction": "surface"}}))
    assert sim.prm.kgc == KGC_SURFACE
    assert Simulation(make_scene(base)).prm.kgc == KGC_OFF
    with pytest.raises(SceneError, match="kernel_correction"):
        make_scene({**base, "constants": {"kernel_correction": "all"}, "scheme": {"kind": "riemann"}})


# No variant holds still water yet (docs/wave_decay_study.md "Kernel gradient correction"):
# all / surface lose a fluid particle through the bed within ~0.5-0.7 s, weighted reaches
# 0.36 m/s of particle noise by 1.5 s. Known defects of the experimental option, kept as strict
# xfails so that a fix shows.
_LEAKS = pytest.mark.xfail(strict=True, reason="still water leaks through the bed (docs)")
_NOISE = pytest.mark.xfail(strict=True, reason="particle noise grows in still water (docs)")


@pytest.mark.parametrize("mode", [pytest.param("all", marks=_LEAKS),
                                  pytest.param("surface", marks=_LEAKS),
                                  pytest.param("weighted", marks=_NOISE)])
def test_still_water_with_kernel_correction_stays_still(mode):
    """A still tank (d 0.2 m, d/dp 10) with the correction on for 1.5 s: the water stays at rest
    (max speed, net momentum), keeps every particle and the surface keeps its level."""
    from sph_core.scene import make_scene
    from sph_core.simulation import Simulation

    d = 0.2
    scene = make_scene({
        "name": "still_kgc", "dp": DP, "t_end": 1.5, "still_water_level": d,
        "tank": {"x0": 0.0, "x1": 2 * d, "z0": 0.0, "z1": 1.6 * d},
        "water_blocks": [{"x0": 0.0, "x1": 2 * d, "z0": 0.0, "z1": d}],
        "constants": {"kernel_correction": mode}, "output": {"probe_every": 0.05},
        "probes": [{"kind": "elevation", "name": "g", "x": 0.7 * d}]})
    sim = Simulation(scene)
    st0 = sim.fluid_state()
    sim.advance_to(1.5)
    st = sim.fluid_state()
    assert st["m"].size == st0["m"].size, f"{len(sim.excluded)} particle(s) excluded"
    vmax = np.sqrt(st["vx"] ** 2 + st["vz"] ** 2).max()
    assert vmax < 0.01 * math.sqrt(9.81 * d), f"max speed {vmax:.3g} m/s"
    mom = np.hypot(np.sum(st["m"] * st["vx"]), np.sum(st["m"] * st["vz"]))
    assert mom < 1e-3 * np.sum(st["m"]) * math.sqrt(9.81 * d)
    com = np.sum(st["m"] * st["z"]) / np.sum(st["m"]) - np.sum(st0["m"] * st0["z"]) / np.sum(st0["m"])
    assert abs(com) < 0.05 * DP, f"centre of mass moved {com:.3g} m"
    late = [r["g_eta"] for r in sim.history if r["t"] >= 0.75]
    assert max(abs(e) for e in late) < 0.25 * DP, "surface gauge drifted"
