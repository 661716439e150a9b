"""The solver's schemes as named option sets, and the command-line options that pick one.

    add_scheme_arguments(ap); scheme = scheme_from_args(ap.parse_args())   # -> [scheme] table
    wave_flume_scene(..., scheme=scheme)        # every case builder takes ``scheme``

A scheme option set is the scene's ``[scheme]`` table (sph_core.scene.Scheme) as a dict; the
case builders (dambreak, wave_flume, standing_wave of this package) pass it into the scene.
"""

from __future__ import annotations

import argparse
from typing import Any

# Riemann SPH variants (sph_core.riemann): MUSCL reconstruction (van Leer) or none (the plain
# first-order Godunov flux). riemann_muscl is the scene's default [scheme] kind = "riemann".
RIEMANN_VARIANTS: dict[str, dict[str, Any]] = {
    "riemann_muscl": {"kind": "riemann", "reconstruction": "muscl"},
    "riemann_plain": {"kind": "riemann", "reconstruction": "none"},
}


def add_scheme_arguments(ap: argparse.ArgumentParser) -> None:
    """--scheme, --reconstruction, and the isph options --ppe-solver, --isph-density-relaxation,
    --isph-wall-stop, --isph-relaxation-zone, --isph-relaxation-time."""
    ap.add_argument("--scheme", choices=["wcsph", "riemann", "isph"], default="wcsph",
                    help="[scheme] kind (sph_core.scene.Scheme)")
    ap.add_argument("--reconstruction", choices=["muscl", "none"], help="riemann: reconstruction")
    ap.add_argument("--ppe-solver", choices=["bicgstab", "amg"],
                    help="isph: pressure Poisson solver (scene default: bicgstab)")
    ap.add_argument("--isph-density-relaxation", type=float,
                    help="isph: density-invariance weight (scene default 0.01)")
    ap.add_argument("--isph-wall-stop", type=float,
                    help="isph: steps over which fluid approaching a wall is stopped "
                         "(scene default 1)")
    ap.add_argument("--isph-relaxation-zone", type=float,
                    help="isph: relaxation zone inside each open end [m] (scene default 0: "
                         "none)")
    ap.add_argument("--isph-relaxation-time", type=float,
                    help="isph: time scale of the relaxation zone's pull at the face [s] "
                         "(scene default 0.2)")


def scheme_from_args(a: argparse.Namespace) -> dict[str, Any]:
    """The [scheme] table of the parsed options (options left out keep the scene defaults)."""
    out: dict[str, Any] = {"kind": a.scheme}
    if a.scheme == "riemann":
        if a.reconstruction is not None:
            out["reconstruction"] = a.reconstruction
    if a.scheme == "isph":
        for key in ("ppe_solver", "isph_density_relaxation", "isph_wall_stop",
                    "isph_relaxation_zone", "isph_relaxation_time"):
            if getattr(a, key) is not None:
                out[key] = getattr(a, key)
    return out


def add_constant_arguments(ap: argparse.ArgumentParser, open_ends: bool = False) -> None:
    """The [constants] options a bench varies (sph_core.scene.Constants); unset keeps the scene's."""
    ap.add_argument("--h-over-dp", type=float, help="smoothing length / dp (scene default if unset)")
    ap.add_argument("--alpha", type=float, help="artificial viscosity coefficient")
    ap.add_argument("--slip", choices=["no_slip", "free_slip"], help="wall (bed) condition")
    ap.add_argument("--delta", type=float, help="delta-SPH density diffusion coefficient")
    ap.add_argument("--cfl", type=float, help="Courant number")
    ap.add_argument("--integrator", choices=["kdk", "symplectic_pc"])
    ap.add_argument("--nu", type=float, help="laminar kinematic viscosity [m^2/s]")
    ap.add_argument("--shifting", choices=["none", "fickian", "dplus"], help="particle shifting")
    ap.add_argument("--shift-a", type=float, help="shifting coefficient A (Lind et al. 2012)")
    ap.add_argument("--shift-fs-div", type=float, help="free-surface position-divergence limit")
    ap.add_argument("--shift-dplus-scale", type=float, help="dplus: multiplier on CFL Ma (2h)^2")
    if open_ends:
        ap.add_argument("--shift-open-end", choices=["full", "none"],
                        help="shifting next to an open end's buffer")
    ap.add_argument("--no-shift-carry", action="store_true",
                    help="do not Taylor-carry rho, v of a shifted particle")
    ap.add_argument("--alpha-wall", type=float, help="artificial viscosity factor against walls")
    ap.add_argument("--precision", choices=["float64", "float32"],
                    help="storage of the particle fields")


def constants_from_args(a: argparse.Namespace) -> dict[str, Any]:
    """The [constants] table of the options add_constant_arguments parsed: only those given."""
    given = {"h_over_dp": a.h_over_dp, "alpha": a.alpha, "wall_slip": a.slip,
             "delta": a.delta, "cfl": a.cfl, "nu": a.nu,
             "integrator": a.integrator, "shifting": a.shifting,
             "shift_a": a.shift_a, "shift_fs_div": a.shift_fs_div,
             "alpha_wall_factor": a.alpha_wall,
             "shift_dplus_scale": a.shift_dplus_scale,
             "shift_carry": False if a.no_shift_carry else None,
             "shift_open_end": getattr(a, "shift_open_end", None),
             "precision": getattr(a, "precision", None)}
    return {k: v for k, v in given.items() if v is not None}
