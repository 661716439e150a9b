"""The case of `wavesph demo`: a coupled wave-SPH flume with a beach, end to end on this machine.

`run_demo` starts the SPH server in this process on free loopback ports, creates a coupled run of a short
2D flume (open inlet on the left, flat bed, then a 1:10 beach up to a closed right end), connects
wave_client's coupling client with a regular second-order Stokes wave over the real socket
(WebSocket, or TCP with ``--transport tcp``), shows the client's progress bar, and writes into
the run directory (`wavesph/cli/demo.py` adds the figures and the plot):

    <run id>/            the server's run record: meta.json, gauges.csv (SPH-measured), sph/...
    client_gauges.csv    the client's log: measured and theoretical elevation per window
    elevation.png        SPH-measured vs theoretical elevation at the gauges, and the flume
    summary.json         the figures printed at the end

Datum: the flume floor is z = 0, still water at z = depth_for(dp) (0.24 m); elevations are up from it.
The standalone dam break of earlier versions: ``wavesph demo --dambreak`` (or
``wavesph run examples/scenes/dambreak_martin_moyce.toml``).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import Any

import numpy as np

from .coupled_flume import depth_for_case
from .wave_flume import buffer_width_for
from ..local_server import InProcessServer, wait_for_state
from ..analysis import group_velocity, rmse_over_height

# the embedded case: depth d, regular wave (H, T), beach slope
DEPTH = 0.24          # still-water depth on the flat bed [m] (rounded to whole dp: depth_for)
HEIGHT = 0.04         # wave height [m]
PERIOD = 1.4          # wave period [s]; L = 2.0 m at this depth (Stokes 2, Ursell ~ 11)
SLOPE = 0.1           # 1:10 beach
X_TOE = 2.0           # beach toe [m]: one wavelength of flat bed after the inlet
RAMP_PERIODS = 2.0    # start-up ramp of the wave [periods]
FREEBOARD = 0.2       # tank top above the beach's top (d + 0.1 m) [m]
GAUGES = {"flat": 1.0, "toe": X_TOE, "beach": X_TOE + 0.5 * DEPTH / SLOPE}  # x [m]


def depth_for(dp: float) -> float:
    """Still-water depth [m] nearest DEPTH holding whole particle rows: the particles fill whole
    rows of dp, so any other depth would put the SPH surface up to dp/2 below still water."""
    return depth_for_case(DEPTH, dp)


def tank_end(dp: float) -> float:
    """x [m] of the closed right end: the beach rises 0.1 m past still water (room for run-up)."""
    return dp * round((X_TOE + (depth_for(dp) + 0.1) / SLOPE) / dp)


X_BODY = 1.5          # x [m] of the optional body's centre: on the flat bed, past the flat gauge
BODIES = ("box", "flap")
FLAP_THICKNESS = 0.08  # m
FLAP_SPRING = 20.0     # N m/rad


def demo_body(kind: str, dp: float) -> dict[str, Any]:
    """The demo's optional rigid body at X_BODY: ``box``, 0.2 m wide, 0.1 m high,
    500 kg/m^3, free in heave and pitch (draft 0.05 m); ``flap``, bottom-hinged on the bed,
    0.05 m above still water, 500 kg/m^3, with a torsion spring (k = FLAP_SPRING), FLAP_THICKNESS
    thick (4 dp at dp 0.02: thicker than the kernel support, BODIES.md)."""
    d = depth_for(dp)
    if kind == "box":
        return {"name": "box", "shape": "box", "x0": X_BODY - 0.1, "x1": X_BODY + 0.1,
                "z0": d - 0.05, "z1": d + 0.05, "density": 500.0, "motion": "free",
                "dofs": ["heave", "pitch"]}
    if kind == "flap":
        t = max(FLAP_THICKNESS, 4.0 * dp)
        return {"name": "flap", "shape": "flap", "x0": X_BODY - 0.5 * t, "x1": X_BODY + 0.5 * t,
                "z0": 0.0, "z1": d + 0.05, "density": 500.0, "motion": "hinged",
                "spring": FLAP_SPRING}
    raise ValueError(f"body: one of {BODIES}, got {kind!r}")


SNAPSHOT_EVERY = 1.0   # s


def demo_scene(dp: float, t_end: float, body: str | None = None) -> dict[str, Any]:
    """The flume as a server scene (plain dict, validated by the server); ``body``: None, or one
    of BODIES placed on the flat bed (``demo_body``)."""
    d, x1 = depth_for(dp), tank_end(dp)
    return {
        "name": "wavesph-demo", "dp": dp, "t_end": t_end, "still_water_level": d,
        # freeboard: the walls reach FREEBOARD above the beach's top, room for run-up and
        # splashes (the top at d + 2H + 4dp let a shoreline particle hit it at t = 2.4 s); a
        # particle that still leaves is excluded and logged (Constants.exclude_limit)
        "tank": {"x0": 0.0, "x1": x1, "z0": 0.0, "z1": round(d + 0.1 + FREEBOARD, 12)},
        "water_blocks": [{"x0": 0.0, "x1": X_TOE + d / SLOPE, "z0": 0.0, "z1": d}],
        "beds": [{"points": [[X_TOE, 0.0], [x1, SLOPE * (x1 - X_TOE)]]}],
        # c0 = 10 sqrt(g d) bounds orbital speeds x10; free slip: the theory is inviscid
        "constants": {"c0": 10.0 * math.sqrt(9.81 * d), "wall_slip": "free_slip"},
        # VTK snapshots every second (sph/snapshots/, sph/run.pvd), at least the first and last
        "output": {"probe_every": PERIOD / 20, "snapshot_every": min(SNAPSHOT_EVERY, t_end)},
        "probes": [{"kind": "elevation", "name": n, "x": x} for n, x in GAUGES.items()],
        "open_boundaries": [{"side": "left", "elevation": "imposed", "absorb": True,
                             "buffer_width": buffer_width_for(HEIGHT, PERIOD, d, dp)}],
        **({"bodies": [demo_body(body, dp)]} if body else {}),
    }


def run_demo(dp: float, t_end: float, transport: str, out: Path,
             body: str | None = None, device: str | None = None) -> tuple[dict, Any]:
    """The demo flume at spacing ``dp`` [m] to ``t_end`` [s], coupled over ``transport`` ("ws" or
    "tcp") to a server in this process storing its runs in ``out``, with an optional ``body``
    in the SPH zone, the steps on ``device`` (the server's default device; None: cpu): (final
    run record, client report or None)."""
    with InProcessServer(out, **({"device": device} if device else {})) as srv:
        return _couple(srv, demo_scene(dp, t_end, body), transport, out)


def _couple(srv: InProcessServer, scene: dict, transport: str, out: Path,
            where: str | None = None) -> tuple[dict, Any]:
    """Create the run, couple the wave to it; (final run record, client report or None).
    ``where``: what the waves run into, for the start line (default: the flume's beach)."""
    import httpx

    from server.schemas import TERMINAL
    from wave_client.coupling import CouplingError, CouplingOptions, couple
    from wave_client.theories import build_theory

    base = f"http://127.0.0.1:{srv.port}"
    with httpx.Client(base_url=base, timeout=60) as http:
        r = http.post("/runs", json={"scene": scene, "mode": "coupled",
                                     "coupling": {"window_max": PERIOD / 50}})
        r.raise_for_status()
        run = r.json()
        info = wait_for_state(http, run["id"], {"waiting_for_client", "failed"}, timeout=120)
        if info["state"] == "failed":
            return info, None
        count = f"{info['particles']} particles, " if info.get("particles") else ""
        print(f"wavesph demo: {count}dp = {scene['dp']} m, "
              f"{scene['t_end']} s of Stokes-2 waves (H = {HEIGHT} m, T = {PERIOD} s, depth "
              f"{scene['still_water_level']:.4g} m) {where or f'onto a 1:{1 / SLOPE:g} beach'}; "
              f"server on {base}, coupling over "
              f"{'WebSocket' if transport == 'ws' else 'TCP'}", file=sys.stderr)
        url = (f"ws://127.0.0.1:{srv.port}/runs/{run['id']}/couple" if transport == "ws"
               else f"tcp://127.0.0.1:{srv.tcp_port}")
        wave = build_theory("stokes", height=HEIGHT, period=PERIOD, depth=scene["still_water_level"], order=2,
                            ramp_time=RAMP_PERIODS * PERIOD)
        report = None
        try:
            report = couple(url, wave, CouplingOptions(), run_id=run["id"],
                            scene_hash=bytes.fromhex(run["scene_hash"]), timeout=600.0,
                            log_path=out / "client_gauges.csv")
        except CouplingError as exc:
            print(f"wavesph demo: coupling failed: {exc}", file=sys.stderr)
        info = wait_for_state(http, run["id"], TERMINAL, timeout=60)
    return info, report


def compare_from(depth: float) -> float:
    """Start of the comparison at the flat-bed gauge: the ramp, then the travel to the gauge at
    the linear group velocity (before that SPH still has the front, the theory has not)."""
    from wave_client.theories import wavenumber

    wavelength = 2 * math.pi / float(wavenumber(2 * math.pi / PERIOD, depth))
    return RAMP_PERIODS * PERIOD + GAUGES["flat"] / group_velocity(wavelength, PERIOD, depth)


def gauge_rmse(report: Any, j: int, t0: float) -> float | None:
    """RMSE/H of RESULT gauge j (measured, dry as NaN) against the wave model's elevation there
    from t0 on; None with fewer than 10 windows after t0."""
    sel = report.t >= t0
    if sel.sum() < 10:
        return None
    meas = np.array([r.eta[j] if r.wet[j] else np.nan for r in report.records])[sel]
    theory = np.array([r.eta_model[j] for r in report.records])[sel]
    return rmse_over_height(meas, theory, HEIGHT)


def demo_figures(info: dict, report: Any, wall: float, depth: float) -> dict[str, Any]:
    """The figures of a finished demo run (summary.json): speed, coupling overhead, RMSE/H at
    the flat-bed gauge against the Stokes-2 theory."""
    t0 = compare_from(depth)
    rmse = gauge_rmse(report, _gauge_index(report, "flat"), t0)
    particles, steps = info["particles"], info["steps"]
    pss = info["particle_steps_per_s"] or 0.0
    return {"particles": particles, "windows": info["windows"], "steps": steps,
            "wall_s": round(wall, 2), "sph_solve_s": round(particles * steps / pss, 2) if pss else 0.0,
            "particle_steps_per_s": round(pss), "particle_steps_per_s_wall": round(particles * steps / wall),
            "coupling_overhead_share": round(info["coupling_overhead_share"] or 0.0, 4),
            "compare_from_s": round(t0, 3), "rmse_over_H_flat": None if rmse is None else round(rmse, 4),
            "gauge_x_m": GAUGES, "H_m": HEIGHT, "T_s": PERIOD, "depth_m": depth, "slope": SLOPE}


def _gauge_index(report: Any, name: str) -> int:
    """Index of a scene probe among the RESULT gauges: the inlet's boundary gauge comes first."""
    return 1 + list(GAUGES).index(name)


def plot_demo(report: Any, info: dict, path: Path, dp: float, t_end: float, t0: float,
              rmse_over_h: float | None = None) -> Path:
    """Measured vs theoretical elevation at each gauge, and the flume with its gauges; the title
    says the resolution is deliberately coarse and gives the flat-bed gauge's RMSE/H."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = report.t
    names = ["inlet gauge"] + [f"{n} (x = {x:g} m)" for n, x in GAUGES.items()]
    fig, axes = plt.subplots(len(names) + 1, 1, figsize=(10, 2.1 * (len(names) + 1)),
                             sharex=False, constrained_layout=True)
    for j, (ax, name) in enumerate(zip(axes, names)):
        meas = np.array([r.eta[j] if r.wet[j] else np.nan for r in report.records])
        theory = np.array([r.eta_model[j] for r in report.records])
        flat = j <= 2  # inlet, flat-bed and toe gauges stand on the flat bed
        ax.plot(t, 100 * theory, "k--", lw=1, label="Stokes 2 theory" + ("" if flat else
                                                                        " (flat bed: not valid here)"))
        ax.plot(t, 100 * meas, "C0-", lw=1.2, label=f"SPH measured (dp = {dp:g} m)")
        ax.axvline(t0, color="0.7", lw=0.8)
        ax.set(ylabel="eta [cm]", xlim=(0, t_end), title=name)
        ax.grid(alpha=0.3)
        ax.legend(loc="upper left", fontsize=8)
    axes[-2].set_xlabel("t [s]")
    ax = axes[-1]
    d, x1 = depth_for(dp), tank_end(dp)
    ax.fill_between([0.0, X_TOE, x1], -0.02, [0.0, 0.0, SLOPE * (x1 - X_TOE)], color="0.75")
    ax.fill_between([0, X_TOE, X_TOE + d / SLOPE], [0, 0, d], d, color="C0", alpha=0.3)
    for n, x in GAUGES.items():
        ax.axvline(x, color="C3", lw=0.8)
        ax.text(x, d + 0.03, n, color="C3", ha="center", fontsize=8)
    ax.set(xlabel="x [m]", ylabel="z [m]", title="flume: open inlet at x = 0, 1:10 beach, "
           f"still water at z = {d:.4g} m (floor z = 0)", ylim=(-0.02, d + 0.1))
    rmse = "n/a" if rmse_over_h is None else f"{100 * rmse_over_h:.1f} %"
    fig.suptitle(f"wavesph demo: coupled run {info['id'][:8]}, {info['particles']} particles; "
                 f"deliberately coarse (dp = {dp:g} m, H/dp = {HEIGHT / dp:.3g}) to run in about a "
                 f"minute; RMSE/H at the flat-bed gauge {rmse} (t >= {t0:.2f} s)")
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path
