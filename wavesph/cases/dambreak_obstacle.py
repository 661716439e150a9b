"""Dam break on a tall structure in 2D (seed 004, test case 1), and the wall-pressure noise metric.

Seed 004 (Yeylaghi et al. 2016) runs the Yeh & Petroff experiment reported by Gómez-Gesteira &
Dalrymple (2004): a 1.6 m long tank, a water column 0.4 m long and 0.3 m high at its left end,
and a square column 0.12 m wide whose front face stands at x = 0.9 m. In this 2D vertical plane
the column spans the tank's width: the surge cannot pass around it, it runs up its face (the
structure is 0.75 m tall, as the tank) and falls back. The 1 cm wet bed of the experiment is
left out (one particle layer at dp = 0.01 m). The probe ``obstacle`` gives the horizontal force
per metre of width on the structure against time (the case's output); ``front_face`` the
pressure on its front face 1 cm above the bed.

``pressure_noise`` is the issue's pressure-noise figure: the standard deviation of the wall
pressure after a 4th-order Butterworth high-pass at ``cutoff`` [Hz] (zero phase), i.e. what is
left of the signal above the flow's own time scales; WCSPH's acoustic oscillations (period
~ 2 H / c0) land there.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
from scipy.signal import butter, sosfiltfilt

from sph_core.scene import Scene, make_scene
from sph_core.simulation import Simulation

OBSTACLE_TANK_LENGTH = 1.6
COLUMN = (0.4, 0.3)          # water column length, height [m]
STRUCTURE = (0.9, 1.02, 0.75)  # front face x, back face x, top z [m]


def obstacle_scene(dp: float = 0.01, t_end: float = 1.5, scheme: dict | None = None,
                   probe_every: float = 0.002, **constants: Any) -> Scene:
    """The seed 004 geometry in 2D; ``scheme`` is the scene's [scheme] table (default WCSPH)."""
    x0, x1, top = STRUCTURE
    constants.setdefault("alpha", 0.1)   # the dam-break value of wavesph.cases.dambreak (WCSPH only)
    return make_scene({
        "name": "dambreak_obstacle", "dp": dp, "t_end": t_end,
        "tank": {"x0": 0.0, "x1": OBSTACLE_TANK_LENGTH, "z0": 0.0, "z1": top},
        "water_blocks": [{"x0": 0.0, "x1": COLUMN[0], "z0": 0.0, "z1": COLUMN[1]}],
        "structures": [{"x0": x0, "x1": x1, "z0": 0.0, "z1": top}],
        "constants": constants,
        "scheme": scheme or {},
        "output": {"probe_every": probe_every},
        "probes": [{"kind": "force", "name": "obstacle", "x0": x0, "x1": x1, "z0": 0.0,
                    "z1": top},
                   {"kind": "pressure_line", "name": "front_face", "points": [[x0 - 0.5 * dp,
                                                                               0.01]]},
                   {"kind": "front", "name": "front"}],
    })


def pressure_noise(t: np.ndarray, p: np.ndarray, cutoff: float) -> float:
    """Std [Pa] of the wall pressure ``p`` (None/NaN: dry, taken as 0) after a zero-phase
    4th-order Butterworth high-pass at ``cutoff`` [Hz]; ``t`` must be uniformly sampled."""
    t = np.asarray(t, dtype=float)
    p = np.nan_to_num(np.asarray(p, dtype=float))
    dt = float(np.median(np.diff(t)))
    sos = butter(4, cutoff, btype="highpass", fs=1.0 / dt, output="sos")
    return float(np.std(sosfiltfilt(sos, p)))


def run_obstacle(dp: float = 0.01, t_end: float = 1.5, scheme: dict | None = None,
                 cutoff: float = 10.0, **constants: Any) -> dict[str, Any]:
    """Run the case (``constants`` override the scene's); returns the force trace and summary
    numbers (wall time under whatever load the machine has)."""
    sim = Simulation(obstacle_scene(dp, t_end, scheme, **constants))
    tic = time.perf_counter()
    sim.advance_to(t_end)
    wall = time.perf_counter() - tic
    h = sim.history
    t = np.array([r["t"] for r in h])
    fx = np.array([r["obstacle_fx"] for r in h], dtype=float)
    pf = np.array([np.nan if r["front_face_p0"] is None else r["front_face_p0"] for r in h])
    return {"scheme": sim.scene.scheme.kind, "dp": dp, "t": t, "fx": fx, "p_face": pf,
            "fx_max": float(np.nanmax(fx)), "t_fx_max": float(t[int(np.nanargmax(fx))]),
            "force_noise_n_per_m": pressure_noise(t, fx, cutoff),
            "face_pressure_noise_pa": pressure_noise(t, pf, cutoff),
            "wall_s": wall, "wall_s_per_sim_s": wall / t_end, "steps": sim.steps,
            "mean_dt": t_end / max(sim.steps, 1), "n_particles": sim.n_particles,
            "excluded": len(sim.excluded),
            **({k: v for k, v in sim.stepper.stats().items()} if sim.stepper else {})}

