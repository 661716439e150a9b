"""Rigid-body test problems: scene builders and their analytic references.

    floating_box_scene(dp, ...)    a 2D box of density rho_b floating in a tank (heave, Archimedes)
    box_draft(sim)                 its draft below the level the closed tank's water has now
    hinged_flap_scene(dp, ...)     a bottom-hinged flap in still water (at rest), or in air with a
                                   torsion spring (period of the hinge dynamics)
    zero_gravity(sim)              the same run without gravity (momentum check)

References (per metre of span, still-water level ``swl``, bed z = 0):
    Archimedes draft  d = rho_b H / rho0 for a box of height H (its weight = the displaced water)
    spring flap (no water) T = 2 pi sqrt(I_p / (k - m g h_c)), I_p about the hinge, h_c the height
                      of its centre of mass above the hinge (gravity destabilises an upright flap)
    spring flap in water   the same with the added inertia a(omega) and radiation damping b(omega)
                      of a bottom-hinged flap in water of depth h on both sides (linear wavemaker
                      theory, Havelock 1929; Dean & Dalrymple 1991, ch. 6: eigenfunction
                      expansion, one propagating and the evanescent modes) and the buoyancy
                      moment rho g t h^2 / 2 of its submerged part
"""

from __future__ import annotations

import math

import numpy as np

from sph_core.scene import Scene, make_scene


def floating_box_scene(dp: float = 0.02, breadth: float = 0.4, height: float = 0.2,
                       density: float = 500.0, offset: float = 0.0, depth: float = 0.3,
                       tank_length: float = 1.6, damper: float = 0.0,
                       dofs: tuple[str, ...] = ("heave",), t_end: float = 1.0,
                       integrator: str = "kdk", probe_every: float = 0.01,
                       constants: dict | None = None) -> Scene:
    """A box (breadth x height) of density ``density`` in the middle of a tank of water ``depth``
    deep, its bottom ``offset`` [m] below the Archimedes equilibrium (negative: above);
    ``damper`` [N s/m] on heave (zero force at rest: the equilibrium is unchanged);
    ``constants``: further [constants] (e.g. h_over_dp, alpha_wall_factor)."""
    draft = density * height / 1000.0
    z0 = depth - draft - offset
    xc = 0.5 * tank_length
    return make_scene({
        "name": "floating_box", "dp": dp, "t_end": t_end, "still_water_level": depth,
        "tank": {"x0": 0.0, "x1": tank_length, "z0": 0.0, "z1": depth + 1.5 * height},
        "water_blocks": [{"x0": 0.0, "x1": tank_length, "z0": 0.0, "z1": depth}],
        "constants": {"integrator": integrator, **(constants or {})},
        "output": {"probe_every": probe_every},
        "bodies": [{"name": "box", "shape": "box", "x0": xc - 0.5 * breadth,
                    "x1": xc + 0.5 * breadth, "z0": z0, "z1": z0 + height, "density": density,
                    "motion": "free", "dofs": list(dofs), "damper": (0.0, damper, 0.0)}]})


def archimedes_draft(density: float, height: float, rho0: float = 1000.0) -> float:
    """Equilibrium draft [m] of a floating box: its weight equals the displaced water's."""
    return density * height / rho0


def box_draft(sim, name: str = "box", z_bottom=None):
    """Draft [m] of a floating box in a closed tank, below the still-water level the fluid has
    now: the fluid area (n_fluid dp^2, the lattice volume) plus the box's submerged part fill the
    tank's length L up to eta, so eta (L - B) = A_fluid - B z_bottom. (The box displaces water
    in the closed tank: the nominal still-water level is no longer the level.) ``z_bottom``:
    the box bottom(s) [m] to evaluate at (default: the current one)."""
    scene = sim.scene
    body = next(b for b in scene.bodies if b.name == name)
    k = sim.bodies.names.index(name)
    breadth, height = body.x1 - body.x0, body.z1 - body.z0
    if z_bottom is None:
        z_bottom = float(sim.bodies.state.q[k, 1]) - 0.5 * height
    length = scene.tank.x1 - scene.tank.x0
    eta = (sim.n_fluid * scene.dp ** 2 - breadth * z_bottom) / (length - breadth)
    return eta - z_bottom


