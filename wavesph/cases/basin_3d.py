"""The 3D coupled basin of `wavesph demo --basin`: long-crested waves from the wave client past a
square column in a basin with side walls, through the server like the 2D demo flume.

A basin of width BASIN_WIDTH with side walls, still water BASIN_DEPTH (rounded to whole dp rows), an open
inlet at x = 0 (elevation imposed, absorbing) driven over the coupling socket by wave_client's
regular Stokes-2 wave, an open outlet at x = BASIN_LENGTH (elevation extrapolated, absorbing), and a
square column (BASIN_COLUMN wide, from the bed through the surface) in the middle of the width at
x = X_COLUMN. The protocol carries the 2D wave (PROTOCOL.md: long-crested waves in 3D runs); the
gauges are elevation probes on the centre line before and beside the column, and a force probe
gives the load on the column. Datum: the floor is z = 0, still water at z = depth.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from .coupled_flume import depth_for_case
from .wave_flume import buffer_width_for
from .demo_flume import HEIGHT, PERIOD, _couple
from ..local_server import InProcessServer

BASIN_DEPTH = 0.24      # m (the 2D demo's)
BASIN_WIDTH = 0.36      # m
BASIN_LENGTH = 2.4      # m: one wavelength (2.0 m) and a little
X_COLUMN = 1.2    # m: the column's centre
BASIN_COLUMN = 0.12     # m: its side
H_OVER_DP = 1.5   # a 3D support of ~110 neighbours (2: ~270, 2.4x the cost)
BASIN_GAUGES = {"front": X_COLUMN - 0.5, "column": X_COLUMN}   # x of the centre-line gauges [m]


def basin_scene(dp: float, t_end: float) -> dict[str, Any]:
    """The basin as a server scene (plain dict, validated by the server)."""
    d = depth_for_case(BASIN_DEPTH, dp)
    yc = 0.5 * BASIN_WIDTH
    c0, c1 = X_COLUMN - 0.5 * BASIN_COLUMN, X_COLUMN + 0.5 * BASIN_COLUMN
    probes: list[dict[str, Any]] = [{"kind": "elevation", "name": "front", "x": BASIN_GAUGES["front"],
                                     "y": yc},
                                    # beside the column, half-way to the side wall
                                    {"kind": "elevation", "name": "column", "x": X_COLUMN,
                                     "y": 0.5 * (yc + 0.5 * BASIN_COLUMN + BASIN_WIDTH)},
                                    {"kind": "force", "name": "column_load", "x0": c0 - dp,
                                     "x1": c1 + dp, "y0": yc - 0.5 * BASIN_COLUMN - dp,
                                     "y1": yc + 0.5 * BASIN_COLUMN + dp, "z0": 0.0, "z1": d + 0.2}]
    bw = buffer_width_for(HEIGHT, PERIOD, d, dp)   # the buffers as wide as the wave's orbit
    return {
        "name": "wavesph-basin-3d", "dim": 3, "dp": dp, "t_end": t_end, "still_water_level": d,
        "tank": {"x0": 0.0, "x1": BASIN_LENGTH, "y0": 0.0, "y1": BASIN_WIDTH, "z0": 0.0, "z1": round(d + 0.2, 12)},
        "water_blocks": [{"x0": 0.0, "x1": BASIN_LENGTH, "z0": 0.0, "z1": d}],
        "structures": [{"x0": c0, "x1": c1, "y0": yc - 0.5 * BASIN_COLUMN, "y1": yc + 0.5 * BASIN_COLUMN,
                        "z0": 0.0, "z1": round(d + 0.2, 12)}],
        "constants": {"c0": 10.0 * math.sqrt(9.81 * d), "wall_slip": "free_slip",
                      "h_over_dp": H_OVER_DP},
        "output": {"probe_every": PERIOD / 20, "snapshot_every": min(1.0, t_end)},
        "probes": probes,
        "open_boundaries": [{"side": "left", "elevation": "imposed", "absorb": True,
                             "buffer_width": bw},
                            {"side": "right", "elevation": "extrapolated", "absorb": True,
                             "buffer_width": bw}],
    }


def run_basin(dp: float, t_end: float, transport: str, out: Path,
              device: str | None = None) -> tuple[dict, Any]:
    """The basin at spacing ``dp`` [m] to ``t_end`` [s], coupled over ``transport`` to a server
    in this process storing its runs in ``out``: (final run record, client report or None)."""
    with InProcessServer(out, **({"device": device} if device else {})) as srv:
        return _couple(srv, basin_scene(dp, t_end), transport, out,
                       where=f"past a {BASIN_COLUMN:g} m square column in a {BASIN_WIDTH:g} m wide 3D basin")


def basin_figures(info: dict, report: Any, wall: float, depth: float) -> dict[str, Any]:
    """The figures of a finished basin run (summary.json): speed, coupling overhead, RMSE/H at
    the centre-line gauge before the column against the Stokes-2 theory (from when the ramped
    wave has reached it at the linear group velocity)."""
    from wave_client.theories import wavenumber

    from ..analysis import group_velocity
    from .demo_flume import RAMP_PERIODS, gauge_rmse

    wavelength = 2 * math.pi / float(wavenumber(2 * math.pi / PERIOD, depth))
    t0 = RAMP_PERIODS * PERIOD + BASIN_GAUGES["front"] / group_velocity(wavelength, PERIOD, depth)
    # after the two open ends' own gauges
    rmse = gauge_rmse(report, 2 + list(BASIN_GAUGES).index("front"), t0)
    particles, steps = info["particles"], info["steps"]
    pss = info["particle_steps_per_s"] or 0.0
    return {"particles": particles, "windows": info["windows"], "steps": steps,
            "wall_s": round(wall, 2), "particle_steps_per_s": round(pss),
            "coupling_overhead_share": round(info["coupling_overhead_share"] or 0.0, 4),
            "compare_from_s": round(t0, 3),
            "rmse_over_H_front": None if rmse is None else round(rmse, 4),
            "gauge_x_m": BASIN_GAUGES, "H_m": HEIGHT, "T_s": PERIOD, "depth_m": depth,
            "width_m": BASIN_WIDTH, "column_m": BASIN_COLUMN}
