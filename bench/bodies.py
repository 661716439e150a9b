"""Rigid bodies in the SPH zone: physics checks and the cost of a body.

Questions: does a floating box settle at its Archimedes draft; at what period does it heave and
how fast does that decay; does a hinged flap stay at rest in still water; does a spring flap
oscillate at its analytic period; is fluid + body momentum conserved; and how much does a body
slow the flume scene (goal: <= 10 % fewer particle-steps/s)?

Output: one JSON object per line, each with check, value, reference, rel_error, wall_s (and
flap_pitch runs the coupled demo flume with its flap: linear theory as the reference). The wedge
(Zhao et al. 1996 drop test) is compared with Wagner's theory, not the experiment (its data
were not found in a copyable form; docs/studies/BODIES.md). The body checks need h/dp 2 and no wall
artificial viscosity (docs/studies/BODIES.md, heave study):

    python bench/bodies.py [--dp 0.02] [--checks archimedes_draft heave_period ...] \
        [--constants '{"h_over_dp": 2.0, "alpha_wall_factor": 0.0}']

Wall times are single-run, this machine's load at the time (label them so in reports).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from wavesph.cases.rigid_bodies import (archimedes_draft, box_draft, floating_box_scene,  # noqa: E402
                                hinged_flap_scene, spring_flap_period, zero_crossing_period,
                                zero_gravity)
from sph_core.particles import FLUID, M, VX, VZ  # noqa: E402
from sph_core.scene import make_scene  # noqa: E402
from sph_core.simulation import Simulation  # noqa: E402

DENSITY, HEIGHT, BREADTH, DEPTH = 500.0, 0.2, 0.4, 0.3   # the floating box of the checks
CONSTANTS: dict = {}   # --constants: [constants] overrides for every check's scene


def _sim(scene) -> Simulation:
    """A Simulation of ``scene`` with the --constants overrides."""
    if CONSTANTS:
        d = scene.model_dump(mode="json")
        d["constants"].update(CONSTANTS)
        scene = make_scene(d)
    return Simulation(scene)


def _line(check: str, value, reference, wall: float, **extra) -> dict:
    rel = (abs(value - reference) / abs(reference)
           if value is not None and reference not in (None, 0) else None)
    return {"check": check, "value": value, "reference": reference, "rel_error": rel,
            "wall_s": round(wall, 2), **extra}


def _series(sim: Simulation, key: str) -> tuple[np.ndarray, np.ndarray]:
    return (np.array([r["t"] for r in sim.body_history]),
            np.array([r[key] for r in sim.body_history]))


def archimedes(dp: float) -> dict:
    """Box released 0.02 m (20 % of its draft) too deep, heave only, with a heave damper (zero at
    rest: the equilibrium is unchanged) so it settles in ~1 s; draft = mean of the last 0.5 s."""
    t_end = 2.0
    sim = _sim(floating_box_scene(dp=dp, breadth=BREADTH, height=HEIGHT, density=DENSITY,
                                        depth=DEPTH, offset=0.02, damper=800.0, t_end=t_end))
    tic = time.perf_counter()
    sim.advance_to(t_end)
    t, zc = _series(sim, "box_z")
    # the draft below the level the water has (the box displaces water in the closed tank):
    draft = box_draft(sim, z_bottom=zc - 0.5 * HEIGHT)
    last = t > t_end - 0.5
    return _line("archimedes_draft", float(draft[last].mean()), archimedes_draft(DENSITY, HEIGHT),
                 time.perf_counter() - tic, dp=dp, draft_std_last=float(draft[last].std()),
                 unit="m")


def _crossings(t: np.ndarray, y: np.ndarray) -> np.ndarray:
    k = np.nonzero(np.sign(y[:-1]) != np.sign(y[1:]))[0]
    return t[k] - y[k] * (t[k + 1] - t[k]) / (y[k + 1] - y[k])


def heave(dp: float, offset: float = 0.02, constants: dict | None = None,
          length: float = 3.2, t_end: float = 1.2, save: str | None = None) -> dict:
    """Undamped release ``offset`` too deep in a ``length`` closed tank, heave only, against
    linear potential flow for the same tank and release (wavesph/cases/heave_potential.py, converged: dx
    0.01 and 0.005 m give the same crossings within 0.3 %). Heave Z from the equilibrium position;
    the period measure is twice the time between its first two zero crossings (the motion is
    a heave mode coupled with the tank's sloshing, the same measure on both); the decay is the
    first half-cycle peak over the release offset, for both. ``constants``: [constants] of the
    scene (a study's one factor); ``save``: an .npz path for both series."""
    from wavesph.cases.heave_potential import heave_release

    d = archimedes_draft(DENSITY, HEIGHT)
    sim = _sim(floating_box_scene(dp=dp, breadth=BREADTH, height=HEIGHT, density=DENSITY,
                                        depth=DEPTH, offset=offset, tank_length=length,
                                        t_end=t_end, probe_every=0.005, constants=constants))
    tic = time.perf_counter()
    sim.advance_to(t_end)
    wall = time.perf_counter() - tic
    t, zc = _series(sim, "box_z")
    _, fz = _series(sim, "box_fz")
    zb = zc - 0.5 * HEIGHT
    # equilibrium bottom: the level the water has then, minus the draft
    area = sim.n_fluid * dp * dp
    zb_eq = (area + BREADTH * d) / length - d
    z_sph = zb - zb_eq
    tl, z_lin = heave_release(length, DEPTH, BREADTH, d, DENSITY * BREADTH * HEIGHT,
                              float(z_sph[0]), t_end, dx=0.01)
    if save:
        Path(save).parent.mkdir(parents=True, exist_ok=True)
        np.savez(save, t=t, z=z_sph, fz=fz, t_lin=tl, z_lin=z_lin)
    cs, cl = _crossings(t, z_sph), _crossings(tl, z_lin)

    def peaks(tt, zz, c):
        return [float(np.max(np.abs(zz[(tt >= a) & (tt <= b)]))) for a, b in zip(c[:-1], c[1:])]

    ps, pl = peaks(t, z_sph, cs), peaks(tl, z_lin, cl)
    period = 2.0 * float(cs[1] - cs[0]) if cs.size > 1 else None
    ref = 2.0 * float(cl[1] - cl[0])
    return _line("heave_period", period, ref, wall, dp=dp, tank_length=length, offset=offset,
                 constants=constants or {}, first_crossing=float(cs[0]),
                 first_crossing_linear=float(cl[0]),
                 peak_ratio=(ps[0] / abs(z_sph[0]) if ps else None),
                 peak_ratio_linear=pl[0] / abs(z_lin[0]),
                 added_mass_inf_linear=heave_release.last["a_inf"], unit="s")


def flap_still(dp: float) -> dict:
    t_end = 1.0
    sim = _sim(hinged_flap_scene(dp=dp, t_end=t_end))
    tic = time.perf_counter()
    sim.advance_to(t_end)
    _, th = _series(sim, "flap_theta")
    return _line("flap_still", float(np.max(np.abs(th))), 0.0, time.perf_counter() - tic, dp=dp,
                 unit="rad (max |theta| over 1 s)")


SPRING_IN_WATER = 600.0   # N m/rad: natural frequency ~20 rad/s, radiation damping ratio ~0.06


def spring_flap(dp: float) -> dict:
    """A bottom-hinged flap on a torsion spring in still water (0.3 m deep on both sides),
    started with a small rate, against linear wavemaker theory (added inertia and radiation
    damping at the natural frequency, wavesph.cases.rigid_bodies.spring_flap_in_water). The stiff spring
    keeps the radiation damping small (a flap is an efficient wavemaker: at 10 rad/s it would
    be damped at ~0.8 of critical). Period: mean of the zero-crossing intervals over 1.5 s,
    before the radiated waves come back from the tank ends (~8 s)."""
    from wavesph.cases.rigid_bodies import spring_flap_in_water

    ref = spring_flap_in_water(0.04, 0.4, 500.0, SPRING_IN_WATER, 0.3)
    t_end = 1.5
    sim = _sim(hinged_flap_scene(dp=dp, spring=SPRING_IN_WATER, omega0=0.5,
                                       in_water=True, t_end=t_end, probe_every=0.002))
    tic = time.perf_counter()
    sim.advance_to(t_end)
    t, th = _series(sim, "flap_theta")
    c = _crossings(t, th)
    period = 2.0 * float(np.mean(np.diff(c))) if c.size > 2 else None
    peaks = [float(np.max(np.abs(th[(t >= a) & (t <= b)]))) for a, b in zip(c[:-1], c[1:])]
    decay = (float(np.log(peaks[0] / peaks[-1]) / (len(peaks) - 1) / np.pi)
             if len(peaks) > 1 else None)   # log decrement per half cycle / pi ~ zeta
    return _line("spring_flap_period", period, ref["period"], time.perf_counter() - tic, dp=dp,
                 medium="water 0.3 m deep both sides", spring=SPRING_IN_WATER,
                 added_inertia_linear=ref["added_inertia"], inertia=ref["inertia"],
                 zeta_linear=ref["zeta"], zeta_measured=decay, half_cycles=len(peaks),
                 unit="s")


def spring_flap_air(dp: float) -> dict:
    """In air (the water is a pool held away from the flap): hinge inertia, gravity, spring."""
    k = 40.0
    ref = spring_flap_period(0.04, 0.4, 500.0, k)
    sim = _sim(hinged_flap_scene(dp=dp, spring=k, omega0=0.05, in_water=False,
                                       t_end=3.2 * ref, probe_every=ref / 100))
    tic = time.perf_counter()
    sim.advance_to(sim.scene.t_end)
    t, th = _series(sim, "flap_theta")
    return _line("spring_flap_period_air", zero_crossing_period(t, th), ref,
                 time.perf_counter() - tic, dp=dp, medium="air (no water on the flap)", unit="s")


def wedge(dp: float) -> dict:
    """Zhao et al. (1996) drop test: pressure along the face at 0.00435 s against Wagner's
    theory with the run's own speed (wavesph/cases/wedge_entry.py; the measured distributions were not
    at hand), and the SPH values at 0.0158 s (flow separated: no Wagner reference)."""
    from wavesph.cases.wedge_entry import TIMES, wedge_pressures, wedge_scene

    sim = _sim(wedge_scene(dp=dp))
    tic = time.perf_counter()
    rows = wedge_pressures(sim, TIMES)
    first = rows[0]
    xs = np.array(first["x"])
    sel = (np.isfinite(np.array(first["p_sph"], dtype=float))
           & np.isfinite(np.array(first["p_wagner"], dtype=float)) & (xs <= 0.8 * first["c_wagner"]))
    value = float(np.mean(np.array(first["p_sph"], dtype=float)[sel])) if sel.any() else None
    ref = float(np.mean(np.array(first["p_wagner"], dtype=float)[sel])) if sel.any() else None
    return _line("wedge_pressure", value, ref, time.perf_counter() - tic, dp=dp,
                 unit="Pa (mean over the face points at x <= 0.8 c, t = 0.00435 s)",
                 reference_kind="Wagner (1932) outer solution, the run's own V(t)",
                 times=rows)


def momentum(dp: float) -> dict:
    scene = make_scene({
        "dp": dp, "t_end": 1.0, "tank": {"x0": 0, "x1": 1.2, "z0": 0, "z1": 1.2},
        "water_blocks": [{"x0": 0.3, "x1": 0.9, "z0": 0.3, "z1": 0.9}],
        "bodies": [{"name": "box", "shape": "box", "x0": 0.52, "x1": 0.68, "z0": 0.52,
                    "z1": 0.6, "density": 800.0, "velocity": (0.5, -0.3, 1.0)}]})
    sim = _sim(scene)
    zero_gravity(sim)

    def total() -> np.ndarray:
        ps, bd = sim.particles, sim.bodies.state
        fl = ps.mask(FLUID)
        m = ps.field(M)[fl]
        return np.array([np.sum(m * ps.field(VX)[fl]) + bd.mass[0] * bd.qd[0, 0],
                         np.sum(m * ps.field(VZ)[fl]) + bd.mass[0] * bd.qd[0, 1]])

    p0 = total()
    scale = float(np.hypot(*(sim.bodies.state.mass[0] * sim.bodies.state.qd[0, :2])))
    tic = time.perf_counter()
    sim.advance_steps(300)
    return _line("momentum_zero_gravity", float(np.linalg.norm(total() - p0) / scale), 0.0,
                 time.perf_counter() - tic, dp=dp, unit="|dP| / |P_body(0)| after 300 steps")


def flume_throughput(dp: float, steps: int) -> list[dict]:
    """Particle-steps/s of the demo flume (closed, still water) without and with a floating box."""
    from wavesph.cases.demo_flume import demo_scene, depth_for

    base = demo_scene(dp, 10.0)
    base.pop("open_boundaries")
    d = depth_for(dp)
    box = {"name": "box", "shape": "box", "x0": 1.0, "x1": 1.2, "z0": d - 0.04, "z1": d + 0.04,
           "density": 500.0}
    out = []
    for label, bodies in (("without_body", []), ("with_body", [box])):
        sim = _sim(make_scene({**base, "bodies": bodies}))
        sim.advance_steps(20)   # compile + warm-up
        w0, s0 = sim.wall_time, sim.steps
        sim.advance_steps(steps)
        wall = sim.wall_time - w0
        out.append({"check": "flume_throughput", "variant": label, "dp": dp,
                    "particles": sim.n_particles, "steps": sim.steps - s0,
                    "particle_steps_per_s": sim.n_particles * (sim.steps - s0) / wall,
                    "wall_s": round(wall, 2)})
    out.append({"check": "flume_throughput_ratio", "value": out[1]["particle_steps_per_s"]
                / out[0]["particle_steps_per_s"], "reference": 0.9,
                "note": "with/without body; goal >= 0.9 (under load: noisy)"})
    return out


def flap_pitch(dp: float, t_end: float = 8.0) -> dict:
    """The coupled demo flume with its bottom-hinged flap (`wavesph demo --body flap`: Stokes-2
    waves H 0.04 m, T 1.4 s from the wave client, depth 0.24 m, flap 0.08 m thick, 500 kg/m^3,
    k = 20 N m/rad): pitch period (mean upward zero-crossing interval) and amplitude (half the
    peak-to-peak) over the last 3 wave periods, against the linear response of the flap in a
    channel open on both sides (wavesph.cases.rigid_bodies.flap_wave_response). Not seed 004's
    H 0.15 m, T 1.34 s: no published pitch amplitude for that set-up was found."""
    import csv
    import math
    import tempfile

    from wavesph.cases.demo_flume import (FLAP_SPRING, FLAP_THICKNESS, HEIGHT, PERIOD, depth_for,
                                  run_demo)
    from wavesph.cases.rigid_bodies import flap_wave_response

    d = depth_for(dp)
    tic = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        info, _ = run_demo(dp, t_end, "tcp", Path(tmp), body="flap")
        (path,) = list(Path(tmp).glob("*/sph*/bodies.csv"))
        rows = list(csv.DictReader(open(path)))
    wall = time.perf_counter() - tic
    t = np.array([float(r["t"]) for r in rows])
    th = np.array([float(r["flap_theta"]) for r in rows])
    sel = t >= t[-1] - 3 * PERIOD
    y = th[sel] - th[sel].mean()
    ts = t[sel]
    k = np.nonzero((y[:-1] < 0) & (y[1:] >= 0))[0]
    tc = ts[k] - y[k] * (ts[k + 1] - ts[k]) / (y[k + 1] - y[k])
    amp = 0.5 * float(th[sel].max() - th[sel].min())
    ref = flap_wave_response(max(FLAP_THICKNESS, 4 * dp), d + 0.05, 500.0, FLAP_SPRING, d,
                             HEIGHT, PERIOD)
    return _line("flap_pitch", amp, ref["amplitude"], wall, dp=dp, state=info["state"],
                 unit="rad (pitch amplitude, last 3 wave periods)",
                 amplitude_deg=math.degrees(amp), reference_deg=math.degrees(ref["amplitude"]),
                 period=float(np.mean(np.diff(tc))) if tc.size > 1 else None,
                 wave_period=PERIOD, mean_theta_deg=math.degrees(float(th[sel].mean())),
                 reference_kind="linear wavemaker theory (no published value found)")


CHECKS = ("archimedes_draft", "heave_period", "flap_still", "spring_flap_period",
          "spring_flap_period_air", "momentum_zero_gravity", "wedge_pressure", "flap_pitch",
          "throughput")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dp", type=float, default=0.02)
    ap.add_argument("--steps", type=int, default=1000, help="steps per throughput variant")
    ap.add_argument("--checks", nargs="*", default=list(CHECKS), choices=CHECKS)
    ap.add_argument("--constants", type=json.loads, default={},
                    help='JSON [constants] for every scene, e.g. \'{"h_over_dp": 2.0}\'')
    a = ap.parse_args()
    CONSTANTS.update(a.constants)
    runners = {"archimedes_draft": archimedes, "heave_period": heave, "flap_still": flap_still,
               "spring_flap_period": spring_flap, "spring_flap_period_air": spring_flap_air,
               "momentum_zero_gravity": momentum, "wedge_pressure": wedge,
               "flap_pitch": flap_pitch}
    for c in a.checks:
        if c in runners:
            print(json.dumps({**runners[c](a.dp), "constants": a.constants}), flush=True)
        elif c == "throughput":
            for line in flume_throughput(a.dp, a.steps):
                print(json.dumps(line), flush=True)
        else:
            print(json.dumps({"check": c, "value": None, "reference": None, "rel_error": None,
                              "wall_s": 0.0, "status": "not_run"}), flush=True)


if __name__ == "__main__":
    main()