def hinged_flap_scene(dp: float = 0.02, thickness: float = 0.04, height: float = 0.4,
                      density: float = 500.0, depth: float = 0.3, spring: float = 0.0,
                      omega0: float = 0.0, in_water: bool = True, t_end: float = 1.0,
                      integrator: str = "kdk", probe_every: float = 0.005) -> Scene:
    """A flap (thickness x height) hinged at the centre of its bottom edge, on the bed at x = 1 m
    of a 2 m tank. ``in_water`` False: the water is a block at the far left (x < 0.3 m), out of
    the flap's reach, so only gravity and the spring act. ``omega0`` [rad/s]: initial rate."""
    length = 2.0
    xc = 1.0
    water = ({"x0": 0.0, "x1": length, "z0": 0.0, "z1": depth} if in_water
             else {"x0": 0.0, "x1": 0.3, "z0": 0.0, "z1": depth})
    return make_scene({
        "name": "hinged_flap", "dp": dp, "t_end": t_end, "still_water_level": depth,
        "tank": {"x0": 0.0, "x1": length, "z0": 0.0, "z1": max(depth, height) + 0.2},
        "water_blocks": [water],
        "structures": [] if in_water else [{"x0": 0.3, "x1": 0.4, "z0": 0.0, "z1": depth + 0.1}],
        "constants": {"integrator": integrator},
        "output": {"probe_every": probe_every},
        "bodies": [{"name": "flap", "shape": "flap", "x0": xc - 0.5 * thickness,
                    "x1": xc + 0.5 * thickness, "z0": 0.0, "z1": height, "density": density,
                    "motion": "hinged", "spring": spring, "velocity": (0.0, 0.0, omega0)}]})


def spring_flap_period(thickness: float, height: float, density: float, spring: float,
                       g: float = 9.81) -> float:
    """Small-amplitude period [s] of an upright flap on a torsion spring, hinged at its bottom
    edge's centre, in air: I_p theta'' = -(k - m g h/2) theta, I_p = m (t^2 + 4 h^2) / 12."""
    m = density * thickness * height
    i_p = m * (thickness ** 2 + 4.0 * height ** 2) / 12.0
    k_eff = spring - m * g * 0.5 * height
    if k_eff <= 0:
        raise ValueError("spring: too weak, the upright flap is unstable")
    return 2.0 * math.pi * math.sqrt(i_p / k_eff)


def _flap_wavenumbers(omega: float, depth: float, g: float, modes: int) -> tuple[float, np.ndarray]:
    """k0 (omega^2 = g k0 tanh k0 h) and the evanescent k_n (omega^2 = -g k_n tan k_n h),
    n = 1..modes, each in ((n - 1/2) pi / h, n pi / h)."""
    from scipy.optimize import brentq

    nu = omega * omega / g
    k0 = brentq(lambda k: k * math.tanh(k * depth) - nu, 1e-12, nu + 1.0 / depth + 10.0)
    kn = np.array([brentq(lambda k: k * math.tan(k * depth) + nu,
                          ((n - 0.5) * math.pi + 1e-12) / depth, n * math.pi / depth - 1e-12)
                   for n in range(1, modes + 1)])
    return k0, kn


def flap_hydrodynamics(omega: float, depth: float, rho: float = 1000.0, g: float = 9.81,
                       modes: int = 400) -> tuple[float, float]:
    """Added inertia a [kg m^2/m] and radiation damping b [N m s/m] of a thin flap hinged on the
    bed, pitching at omega [rad/s] in water of depth h on both sides (no reflection): with z
    from the bed, C_m = int_0^h z f_m dz, N_m = int_0^h f_m^2 dz (f_0 = cosh k0 z, f_n =
    cos k_n z), a = 2 rho sum_n C_n^2 / (k_n N_n), b = 2 rho omega C_0^2 / (k0 N_0)."""
    h = depth
    k0, kn = _flap_wavenumbers(omega, h, g, modes)
    # C_0 e^{-k0 h} and N_0 e^{-2 k0 h} (no overflow at high frequency), e = e^{-k0 h}
    e = math.exp(-k0 * h)
    c0 = h * (1.0 - e * e) / (2.0 * k0) - (0.5 * (1.0 + e * e) - e) / k0 ** 2
    n0 = 0.5 * h * e * e + (1.0 - e ** 4) / (8.0 * k0)
    cn = h * np.sin(kn * h) / kn + (np.cos(kn * h) - 1.0) / kn ** 2
    nn = 0.5 * h + np.sin(2.0 * kn * h) / (4.0 * kn)
    return float(2.0 * rho * np.sum(cn ** 2 / (kn * nn))), 2.0 * rho * omega * c0 ** 2 / (k0 * n0)


