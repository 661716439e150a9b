"""The step (kdk or symplectic_pc) on the GPU for a built ``Simulation``: its state is copied
to the device once, stepped there, and copied back on request.

    stepper = CudaStepper(sim)            # raises RuntimeError (no GPU) / ValueError (scope)
    stepper.advance_steps(100)            # or stepper.advance_to(t_end)
    stepper.to_host()                     # particles, cells and clock back into ``sim``
    stepper.from_host()                   # after the host changed ``sim``'s state: to the device

``Simulation(scene, device="cuda")`` drives one of these (simulation.py); this interface serves
the tests and benchmarks.

A kdk WCSPH step is 11 kernel launches, all queued without a host wait (``gpu_kernels.py``):
kick + drift + binning, the cell count's prefix sum (3), scatter, per-cell ordering, permute
into the twin, wall pass, fluid pass, kick with the guards and reductions, and a one-thread
kernel that computes the next dt on the device. symplectic_pc, particle shifting and Riemann SPH
add or swap kernels of ``gpu_schemes.py`` (``_launches`` is the plan). The host reads two small
arrays (clock and guards) every ``batch`` steps to learn whether the device stopped (t_stop, max_steps or a guard).
``enable_graphs()`` captures two steps into a CUDA graph, replayed with one host call per pair
of steps (the kernels' launch cost in Python is what bounds small cases).

Scope: closed tanks with kdk or symplectic_pc, delta-SPH or Riemann SPH (with or without
MUSCL), Fickian or delta-plus shifting; and, with the kdk delta-SPH step, open ends (the open-end
kernels and launches are ``gpu_open_ends.py``; per coupling window ``load_window`` moves the
boundary data in and ``read_boundaries`` the gauges and counters out) and rigid bodies
(``gpu_bodies.py``; the launch list with either is ``gpu_step_plan.py``). No ISPH:
``unsupported`` names what a scene uses that this step lacks.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..particles import N_FIELDS
from ..state import Cells
from ..riemann import NO_RECONSTRUCTION
from . import gpu_kernels as K
from . import gpu_schemes as S
from . import gpu_step_plan
from .gpu_bodies import BodiesDevice
from .gpu_open_ends import OpenEndsDevice
from . import simulated, unavailable_reason

LAUNCHES_PER_STEP = 11   # kdk WCSPH; a scene's own count: CudaStepper.launches_per_step


def unsupported(sim: Any) -> list[str]:
    """What the scene of ``sim`` uses that the GPU step does not do yet (empty: supported)."""
    out = []
    if sim.scene.scheme.kind == "isph":
        out.append("ISPH")
    if sim.open.active or sim.bodies.active:
        # open ends and bodies have the kdk delta-SPH step's plan only (gpu_step_plan.py)
        what = "open ends" if sim.open.active else "rigid bodies"
        prm = sim.prm
        if sim.scene.constants.integrator != "kdk":
            out.append(f"integrator {sim.scene.constants.integrator} with {what} (only kdk)")
        if prm.shift_a > 0.0:
            out.append(f"particle shifting with {what}")
        if prm.riemann:
            out.append(f"Riemann SPH with {what}")
    if sim.particles.f.dtype != np.float64:
        out.append("float32 storage")
    return out


class CudaStepper:
    """The GPU twin of ``step.run`` for one Simulation; see the module docstring."""

    def __init__(self, sim: Any, batch: int | None = None) -> None:
        reason = unavailable_reason()
        if reason is not None:
            raise RuntimeError(f"device cuda: {reason}")
        missing = unsupported(sim)
        if missing:
            raise ValueError("device cuda: not supported yet: " + ", ".join(missing))
        from numba import cuda

        self._cuda = cuda
        self.sim = sim
        # steps queued between reads of the stop flag (the simulator runs queued no-op steps
        # thread by thread: one at a time there)
        self.batch = int(batch) if batch else (1 if simulated() else 64)
        ps = sim.particles
        # with open ends the kernels run over every slot (gpu_open_ends.py): the count changes
        self.n = int(ps.capacity) if sim.open.active else int(ps.n)
        grid = sim.grid
        self.ncell = grid.ncell
        self.m = self.ncell + 2            # cells, the inactive bin, and the total
        dev = self._to_device
        # the simulator's kernels take numpy arrays (numba-compiled bodies cannot index its
        # array wrappers); on a GPU these are device arrays
        # (f, kind, ids, cell) of each buffer: gpu_kernels.py says why not state.Particles
        self.bufs = [(dev(ps.f), dev(ps.kind), dev(ps.ids), dev(ps.cell)),
                     (dev(ps.f2), dev(ps.kind2), dev(ps.ids2), dev(ps.cell2))]
        self.cur = 0                       # which buffer holds the state
        c = sim.cells
        self.start = dev(c.start)
        self.cursor = dev(np.zeros(self.m, dtype=np.int64))
        self.count = dev(np.zeros(self.m, dtype=np.int64))
        self.order = dev(c.order)
        self.nb = (self.m + K.SCAN_B - 1) // K.SCAN_B
        self.bsum = dev(np.zeros(self.nb, dtype=np.int64))
        self.cells = Cells(self.start, self.cursor, self.order, c.ncx, c.ncz, c.xmin, c.zmin,
                           c.inv_cs, c.reach, c.ncy, c.ymin)
        self.clk = dev(np.zeros(K.N_CLK))
        self.ctl = dev(np.zeros(K.N_CTL, dtype=np.int64))
        self.prm = sim.prm
        self.t = float(sim.t)
        self.dt = float(sim.dt)
        self.steps = 0                     # steps taken on the device since steps0
        self.steps0 = int(sim.steps)       # the Simulation's step count when the state came
        self.v_max = float(sim.v_max)
        self.launches = 0
        self._grid_n = (self.n + K.TPB - 1) // K.TPB
        self._grid_c = (self.ncell + 1 + K.TPB - 1) // K.TPB
        # (symplectic_pc, shifting, Riemann SPH, MUSCL gradients, delta-plus law): the step plan
        prm = sim.prm
        self._scheme = (sim.scene.constants.integrator == "symplectic_pc", prm.shift_a > 0.0,
                        bool(prm.riemann), bool(prm.riemann) and prm.limiter != NO_RECONSTRUCTION,
                        bool(prm.shift_dplus))
        self.open = (OpenEndsDevice(self, sim.open.ends, int(ps.n), int(ps.next_id))
                     if sim.open.active else None)
        self.bodies = BodiesDevice(self, sim.bodies.state) if sim.bodies.active else None
        # the launches of an even and an odd step, configured once (their arguments never change)
        self._plan = [self._launches(0), self._launches(1)]
        self.launches_per_step = len(self._plan[0])
        self._graph = None                 # (enable_graphs) two-step CUDA graphs, if captured
        self.graph_error: str | None = None

    def _to_device(self, a: np.ndarray):
        if simulated():
            return np.array(a, copy=True)
        return self._cuda.to_device(np.ascontiguousarray(a))

    def _to_host(self, a) -> np.ndarray:
        return np.array(a, copy=True) if simulated() else a.copy_to_host()

    def _put(self, dst, src: np.ndarray) -> None:
        if simulated():
            dst[:] = src
        else:
            dst.copy_to_device(src)

    # ------------------------------------------------------------------ stepping
    def _launches(self, parity: int, stream: Any = 0) -> list:
        """The step's kernel launches in order, as (name, configured kernel, args)."""
        if self.open is not None or self.bodies is not None:
            return gpu_step_plan.launches(self, parity, stream)
        ps, ps2 = self.bufs[parity], self.bufs[1 - parity]
        n, prm, cells, clk, ctl = self.n, self.prm, self.cells, self.clk, self.ctl
        gn, tpb, nb, sb, gc = self._grid_n, K.TPB, self.nb, K.SCAN_B, self._grid_c
        count, start, bsum = self.count, self.start, self.bsum
        cursor, order = self.cursor, self.order
        pc, shift, riemann, muscl, dplus = self._scheme
        if pc:   # symplectic_pc sorts first (x^n), then two force passes
            head = [("bin", K.k_bin[gn, tpb, stream], (ps, n, cells, count, ctl))]
        else:
            head = [("kick_drift_bin", K.k_kick_drift_bin[gn, tpb, stream],
                     (ps, n, prm, cells, count, clk, ctl))]
        sort = [
            ("scan_blocks", K.k_scan_blocks[nb, sb, stream], (count, start, bsum, self.m, ctl)),
            ("scan_sums", K.k_scan_sums[1, sb, stream], (bsum, nb, ctl)),
            ("scan_add", K.k_scan_add[nb, sb, stream], (start, bsum, cursor, count, self.m, ctl)),
            ("scatter", K.k_scatter[gn, tpb, stream], (ps, n, cursor, order, ctl)),
            ("cell_order", K.k_cell_order[gc, tpb, stream], (start, order, self.ncell + 1, ctl)),
            ("permute", (S.k_permute_pc if pc else K.k_permute)[gn, tpb, stream],
             (ps, ps2, order, n, ctl)),
        ]
        # step._forces: walls, (MUSCL gradients), fluid
        forces = [("wall", K.k_wall[gn, tpb, stream], (ps2, n, cells, prm, ctl))]
        if muscl:
            forces.append(("muscl_gradients", S.k_muscl_gradients[gn, tpb, stream],
                           (ps2, n, cells, prm, ctl)))
        forces.append(("fluid", (S.k_fluid_riemann if riemann else K.k_fluid)[gn, tpb, stream],
                       (ps2, n, cells, prm, ctl)))
        if pc:
            update = forces + [("predict", S.k_predict[gn, tpb, stream], (ps2, n, prm, clk, ctl))]
            update += forces + [("correct", S.k_correct[gn, tpb, stream], (ps2, n, prm, clk, ctl))]
        else:
            update = forces + [("kick", K.k_kick[gn, tpb, stream], (ps2, n, prm, clk, ctl))]
        # step._shift: after the kick / corrector, on the sorted state
        if shift and dplus:
            update += [("dplus_surface", S.k_dplus_surface[gn, tpb, stream],
                        (ps2, n, cells, prm, clk, ctl)),
                       ("dplus_tangential", S.k_dplus_tangential[gn, tpb, stream],
                        (ps2, n, cells, prm, ctl))]
        elif shift:
            update.append(("shift_fickian", S.k_shift_fickian[gn, tpb, stream],
                           (ps2, n, cells, prm, clk, ctl)))
        if shift:
            update.append(("shift_move", S.k_shift_move[gn, tpb, stream], (ps2, n, ctl)))
        return head + sort + update + [("finish", K.k_finish[1, 1, stream], (prm, clk, ctl))]

    def enable_graphs(self) -> bool:
        """Capture two steps (even + odd buffer parity) into a CUDA graph per starting parity,
        so ``run`` replays a pair of steps with one host call instead of 2 x
        ``launches_per_step`` launches. Call after the kernels have been compiled (a step
        taken). Returns False, with the reason in ``graph_error``, where it fails (and under
        the simulator); the plain launches then stay in use."""
        if simulated():
            self.graph_error = "the simulator has no CUDA graphs"
            return False
        try:
            from cuda.bindings import driver as cu
        except ImportError as exc:
            self.graph_error = f"cuda.bindings: {exc}"
            return False

        def check(res):
            res = res if isinstance(res, tuple) else (res,)
            if res[0] != cu.CUresult.CUDA_SUCCESS:
                raise RuntimeError(f"CUDA graph call failed: {res[0]}")
            return res[1] if len(res) > 1 else None

        stream = self._cuda.stream()
        h = int(stream.handle)
        execs = []
        try:
            for p in (0, 1):
                plan = self._launches(p, stream) + self._launches(1 - p, stream)
                check(cu.cuStreamBeginCapture(
                    h, cu.CUstreamCaptureMode.CU_STREAM_CAPTURE_MODE_RELAXED))
                try:
                    for _, kernel, args in plan:
                        kernel(*args)
                finally:
                    graph = check(cu.cuStreamEndCapture(h))
                execs.append(check(cu.cuGraphInstantiate(graph, 0)))
        except Exception as exc:   # a driver or binding that cannot: keep the plain launches
            self.graph_error = repr(exc)
            return False
        self._graph = (cu, stream, h, execs, check)
        self.graph_error = None
        return True

    def _launch_pairs(self, parity: int, pairs: int) -> None:
        """Replay the two-step graph starting at ``parity`` ``pairs`` times."""
        cu, stream, h, execs, check = self._graph
        g = execs[parity]
        for _ in range(pairs):
            check(cu.cuGraphLaunch(g, h))
        self.launches += 2 * pairs

    def _launch_step(self, parity: int) -> None:
        for _, kernel, args in self._plan[parity]:
            kernel(*args)
        self.launches += len(self._plan[parity])

    def kernel_times(self, steps: int = 5) -> dict[str, float]:
        """Milliseconds per kernel (CUDA events around each launch), mean over ``steps`` real
        steps taken from the current state; a profile, not a throughput figure."""
        cuda = self._cuda
        # the simulator's events take no timing flag (and time nothing of the device)
        event = cuda.event if simulated() else (lambda: cuda.event(timing=True))
        self._begin(math.inf, steps)
        total: dict[str, float] = {}
        for s in range(steps):
            marks = [event()]
            marks[0].record()
            names = []
            for name, kernel, args in self._plan[(self.cur + s) % 2]:
                kernel(*args)
                e = event()
                e.record()
                marks.append(e)
                names.append(name)
            marks[-1].synchronize()
            for k, name in enumerate(names):
                total[name] = total.get(name, 0.0) + marks[k].elapsed_time(marks[k + 1])
        self._end()
        return {k: round(v / steps, 4) for k, v in total.items()}

    def run(self, t_stop: float, max_steps: int) -> tuple[float, float, int, int, int, float]:
        """Steps until t_stop or max_steps or a guard trips (as ``step.run``); returns
        (t, dt_next, steps, status, n_flagged, v_max). The state stays on the device."""
        self._begin(t_stop, max_steps)
        launched = 0
        while launched < max_steps:
            k = min(self.batch, max_steps - launched)
            s = 0
            if self._graph is not None and k >= 2:
                self._launch_pairs((self.cur + launched) % 2, k // 2)
                s = 2 * (k // 2)
            for s in range(s, k):
                self._launch_step((self.cur + launched + s) % 2)
            launched += k
            if self._to_host(self.ctl)[K.STOP] != 0:
                break
        return self._end()

    def _begin(self, t_stop: float, max_steps: int) -> None:
        clk = np.zeros(K.N_CLK)
        clk[K.T], clk[K.DT], clk[K.T_STOP] = self.t, self.dt, t_stop
        ctl = np.zeros(K.N_CTL, dtype=np.int64)
        ctl[K.MAX_STEPS] = max_steps
        self._put(self.clk, clk)
        self._put(self.ctl, ctl)
        K.k_begin[1, 1](self.clk, self.ctl)

    def _end(self) -> tuple[float, float, int, int, int, float]:
        """Read the device's clock and guards after a run call; the host follows its steps."""
        clk = self._to_host(self.clk)
        ctl = self._to_host(self.ctl)
        done = int(ctl[K.STEPS])
        self.cur = (self.cur + done) % 2
        self.steps += done
        self.t, self.dt = float(clk[K.T]), float(clk[K.DT])
        if done:
            self.v_max = math.sqrt(clk[K.V2LAST])
        return self.t, self.dt, done, int(ctl[K.STATUS]), int(ctl[K.N_FLAG]), self.v_max

    def advance_steps(self, n_steps: int) -> int:
        """Take ``n_steps`` steps (fewer if a guard trips); returns the status."""
        return self.run(math.inf, int(n_steps))[3]

    def advance_to(self, t_end: float, max_steps: int = 2**62) -> int:
        """Step until t = t_end (the last step shortened to land on it); returns the status."""
        return self.run(float(t_end), max_steps)[3]

    # ------------------------------------------------------------------ state
    def synchronize(self) -> None:
        if not simulated():
            self._cuda.synchronize()
            if self._graph is not None:
                self._graph[1].synchronize()

    def to_host(self) -> None:
        """Copy the device state into the Simulation: the live particle buffer (f, kind, ids,
        cell; not the twin, which the next step's permute rebuilds), the cell starts (the live
        buffer is in cell order: the host's probes walk it), clock and step count."""
        sim = self.sim
        ps = sim.particles
        for host, dev in zip((ps.f, ps.kind, ps.ids, ps.cell), self.bufs[self.cur]):
            host[:] = self._to_host(dev)
        sim.cells.start[:] = self._to_host(self.start)
        if self.open is not None:
            ps.n = self.open.n_live()
            ps.next_id = int(self.open.read()["next_id"][0])
        if self.bodies is not None:
            self.bodies.read()
        sim.t, sim.dt, sim.v_max = self.t, self.dt, self.v_max
        sim.steps = self.steps0 + self.steps

    def from_host(self) -> None:
        """Copy the Simulation's state to the device after the host changed it (particles
        excluded by a guard, a restored checkpoint, new Params): its live buffer and cell starts
        into the device's first buffer, its clock, count and Params. Graphs captured for another
        count or other Params are dropped (``enable_graphs`` captures them again)."""
        sim = self.sim
        ps = sim.particles
        for dev, host in zip(self.bufs[0], (ps.f, ps.kind, ps.ids, ps.cell)):
            self._put(dev, host)
        self._put(self.start, sim.cells.start)
        self.cur = 0
        if self.open is not None or self.bodies is not None:
            # their device state is rebuilt from the host's (which to_host kept current); the
            # kernels of a scene with open ends run over every slot, so the count stays capacity
            self.open = (OpenEndsDevice(self, sim.open.ends, int(ps.n), int(ps.next_id))
                         if self.open is not None else None)
            self.bodies = BodiesDevice(self, sim.bodies.state) if self.bodies is not None else None
            self.prm = sim.prm
            self._plan = [self._launches(0), self._launches(1)]
            self._graph = None
            self.graph_error = None
        elif int(ps.n) != self.n or sim.prm != self.prm:
            self.n = int(ps.n)
            self.prm = sim.prm
            self._grid_n = (self.n + K.TPB - 1) // K.TPB
            self._plan = [self._launches(0), self._launches(1)]
            self._graph = None
            self.graph_error = None
        self.t, self.dt, self.v_max = float(sim.t), float(sim.dt), float(sim.v_max)
        self.steps0 = int(sim.steps)
        self.steps = 0

    # ------------------------------------------------------------------ open ends
    def load_window(self) -> None:
        """Copy the window's boundary data to the device after ``sim.open.load_window`` filled
        them (``Simulation.advance_window`` does; a few small arrays per window)."""
        if self.open is not None:
            self.open.load_window()

    def read_boundaries(self) -> None:
        """Copy the boundary gauges, surfaces, counters and filter state from the device into
        ``sim.open`` (small arrays), so ``sim.boundary_gauges()`` / ``boundary_counts()`` read
        the device's; the particles stay there."""
        if self.open is not None:
            self.sim.particles.next_id = int(self.open.read()["next_id"][0])

    def device_bytes(self) -> int:
        """Bytes of the particle buffers on the device."""
        cap = self.sim.particles.capacity
        return 2 * cap * (8 * N_FIELDS + 1 + 8 + 8)
