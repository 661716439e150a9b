"""The solver's schemes as named option sets, and the command-line options that pick one.

    add_scheme_arguments(ap); scheme = scheme_from_args(ap.parse_args())   # -> [scheme] table
    wave_flume_scene(..., scheme=scheme)        # every case builder takes ``scheme``

A scheme option set is the scene's ``[scheme]`` table (sph_core.scene.Scheme) as a dict; the
case builders (dambreak, wave_flume, standing_wave of this package) pass it into the scene.
"""

from __future__ import annotations

import argparse
from typing import Any

# Riemann SPH variants (sph_core.riemann): MUSCL reconstruction (van Leer or minmod limiter) or
# none, Zhang et al. (2017) low-dissipation limiter or the plain Godunov flux (beta = 1).
# riemann_muscl is the scene's default [scheme] kind = "riemann".
RIEMANN_VARIANTS: dict[str, dict[str, Any]] = {
    "riemann_muscl": {"kind": "riemann", "reconstruction": "muscl", "limiter": "vanleer",
                      "low_dissipation": False},
    "riemann_muscl_minmod": {"kind": "riemann", "reconstruction": "muscl", "limiter": "minmod",
                             "low_dissipation": False},
    "riemann_muscl_lowdiss": {"kind": "riemann", "reconstruction": "muscl", "limiter": "vanleer",
                              "low_dissipation": True},
    "riemann_lowdiss": {"kind": "riemann", "reconstruction": "none", "low_dissipation": True},
    "riemann_plain": {"kind": "riemann", "reconstruction": "none", "low_dissipation": False},
}


def add_scheme_arguments(ap: argparse.ArgumentParser) -> None:
    """--scheme, --reconstruction, --limiter, --low-dissipation / --no-low-dissipation,
    --ppe-solver."""
    ap.add_argument("--scheme", choices=["wcsph", "riemann", "isph"], default="wcsph",
                    help="[scheme] kind (sph_core.scene.Scheme)")
    ap.add_argument("--reconstruction", choices=["muscl", "none"], help="riemann: reconstruction")
    ap.add_argument("--limiter", choices=["minmod", "vanleer"], help="riemann: MUSCL limiter")
    ap.add_argument("--low-dissipation", action=argparse.BooleanOptionalAction, default=None,
                    help="riemann: Zhang et al. 2017 dissipation limiter (scene default: on)")
    ap.add_argument("--ppe-solver", choices=["explicit", "amg", "ilu", "direct"],
                    help="isph: pressure Poisson solver (scene default: amg)")


def scheme_from_args(a: argparse.Namespace) -> dict[str, Any]:
    """The [scheme] table of the parsed options (options left out keep the scene defaults)."""
    out: dict[str, Any] = {"kind": a.scheme}
    if a.scheme == "riemann":
        out.update({k: v for k, v in {"reconstruction": a.reconstruction, "limiter": a.limiter,
                                      "low_dissipation": a.low_dissipation}.items()
                    if v is not None})
    if a.scheme == "isph" and a.ppe_solver is not None:
        out["ppe_solver"] = a.ppe_solver
    return out
