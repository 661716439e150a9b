"""A deterministic stand-in for the coupled SPH engine (a TEST DOUBLE, no physics).

It follows the engine contract of server/engine.py exactly as a real one must: sub-steps of
dt_sph from t0 to t1 with boundary values interpolated linearly in time between the values in
force at t0 and those set for t1; checkpoint/goback restore clock and boundary values. Its
"gauges" report the node-mean of the imposed eta and u at the last sub-step (gauge named
`dry_*` is always dry), which lets tests check the interpolation and the bookkeeping.
"""

from __future__ import annotations

import copy
import dataclasses
import math
import threading
import time

import numpy as np

from server.engine import EngineNodes, Measurement, SceneSummary, SolveCancelled
from server.schemas import RunRequest
from sph_core.simulation import UnstableError


class EngineDouble:
    def __init__(self, request: RunRequest, dt_sph: float = 1e-3, solve_delay: float = 0.0,
                 unstable_after: float | None = None, gate: threading.Event | None = None,
                 honours_cancel: bool = False) -> None:
        scene = request.scene
        swl = scene.still_water_level if scene.still_water_level is not None else max(
            b.z1 for b in scene.water_blocks)
        depth = swl - scene.tank.z0
        self.summary = SceneSummary(g=scene.constants.g, depth=depth, still_water_level=swl,
                                    z_ref=request.coupling.z_ref if request.coupling.z_ref is not None
                                    else -depth / 2, t_start=0.0, t_end=scene.t_end, dt_sph=dt_sph)
        n = max(int(round(depth / scene.dp)), 2)
        gauges = [p for p in scene.probes if p.kind == "elevation"]
        self._nodes = EngineNodes(np.full(n, scene.tank.x0), np.linspace(-depth, 0.0, n),
                                    np.zeros(n, np.uint32), np.array([p.x for p in gauges]),
                                    [p.name for p in gauges])
        self.t, self.steps, self.n_particles = 0.0, 0, 1000
        self.solve_delay, self.unstable_after = solve_delay, unstable_after
        self.gate = gate  # a solve waits until the test sets it (no timing guess under load)
        if honours_cancel:  # as the flume engine: the server hands it the run's cancel flag
            self.cancel: threading.Event | None = None
        self.cancelled_solves = 0
        self.in_force = {"u": np.zeros(n), "w": np.zeros(n), "eta": np.zeros(n)}
        self.pending: tuple[float, float, dict[str, np.ndarray]] | None = None
        self.imposed: list[tuple[float, float, float]] = []  # (t, mean u, mean eta) per sub-step
        self._saved = None
        self.closed = False

    def nodes(self) -> EngineNodes:
        return self._nodes

    def set_window(self, t0, t1, u, w, eta) -> None:
        self.pending = (t0, t1, {"u": np.array(u), "w": np.array(w), "eta": np.array(eta)})

    def solve_window(self) -> Measurement:
        t0, t1, new = self.pending
        if self.solve_delay:
            time.sleep(self.solve_delay)
        deadline = time.monotonic() + 60.0
        while self.gate is not None and not self.gate.wait(0.01):
            if getattr(self, "cancel", None) is not None and self.cancel.is_set():
                self.cancelled_solves += 1
                raise SolveCancelled()
            if time.monotonic() > deadline:
                raise RuntimeError("test double: the gate was never opened")
        k = max(1, math.ceil((t1 - t0) / self.summary.dt_sph - 1e-9))
        for i in range(1, k + 1):
            s = i / k
            vals = {q: (1 - s) * self.in_force[q] + s * new[q] for q in new}
            self.imposed.append((t0 + s * (t1 - t0), float(vals["u"].mean()), float(vals["eta"].mean())))
        self.in_force, self.pending = new, None
        self.t, self.steps = t1, self.steps + k
        if self.unstable_after is not None and self.t > self.unstable_after:
            raise UnstableError(self.steps, self.t, "density out of band (test double)")
        m = self.measure()
        return Measurement(m.eta, m.wet, m.u_ref, m.w_ref, steps=k)

    def measure(self) -> Measurement:
        g = self._nodes.gauge_x.size
        wet = np.array([not name.startswith("dry") for name in self._nodes.gauge_names], dtype=bool)
        return Measurement(np.full(g, self.in_force["eta"].mean()), wet,
                           np.full(g, self.in_force["u"].mean()), np.zeros(g))

    def checkpoint(self) -> None:
        self._saved = copy.deepcopy((self.t, self.steps, self.in_force, len(self.imposed)))

    def goback(self) -> None:
        self.t, self.steps, self.in_force, n = copy.deepcopy(self._saved)
        del self.imposed[n:]
        self.pending = None

    def save_state(self, path) -> None:
        with open(path, "wb") as f:  # an npz without pickle, as the real engine's
            np.savez(f, t=self.t, steps=self.steps, **{f"in_force_{q}": v for q, v in self.in_force.items()})

    def load_state(self, path) -> None:
        with np.load(path, allow_pickle=False) as z:
            self.t, self.steps = float(z["t"]), int(z["steps"])
            self.in_force = {k.removeprefix("in_force_"): z[k] for k in z.files if k.startswith("in_force_")}
        self.summary = dataclasses.replace(self.summary, t_start=self.t)

    def stability(self) -> dict[str, float]:
        return {"dt": self.summary.dt_sph}

    def close(self) -> None:
        self.closed = True
