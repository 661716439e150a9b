"""The solver's schemes as named option sets, and the command-line options that pick one.

    add_scheme_arguments(ap); scheme = scheme_from_args(ap.parse_args())   # -> [scheme] table
    wave_flume_scene(..., scheme=scheme)        # every case builder takes ``scheme``

A scheme option set is the scene's ``[scheme]`` table (sph_core.scene.Scheme) as a dict; the
case builders (cases.dambreak, cases.wave_flume, cases.standing_wave) pass it into the scene.
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
    """--scheme, --reconstruction, --ppe-solver."""
    ap.add_argument("--scheme", choices=["wcsph", "riemann", "isph"], default="wcsph",
                    help="[scheme] kind (sph_core.scene.Scheme)")
    ap.add_argument("--reconstruction", choices=["muscl", "none"], help="riemann: reconstruction")
    ap.add_argument("--ppe-solver", choices=["bicgstab", "amg"],
                    help="isph: pressure Poisson solver (scene default: bicgstab)")


def scheme_from_args(a: argparse.Namespace) -> dict[str, Any]:
    """The [scheme] table of the parsed options (options left out keep the scene defaults)."""
    out: dict[str, Any] = {"kind": a.scheme}
    if a.scheme == "riemann":
        if a.reconstruction is not None:
            out["reconstruction"] = a.reconstruction
    if a.scheme == "isph" and a.ppe_solver is not None:
        out["ppe_solver"] = a.ppe_solver
    return out
