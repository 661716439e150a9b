"""Riemann SPH (sph_core.riemann): the acoustic Riemann solver of two equal states dissipates
nothing, the limiters keep a consistent slope, the kernel-corrected gradients reproduce a linear
field exactly on a disordered particle set, and so MUSCL removes the pressure jump of a linear
(hydrostatic) pressure field, which drives density diffusion without reconstruction."""

import numpy as np
import pytest
from cell_sorted import sort_into_cells

from sph_core.kernels import wendland_alpha
from sph_core.particles import FLUID, M, N_FIELDS, P, RHO, VX, VZ, WALL, X, Z
from sph_core.riemann import NO_RECONSTRUCTION, VANLEER, interface_state, limited, riemann_gradients
from sph_core.state import Params, particles_view
from sph_core.wcsph import fluid_pass

RHO0, C0 = 1000.0, 20.0


def test_equal_states_give_their_own_state_without_dissipation():
    u, p = 0.37, 1234.5
    ustar, pstar = interface_state(u, u, p, p, RHO0 * C0, 1.0)
    assert ustar == pytest.approx(u, rel=1e-14)
    assert pstar == pytest.approx(p, rel=1e-14)


def test_dissipation_acts_on_jumps():
    z = RHO0 * C0
    # a pressure jump drives a velocity towards the low side: U* > mean for p_L > p_R
    ustar, _ = interface_state(0.0, 0.0, 2000.0, 1000.0, z, 1.0)
    assert ustar == pytest.approx(1000.0 / (2 * z))
    # compression (U_L > U_R): P* above the mean by Z du / 2; expansion pulls as much
    du = 0.2
    _, p_comp = interface_state(du, 0.0, 0.0, 0.0, z, 1.0)
    _, p_exp = interface_state(0.0, du, 0.0, 0.0, z, 1.0)
    assert p_comp == pytest.approx(0.5 * z * du)
    assert p_exp == pytest.approx(-0.5 * z * du)
    # against a wall the dissipation is scaled by the wall factor
    _, p_wall = interface_state(du, 0.0, 0.0, 0.0, z, 0.25)
    assert p_wall == pytest.approx(0.25 * 0.5 * z * du)


def test_van_leer_limiter():
    assert limited(0.3, 0.3) == pytest.approx(0.3)      # consistent slope kept
    assert limited(-0.3, 0.2) == 0.0                    # extremum: first order
    assert 0.0 < limited(0.1, 0.3) <= 0.3
    assert limited(0.1, 0.3) == pytest.approx(2 * 0.1 * 0.3 / 0.4)   # harmonic mean below |d|
    assert limited(3.0, 0.3) == pytest.approx(0.3)     # never past the mid-point


def _disordered_block(linear_v: bool, limiter: int, seed: int = 3):
    """A jittered 14 x 10 fluid block over 4 wall rows, p (and v) linear in x, z; returns the
    fluid's drho after the gradient pass and fluid_pass, the gradients and the exact ones."""
    dp, h = 0.02, 0.028
    rng = np.random.default_rng(seed)
    xs, zs, kinds = [], [], []
    for j in range(-4, 10):
        for i in range(14):
            xs.append((i + 0.5) * dp)
            zs.append((j + 0.5) * dp)
            kinds.append(WALL if j < 0 else FLUID)
    n = len(xs)
    kind = np.array(kinds, dtype=np.int8)
    f = np.zeros((N_FIELDS, n))
    f[X] = np.array(xs) + np.where(kind == FLUID, rng.uniform(-0.15, 0.15, n) * dp, 0.0)
    f[Z] = np.array(zs) + np.where(kind == FLUID, rng.uniform(-0.15, 0.15, n) * dp, 0.0)
    f[RHO] = RHO0
    f[M] = RHO0 * dp * dp
    grad_p = np.array([150.0, -9810.0])
    f[P] = 2000.0 + grad_p[0] * f[X] + grad_p[1] * f[Z]
    grad_u = np.array([[0.3, -0.2], [0.1, -0.3]]) if linear_v else np.zeros((2, 2))
    f[VX] = np.where(kind == FLUID, grad_u[0, 0] * f[X] + grad_u[0, 1] * f[Z], 0.0)
    f[VZ] = np.where(kind == FLUID, grad_u[1, 0] * f[X] + grad_u[1, 1] * f[Z], 0.0)
    f, kind, cell, cells, _ = sort_into_cells(f, kind, h, (-3 * h, 14 * dp + 3 * h,
                                                           -6 * dp - 3 * h, 10 * dp + 3 * h))
    aw = wendland_alpha(h)
    prm = Params(h=h, alpha_w=aw, alpha_f=5.0 * aw / (h * h), rho0=RHO0, c0=C0,
                 b=C0 * C0 * RHO0 / 7.0, gamma=7.0, gx=0.0, gz=-9.81, alpha=0.01, nu=0.0,
                 delta=0.1, cfl=0.25, rho_lo=0.7, rho_hi=1.3, noslip=True, fx0=-1.0, fx1=1.0,
                 fz0=-1.0, fz1=1.0, alpha_wall=1.0, shift_a=0.0, shift_fs_div=1.8,
                 riemann=True, limiter=limiter)
    ps = particles_view(f, kind, np.arange(n, dtype=np.int64), cell)
    if limiter != NO_RECONSTRUCTION:
        riemann_gradients(ps, n, cells, prm)
    fluid_pass(ps, n, cells, prm, True)
    fl = kind == FLUID
    return ps, fl, grad_p, grad_u


