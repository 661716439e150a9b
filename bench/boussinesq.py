"""Boussinesq far-field model: accuracy and throughput. Prints one JSON object per line.

Questions: (1) how far is the model's linear phase speed from Nwogu's relation and from Airy
at kd = 0.5, 1, 2, 3; (2) does a solitary wave (H/d = 0.1, 50 depths) keep its height and speed;
(3) how close are the harmonics over the measured bar of Dingemans (1994); (4) how many
grid-point updates per second does a step do (4000-point flume, regular waves,
corrector iterations included)? Anchor: FUNWAVE-TVD (Fortran, serial, -O3) does 2.2e5 point
updates/s on a 4000-point 1D flume on this machine kind; goal >= 1e7.

    .venv/bin/python bench/boussinesq.py
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np

from wave_client.boussinesq import BoussinesqModel, airy_celerity, nwogu_celerity
from wave_client.boussinesq.checks import compare_with_measurement, solitary_run, standing_wave_speed

FUNWAVE_TVD_ANCHOR = 2.2e5  # point updates/s, serial Fortran -O3, 4000-point 1D flume
GOAL = 1e7


def emit(**obj) -> None:
    print(json.dumps(obj), flush=True)


def dispersion() -> None:
    depth, ppw = 1.0, 32
    for kd in (0.5, 1.0, 2.0, 3.0):
        c = standing_wave_speed(kd, depth, ppw=ppw)
        c_nw, c_airy = float(nwogu_celerity(kd, depth)), float(airy_celerity(kd, depth))
        emit(bench="boussinesq_dispersion", kd=kd, points_per_wavelength=ppw, c_model=c, c_nwogu=c_nw,
             c_airy=c_airy, rel_error_vs_nwogu=c / c_nw - 1, rel_error_vs_airy=c / c_airy - 1,
             nwogu_rel_error_vs_airy=c_nw / c_airy - 1)


def solitary() -> None:
    for profile in ("kdv", "nwogu"):
        r = solitary_run(0.1, depth=1.0, distance=50.0, profile=profile)
        half = len(r["t"]) // 2
        speed = float(np.polyfit(r["t"][half:], r["x"][half:], 1)[0])
        emit(bench="boussinesq_solitary", initial_profile=profile, H_over_d=0.1, distance_depths=50.0,
             height_rel_error_max=float(np.max(np.abs(r["height"] / r["H"] - 1))),
             height_rel_error_end=float(r["height"][-1] / r["H"] - 1),
             speed_rel_error=speed / r["c"] - 1, c_reference=r["c"],
             speed_rel_error_vs_profile=speed / r["c_profile"] - 1, c_profile=r["c_profile"])


def dingemans() -> None:
    root = Path(__file__).resolve().parents[1]
    r = compare_with_measurement(root / "examples" / "waves" / "dingemans.toml",
                                 root / "tests" / "data" / "dingemans_1994_gauges.csv", still_level=0.8)
    for x, cm, cd in zip(r["x"], r["model"], r["measured"]):
        emit(bench="boussinesq_dingemans_bar", gauge_x_m=x,
             measured_harmonics_mm=[round(v, 3) for v in np.abs(cd) * 1e3],
             model_harmonics_mm=[round(v, 3) for v in np.abs(cm) * 1e3],
             model_over_measured=[round(v, 4) for v in np.abs(cm) / np.abs(cd)])


def throughput(nodes: int = 4000, steps: int = 2000, repeats: int = 5) -> None:
    depth, period, dx = 1.0, 3.0, 0.05
    m = BoussinesqModel(0.0, (nodes - 1) * dx, dx, depth, sponge_left=10.0, sponge_right=10.0)
    m.set_regular_wave(50.0, 0.1, period)
    m.advance_to(5 * period)  # compiled, waves in the flume
    rates = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        m.advance_steps(steps)
        rates.append(nodes * steps / (time.perf_counter() - t0))
    best = max(rates)
    emit(bench="boussinesq_throughput", nodes=nodes, steps=steps, repeats=repeats,
         point_updates_per_s=best, point_updates_per_s_median=float(np.median(rates)),
         step_ms=nodes / best * 1e3, mean_corrector_iterations=m.corrector_stats["mean_iterations"],
         anchor_funwave_tvd=FUNWAVE_TVD_ANCHOR, speedup_vs_anchor=best / FUNWAVE_TVD_ANCHOR,
         goal=GOAL, goal_met=best >= GOAL)


if __name__ == "__main__":
    dispersion()
    solitary()
    dingemans()
    throughput()