def spring_flap_in_water(thickness: float, height: float, density: float, spring: float,
                         depth: float, rho: float = 1000.0, g: float = 9.81) -> dict[str, float]:
    """Small-amplitude damped period [s] and damping ratio of the spring flap of
    ``hinged_flap_scene`` in water ``depth`` deep on both sides (linear, frequency domain: the
    natural frequency solves (I_p + a(w)) w^2 = k_eff by fixed point; the period is that of the
    damped oscillator, 2 pi / (w sqrt(1 - zeta^2)), zeta = b / (2 sqrt(k_eff I_tot))).
    k_eff = k - m g h/2 + rho g t d^2/2 (gravity on the flap, buoyancy of its wet part)."""
    m = density * thickness * height
    i_p = m * (thickness ** 2 + 4.0 * height ** 2) / 12.0
    k_eff = spring - m * g * 0.5 * height + rho * g * thickness * depth ** 2 / 2.0
    if k_eff <= 0:
        raise ValueError("spring: too weak, the upright flap is unstable")
    w = math.sqrt(k_eff / i_p)
    for _ in range(100):
        a, b = flap_hydrodynamics(w, depth, rho, g)
        w_new = math.sqrt(k_eff / (i_p + a))
        if abs(w_new - w) < 1e-12 * w:
            break
        w = w_new
    zeta = b / (2.0 * math.sqrt(k_eff * (i_p + a)))
    return {"period": 2.0 * math.pi / (w * math.sqrt(1.0 - zeta ** 2)), "omega_n": w,
            "added_inertia": a, "damping": b, "zeta": zeta, "k_eff": k_eff, "inertia": i_p}


def flap_wave_response(thickness: float, height: float, density: float, spring: float,
                       depth: float, wave_height: float, period: float, rho: float = 1000.0,
                       g: float = 9.81) -> dict[str, float]:
    """Linear pitch amplitude [rad] of a bottom-hinged flap (as spring_flap_in_water) in regular
    waves of ``wave_height`` and ``period``, in a channel open on both sides: the excitation of
    the flap held fixed is exact in linear theory (a full-depth surface-piercing barrier
    reflects the wave totally: the weather side carries the standing wave 2A cosh k0 z /
    cosh k0 h, the lee side none), X = 2 rho g A C_0 / cosh(k0 h); the response
    Theta = X / (k_eff - (I_p + a) w^2 + i b w)."""
    w = 2.0 * math.pi / period
    m = density * thickness * height
    i_p = m * (thickness ** 2 + 4.0 * height ** 2) / 12.0
    k_eff = spring - m * g * 0.5 * height + rho * g * thickness * depth ** 2 / 2.0
    a, b = flap_hydrodynamics(w, depth, rho, g)
    k0, _ = _flap_wavenumbers(w, depth, g, 1)
    c0 = depth * math.sinh(k0 * depth) / k0 - (math.cosh(k0 * depth) - 1.0) / k0 ** 2
    x = 2.0 * rho * g * 0.5 * wave_height * c0 / math.cosh(k0 * depth)
    theta = x / complex(k_eff - (i_p + a) * w * w, b * w)
    return {"amplitude": abs(theta), "excitation": x, "added_inertia": a, "damping": b,
            "k_eff": k_eff, "inertia": i_p}


def zero_crossing_period(t: np.ndarray, y: np.ndarray) -> float:
    """Mean period [s] from the upward zero crossings of y - mean(y) (linear interpolation)."""
    y = np.asarray(y) - np.mean(y)
    k = np.nonzero((y[:-1] < 0) & (y[1:] >= 0))[0]
    tc = t[k] - y[k] * (t[k + 1] - t[k]) / (y[k + 1] - y[k])
    if tc.size < 2:
        raise ValueError("zero_crossing_period: fewer than two upward crossings")
    return float((tc[-1] - tc[0]) / (tc.size - 1))


def zero_gravity(sim) -> None:
    """Turn gravity off in a built WCSPH Simulation (the scene's g must be > 0): fluid at rho0
    (no hydrostatic compression left), rates re-evaluated. For conservation checks only."""
    from sph_core.particles import FLUID, P, RHO

    ps = sim.particles
    fl = ps.mask(FLUID)
    ps.field(RHO)[fl] = sim.scene.constants.rho0
    ps.field(P)[fl] = 0.0
    sim.set_gravity(0.0, 0.0)
