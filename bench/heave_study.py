"""Why does the SPH floating box heave faster and more damped than linear theory?

One factor at a time on bench/bodies.py's heave release (box 0.4 x 0.2 m, 500 kg/m^3, depth
0.3 m, 3.2 m closed tank, released 0.02 m too deep), all in one process (one JIT compile):

    python bench/heave_study.py --dp 0.02 --variants base awf0 h2 ...

Prints one JSON line per variant (bench/bodies.py's heave_period fields) and saves the series
in runs/heave_study/<variant>_dp<dp>.npz. Wall times: this machine's load at the time.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from bodies import heave  # noqa: E402

HEAVE_VARIANTS = {
    "base": ({}, 0.02),                                        # the old defaults
    "awf0": ({"alpha_wall_factor": 0.0}, 0.02),                # no wall AV (fluid-body too)
    "h2": ({"h_over_dp": 2.0}, 0.02),
    "h2_awf0": ({"h_over_dp": 2.0, "alpha_wall_factor": 0.0}, 0.02),
    "inviscid": ({"alpha": 0.0, "nu": 0.0, "alpha_wall_factor": 0.0}, 0.02),
    "small": ({"h_over_dp": 2.0, "alpha_wall_factor": 0.0}, 0.01),   # half the release
    "c20": ({"h_over_dp": 2.0, "alpha_wall_factor": 0.0, "c0_factor": 20.0}, 0.02),
    "nodelta": ({"h_over_dp": 2.0, "alpha_wall_factor": 0.0, "delta": 0.0}, 0.02),
    "pc": ({"h_over_dp": 2.0, "alpha_wall_factor": 0.0, "integrator": "symplectic_pc"}, 0.02),
}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dp", type=float, default=0.02)
    ap.add_argument("--t-end", type=float, default=1.2)
    ap.add_argument("--variants", nargs="*", default=list(HEAVE_VARIANTS), choices=list(HEAVE_VARIANTS))
    a = ap.parse_args()
    for v in a.variants:
        constants, offset = HEAVE_VARIANTS[v]
        line = heave(a.dp, offset=offset, constants=constants, t_end=a.t_end,
                     save=f"runs/heave_study/{v}_dp{a.dp}.npz")
        print(json.dumps({"variant": v, **line}), flush=True)


if __name__ == "__main__":
    main()
