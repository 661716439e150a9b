"""Wedge water entry (seed 004): the drop test of Zhao, Faltinsen & Aarsnes (1996).

    scene = wedge_scene(dp)                   # the section dropped at 6.15 m/s on still water
    p = wagner_pressure(x, c, V, dV)          # Wagner's outer pressure along a wedge [Pa]
    rows = wedge_pressures(sim, times)        # SPH pressure along the face and Wagner's, per time
    F = wagner_force(c, V, dV)                # Wagner's vertical force [N/m]

The experiment (Zhao, R., Faltinsen, O. M., Aarsnes, J. V., 1996, "Water entry of arbitrary
two-dimensional sections with and without flow separation", Proc. 21st Symposium on Naval
Hydrodynamics, Trondheim, pp. 408-423): a wedge section 0.5 m wide, 30 deg deadrise, 0.29 m
high (vertical sides above the knuckles), 241 kg per metre of span (1 m long model), dropped
vertically; 6.15 m/s at first contact; pressures along the face reported at t = 0.00435 s and
0.0158 s after contact. The measured distributions were not found in a form that can be copied
(the paper's figures only; no tabulation found by the searches of this session): the reference
here is therefore Wagner's (1932) theory, as written by Zhao & Faltinsen (1993, J. Fluid Mech.
246, 593-612, eq. 2.3 / Faltinsen 2005, "Hydrodynamics of high-speed marine vehicles", ch. 8):
with the penetration depth zeta(t) = int V dt and the wetted half-width

    c = pi zeta / (2 tan beta),   dc/dt = pi V / (2 tan beta),
    p(x) = rho V c dc/dt / sqrt(c^2 - x^2) + rho dV/dt sqrt(c^2 - x^2)
           - rho V^2 x^2 / (2 (c^2 - x^2))               (|x| < c, outer solution, no jet),

x horizontal from the keel, V the wedge's downward speed (taken from the SPH run itself, so the
two share the deceleration). Wagner's flat-plate linearisation over-predicts c and the pressure
for a 30 deg deadrise (it is exact as beta -> 0); it is singular at the spray root x -> c, so
the comparison uses x <= 0.8 c. At 0.0158 s Wagner's c exceeds the half-breadth (0.25 m): the
flow separates from the knuckles (the case "with flow separation"), where Wagner's outer
solution does not apply: only the SPH values are reported there.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from sph_core.scene import Scene, make_scene

BREADTH = 0.5          # m, at the knuckles
DEADRISE_DEG = 30.0
WEDGE_HEIGHT = 0.29    # m, keel to top
MASS = 241.0           # kg per metre of span
V0 = 6.15              # m/s downwards at first contact
TIMES = (0.00435, 0.0158)   # s after contact: the paper's pressure distributions
N_POINTS = 48          # pressure points along the right face, keel to knuckle (5 mm apart)
PRESSURE_WINDOW = 5e-4  # s: SPH pressures and force averaged over t +- this (acoustic noise)


def wedge_outline(xc: float, z_keel: float) -> list[tuple[float, float]]:
    """The section: keel at (xc, z_keel), knuckles at +-B/2, vertical sides to WEDGE_HEIGHT."""
    half = 0.5 * BREADTH
    zk = z_keel + half * math.tan(math.radians(DEADRISE_DEG))
    return [(xc, z_keel), (xc + half, zk), (xc + half, z_keel + WEDGE_HEIGHT),
            (xc - half, z_keel + WEDGE_HEIGHT), (xc - half, zk)]


def face_points(xc: float, z_keel: float, offset: float) -> list[tuple[float, float]]:
    """N_POINTS on the right face between keel and knuckle (excluding both ends), moved
    ``offset`` [m] along the outward normal into the water."""
    beta = math.radians(DEADRISE_DEG)
    half = 0.5 * BREADTH
    nx, nz = math.sin(beta), -math.cos(beta)     # outward normal of the right face
    xs = half * (np.arange(N_POINTS) + 0.5) / N_POINTS
    return [(xc + x + offset * nx, z_keel + x * math.tan(beta) + offset * nz) for x in xs]


def wedge_scene(dp: float = 0.01, depth: float = 0.6, length: float = 1.2,
                t_end: float = 0.02, c0_factor: float = 20.0, probe_every: float = 2.5e-4,
                constants: dict | None = None) -> Scene:
    """The section free in heave, keel touching the still surface (z = ``depth``) at t = 0 and
    falling at V0. c0 = ``c0_factor`` sqrt(2 g depth): 20 gives 69 m/s at depth 0.6 m (Mach
    0.09 at impact; the water-hammer pressure rho c0 V0 lasts one sound crossing of the
    wetted width). Pressure points on the right face, dp/2 into the water, follow the body."""
    xc = 0.5 * length
    return make_scene({
        "name": "wedge_entry", "dp": dp, "t_end": t_end, "still_water_level": depth,
        "tank": {"x0": 0.0, "x1": length, "z0": 0.0, "z1": depth + WEDGE_HEIGHT + 0.1},
        "water_blocks": [{"x0": 0.0, "x1": length, "z0": 0.0, "z1": depth}],
        "constants": {"c0_factor": c0_factor, **(constants or {})},
        "output": {"probe_every": probe_every},
        "probes": [{"kind": "pressure_line", "name": "face", "follow": "wedge",
                    "points": face_points(xc, depth, 0.5 * dp)}],
        "bodies": [{"name": "wedge", "shape": "polygon", "points": wedge_outline(xc, depth),
                    "mass": MASS, "motion": "free", "dofs": ["heave"],
                    "velocity": (0.0, -V0, 0.0)}]})


def wagner_pressure(x: np.ndarray, c: float, v: float, dv: float, rho: float = 1000.0
                    ) -> np.ndarray:
    """Wagner's outer pressure [Pa] at |x| < c (nan elsewhere); v the downward speed, dv its
    rate (downward positive), dc/dt = pi v / (2 tan beta)."""
    x = np.asarray(x, dtype=float)
    dc = math.pi * v / (2.0 * math.tan(math.radians(DEADRISE_DEG)))
    r2 = c * c - x * x
    with np.errstate(invalid="ignore", divide="ignore"):
        p = rho * v * c * dc / np.sqrt(r2) + rho * dv * np.sqrt(r2) - 0.5 * rho * v * v * x * x / r2
    return np.where(r2 > 0, p, np.nan)


def _finite(a: np.ndarray) -> list[float | None]:
    """A JSON-safe list: None for nan (dry point, or outside Wagner's wetted width)."""
    return [float(v) if np.isfinite(v) else None for v in a]


def wagner_force(c: float, v: float, dv: float, rho: float = 1000.0) -> float:
    """Wagner's vertical force [N/m] (the integral of wagner_pressure's first two terms over
    |x| < c): d/dt (rho pi c^2 V / 2) = rho pi (c dc/dt V + c^2 dV/dt / 2)."""
    dc = math.pi * v / (2.0 * math.tan(math.radians(DEADRISE_DEG)))
    return rho * math.pi * (c * dc * v + 0.5 * c * c * dv)


def wedge_pressures(sim, times=TIMES, x_max_over_c: float = 0.8,
                    window: float = PRESSURE_WINDOW, samples: int = 11) -> list[dict]:
    """Advance ``sim`` (a wedge_scene run) through each time and compare with Wagner: the SPH
    pressure at the face points (x from the keel, horizontal) and the fluid's vertical force,
    each averaged over ``samples`` instants in t +- ``window`` (the weakly compressible impact
    rings: acoustic waves of period ~ wetted width / c0 make the instantaneous values swing by
    a factor 2, the experiment's transducers average too), the wedge's speed, deceleration and
    penetration at t; Wagner's c and pressure at the same x; the RMS difference over x <=
    x_max_over_c * c relative to Wagner's largest pressure there; the ratio at the point nearest
    the keel; and the instantaneous force at t."""
    half = 0.5 * BREADTH
    xs = half * (np.arange(N_POINTS) + 0.5) / N_POINTS
    k = sim.bodies.names.index("wedge")
    bd = sim.bodies.state
    z0 = float(bd.q0[k, 1])
    out = []
    for tt in times:
        ps, fs = [], []
        for ts in tt + np.linspace(-window, window, samples):
            sim.advance_to(ts)
            vals = sim.probe_values()
            ps.append([np.nan if vals[f"face_p{i}"] is None else vals[f"face_p{i}"]
                       for i in range(N_POINTS)])
            fs.append(float(bd.load[k, 1]))
            if abs(ts - tt) < 1e-12:
                v, dv = -float(bd.qd[k, 1]), -float(bd.acc[k, 1])
                zeta = z0 - float(bd.q[k, 1])
                f_now = fs[-1]
        with warnings.catch_warnings():   # a point dry throughout: nan, said, not warned
            warnings.simplefilter("ignore", RuntimeWarning)
            p_sph = np.nanmean(np.array(ps, dtype=float), axis=0)
        c = math.pi * zeta / (2.0 * math.tan(math.radians(DEADRISE_DEG)))
        p_w = wagner_pressure(xs, c, v, dv)
        sel = (xs <= x_max_over_c * c) & np.isfinite(p_sph) & np.isfinite(p_w)
        rms = (float(np.sqrt(np.mean((p_sph[sel] - p_w[sel]) ** 2)) / np.max(p_w[sel]))
               if sel.any() else None)
        cot = 1.0 / math.tan(math.radians(DEADRISE_DEG))
        g = sim.scene.constants.g
        out.append({"t": tt, "window": window, "v": v, "dv": dv, "zeta": zeta, "c_wagner": c,
                    # impulse of the fluid on the wedge since contact, M (V0 - V) + M g t, and
                    # the added-mass momentum rho pi c^2 V / 2 of Wagner (c = pi zeta cot / 2,
                    # over-predicts c at 30 deg) and of von Karman (c = zeta cot, no pile-up:
                    # under-predicts): a bracket for the integral of the force
                    "impulse_sph": MASS * (V0 - v) + MASS * g * tt,
                    "impulse_wagner": 0.5 * 1000.0 * math.pi * c * c * v,
                    "impulse_von_karman": 0.5 * 1000.0 * math.pi * (zeta * cot) ** 2 * v,
                    "force_sph": float(np.mean(fs)), "force_sph_instant": f_now,
                    "force_wagner": wagner_force(c, v, dv),
                    "x": xs.tolist(), "p_sph": _finite(p_sph), "p_wagner": _finite(p_w),
                    "rms_rel": rms, "keel_ratio": (float(p_sph[0] / p_w[0])
                                                   if np.isfinite(p_sph[0] * p_w[0]) else None),
                    "points_compared": int(sel.sum()), "separated": c > half})
    return out