def test_gradients_reproduce_a_linear_field_exactly():
    ps, fl, grad_p, grad_u = _disordered_block(linear_v=True, limiter=VANLEER)
    np.testing.assert_allclose(ps.gpx[fl], grad_p[0], rtol=1e-9, atol=1e-9 * abs(grad_p[1]))
    np.testing.assert_allclose(ps.gpz[fl], grad_p[1], rtol=1e-9)
    for row, exact in ((ps.gux, grad_u[0, 0]), (ps.guz, grad_u[0, 1]), (ps.gwx, grad_u[1, 0]),
                       (ps.gwz, grad_u[1, 1])):
        np.testing.assert_allclose(row[fl], exact, rtol=1e-9, atol=1e-12)


def test_muscl_removes_the_hydrostatic_pressure_jump():
    """Fluid at rest in a linear pressure field: MUSCL's left and right states agree at every
    pair mid-point (wall pairs included), so no density rate; without reconstruction the
    truncated support at the surface and the disorder give one."""
    ps, fl, *_ = _disordered_block(linear_v=False, limiter=VANLEER)
    muscl = np.abs(ps.drho[fl]).max()
    ps0, fl0, *_ = _disordered_block(linear_v=False, limiter=NO_RECONSTRUCTION)
    none = np.abs(ps0.drho[fl0]).max()
    assert none > 1.0        # kg/m^3/s: the jump's diffusion is real without reconstruction
    assert muscl < 1e-9 * none


def test_scene_scheme_selects_the_riemann_params():
    from sph_core.scene import Scheme, SceneError, make_scene
    from sph_core.steppers import scheme_params

    assert scheme_params(Scheme()) == {"riemann": False, "limiter": NO_RECONSTRUCTION}
    assert scheme_params(Scheme(kind="riemann")) == {"riemann": True, "limiter": VANLEER}
    assert scheme_params(Scheme(kind="riemann", reconstruction="none")) == {
        "riemann": True, "limiter": NO_RECONSTRUCTION}
    base = {"dp": 0.05, "t_end": 1.0, "tank": {"x0": 0, "x1": 1, "z0": 0, "z1": 1},
            "water_blocks": [{"x0": 0, "x1": 0.5, "z0": 0, "z1": 0.5}]}
    # the retired options: their surviving value is accepted, any other names its decision page
    assert make_scene({**base, "scheme": {"kind": "riemann", "limiter": "vanleer"}}).scheme.kind == "riemann"
    with pytest.raises(SceneError, match=r"scheme\.limiter: 'minmod' was measured and retired "
                                         r"\(see docs/decisions/limiter\.md\)"):
        make_scene({**base, "scheme": {"kind": "riemann", "limiter": "minmod"}})
    with pytest.raises(SceneError, match="docs/decisions/low_dissipation.md"):
        make_scene({**base, "scheme": {"kind": "riemann", "low_dissipation": True}})
    with pytest.raises(SceneError, match=r"constants\.kernel_correction: .*docs/decisions/kernel_correction\.md"):
        make_scene({**base, "constants": {"kernel_correction": "all"}})
