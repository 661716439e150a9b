"""Open ends (inlet/outlet buffers) in the GPU kdk step: the kernels and their device state.

The particles stay on the device; a coupling window moves only the boundary data in
(``OpenEndsDevice.load_window``: win_t, win_u, win_w, win_eta, win_etag) and the gauges,
surfaces and counters out (``OpenEndsDevice.read``). Every kernel calls the CPU step's own
per-slot functions of ``sph_core/open_boundary.py`` (``boundary_state``, ``buffer_particle``,
``transition_of``, ``extrapolated_state``, ``line_density``, ``crossing``), so the physics has
one source for both devices.

With open ends the kernels run over every slot of the buffers (the capacity): free slots are
INACTIVE and every pass skips them; the sort bins them into the extra cell and puts them last,
so the live particles sit in slots [0, n) in the CPU's order, and the clones of a step go to
slots n, n + 1, ... in slot order of their originals, as the CPU's serial append does: an
exclusive prefix sum over the clone flags (``gpu_kernels``' scan) gives each its slot and id.

The open-end launches in a step (``gpu_step_plan.py``; the CPU's ``step._step_kdk`` with ``ends``):

    k_kick_drift              kick + drift (fluid)                     wcsph.kdk_kick_drift
    k_boundary  (1 thread)    window weight, z_s and du per end         update_buffers
    k_buffers                 buffers imposed and moved                 buffer_update
    k_mark                    crossing of each slot, clone flags        buffer_transitions
    scan (3)                  slots of the clones
    k_apply                   kinds, counters, clones (or ST_CAPACITY)  buffer_transitions
    k_bin, scan (3), scatter, cell_order (live cells), permute          sort_by_cell
    k_extrapolate             ghost-node pressure; live count           extrapolate_buffers
    k_wall, k_fluid, k_kick                                             forces, kdk_kick
    k_gauge_line              line density per (end, point)             measure_boundaries
    k_gauge     (1 thread)    surface of each gauge                     measure_boundaries
    k_finish
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numba import cuda

from ..open_boundary import (C_CREATED, C_IN, C_OUT, C_REMOVED, T_FAR_OUT, T_IDLE_OUT, T_NONE,
                             T_TO_BUFFER, T_TO_FLUID, boundary_state, buffer_particle, crossing,
                             extrapolated_state, gauge_points, line_density, transition_of,
                             window_weight)
from ..particles import FLUID, INACTIVE
from ..wcsph import ST_CAPACITY
from . import gpu_kernels as K
from .gpu_kernels import _view
from .per_particle import kick_drift_particle

# the float scratch oe[F]: this step's window weight and each end's surface and correction
R, ZS0, DU0, ZS1, DU1 = range(5)
N_OEF = 5
# the int scratch oe[I]: live slots after the last sort, next id at the step's start
N_LIVE, ID0 = range(2)
N_OEI = 2
# the scratch tuple oe (a tuple: the simulator hands numpy arrays inside tuples to compiled
# code untouched; docs/developer/gpu.md)
ACT, KNEW, FLAG, OFF, F, I, DENS = range(7)

# the window's arrays loaded per window, and the state read back
END_FIELDS_WINDOW = ("win_t", "win_u", "win_w", "win_eta", "win_etag")
END_FIELDS_READ = ("eta_meas", "zs", "counters", "next_id", "filt_x")


@K.kernel
def k_kick_drift(buf, n, prm, clk, ctl):
    """kdk first half-kick + drift of the fluid (binning comes after the buffers moved)."""
    if ctl[K.STOP] != 0:
        return
    i = cuda.grid(1)
    if i < n and buf[1][i] == FLUID:
        if kick_drift_particle(i, _view(buf), clk[K.DTS], prm):
            cuda.atomic.add(ctl, K.N_OUT, 1)


@K.kernel
def k_boundary(ends, clk, ctl, oe):
    """update_buffers' per-end part (one thread): the window weight at t + dt, each end's
    surface and absorption correction (the filter state advanced by dt)."""
    if cuda.grid(1) != 0 or ctl[K.STOP] != 0:
        return
    dt = clk[K.DTS]
    f = oe[F]
    r = window_weight(clk[K.T] + dt, ends.win_t)
    zs0, du0 = boundary_state(0, r, dt, ends)
    zs1, du1 = boundary_state(1, r, dt, ends)
    ends.zs[0] = zs0
    ends.zs[1] = zs1
    f[R] = r
    f[ZS0] = zs0
    f[DU0] = du0
    f[ZS1] = zs1
    f[DU1] = du1


@K.kernel
def k_buffers(buf, n, ends, prm, clk, ctl, oe):
    """buffer_update: every buffer particle imposed, moved, (de)activated."""
    if ctl[K.STOP] != 0:
        return
    i = cuda.grid(1)
    if i < n:
        ps = _view(buf)
        f = oe[F]
        b, u, w, xi, zi, k, rho, p = buffer_particle(i, ps, clk[K.DTS], f[R], f[ZS0], f[DU0],
                                                     f[ZS1], f[DU1], ends, prm)
        if b >= 0:
            ps.vx[i] = u
            ps.vz[i] = w
            ps.x[i] = xi
            ps.z[i] = zi
            ps.kind[i] = k
            ps.rho[i] = rho
            ps.p[i] = p
            ps.drho[i] = 0.0
            ps.ax[i] = 0.0
            ps.az[i] = 0.0


@K.kernel
def k_mark(buf, n, ends, ctl, oe):
    """Each slot's crossing (transition_of) and its clone flag; thread 0 keeps the next id."""
    if ctl[K.STOP] != 0:
        return
    i = cuda.grid(1)
    if i == 0:
        oe[I][ID0] = ends.next_id[0]
    if i < n:
        f = oe[F]
        act, b, knew = transition_of(i, _view(buf), ends, f[R], f[ZS0], f[DU0], f[ZS1], f[DU1])
        oe[ACT][i] = act * 2 + b if act != T_NONE else 0
        oe[KNEW][i] = knew
        oe[FLAG][i] = 1 if act == T_TO_FLUID or act == T_IDLE_OUT else 0
    elif i == n:
        oe[FLAG][i] = 0


@K.kernel
def k_apply(buf, n, ends, ctl, oe):
    """buffer_transitions: the new kinds, the counters and the clones at slots n_live + their
    prefix sum (the CPU's serial order); the run stops with ST_CAPACITY where they overflow."""
    if ctl[K.STOP] != 0:
        return
    i = cuda.grid(1)
    off = oe[OFF]
    n_live = oe[I][N_LIVE]
    total = off[n]
    if n_live + total > ends.capacity:
        if i == 0:
            ctl[K.STOP] = 1
            ctl[K.STATUS] = ST_CAPACITY
            ctl[K.N_FLAG] = n_live
        return
    if i == 0:
        ends.next_id[0] = oe[I][ID0] + total
    if i >= n:
        return
    code = oe[ACT][i]
    if code == 0:
        return
    act = code // 2
    b = code - 2 * act
    ps = _view(buf)
    if act == T_TO_BUFFER:
        cuda.atomic.add(ends.counters, (b, C_OUT), 1)
    elif act == T_FAR_OUT:
        cuda.atomic.add(ends.counters, (b, C_REMOVED), 1)
    else:
        j = n_live + off[i]
        fr = ps.f
        for row in range(fr.shape[0]):
            fr[row, j] = fr[row, i]
        ps.x[j] = ps.x[i] + ends.nx[b] * ends.length[b]
        ps.kind[j] = ps.kind[i]
        ps.ids[j] = oe[I][ID0] + off[i]
        cuda.atomic.add(ends.counters, (b, C_CREATED), 1)
        cuda.atomic.add(ends.counters, (b, C_IN if act == T_TO_FLUID else C_REMOVED), 1)
    ps.kind[i] = oe[KNEW][i]


@K.kernel
def k_extrapolate(buf, n, cells, ends, prm, ctl, oe):
    """buffer_extrapolate (after the sort); thread 0 records the live count."""
    if ctl[K.STOP] != 0:
        return
    i = cuda.grid(1)
    if i == 0:
        oe[I][N_LIVE] = cells.start[cells.ncx * cells.ncy * cells.ncz]
    if i < n:
        ps = _view(buf)
        ok, p, rho = extrapolated_state(i, ps, cells, ends, prm)
        if ok:
            ps.p[i] = p
            ps.rho[i] = rho


@K.kernel
def k_gauge_line(buf, cells, ends, prm, ctl, oe):
    """measure_boundaries' line densities: one thread per (end, point)."""
    if ctl[K.STOP] != 0:
        return
    g = cuda.grid(1)
    dens = oe[DENS]
    npt = dens.shape[1]
    if g < 2 * npt:
        b = g // npt
        k = g - b * npt
        if ends.on[b] and k < gauge_points(ends, b):
            dens[b, k] = line_density(_view(buf), cells, ends.x_gauge[b], ends.y_gauge,
                                      ends.z_bed[b] + k * ends.dz_gauge, prm)


@K.kernel
def k_gauge(ends, prm, ctl, oe):
    """measure_boundaries (one thread): each gauge's surface from its line, top down."""
    if cuda.grid(1) != 0 or ctl[K.STOP] != 0:
        return
    dens = oe[DENS]
    level = 0.5 * prm.rho0
    for b in range(2):
        if ends.on[b]:
            nz = gauge_points(ends, b)
            zs = np.nan
            prev = 0.0
            for k in range(nz - 1, -1, -1):
                zk = ends.z_bed[b] + k * ends.dz_gauge
                s = dens[b, k]
                if s >= level:
                    zs = crossing(k, nz, zk, s, prev, ends.dz_gauge, level)
                    break
                prev = s
            ends.eta_meas[b] = zs - ends.swl[b]


class OpenEndsDevice:
    """The open ends' state on the device for a CudaStepper, and the step's launches."""

    def __init__(self, st: Any, ends: Any, n_live: int, next_id: int) -> None:
        dev = st._to_device
        self.st = st
        # the kernels run over every slot: the host's free slots may hold stale kinds
        kind = np.array(st.sim.particles.kind, copy=True)
        kind[n_live:] = INACTIVE
        st._put(st.bufs[st.cur][1], kind)
        self.host = ends
        self.ends = ends._replace(**{k: dev(v) for k, v in ends._asdict().items()
                                     if isinstance(v, np.ndarray)})
        st._put(self.ends.next_id, np.array([next_id], dtype=np.int64))
        cap = int(ends.capacity)
        npt = max(int((ends.z_top[b] - ends.z_bed[b]) / ends.dz_gauge) + 1
                  for b in range(2) if ends.on[b])
        oei = np.zeros(N_OEI, dtype=np.int64)
        oei[N_LIVE] = n_live
        self.oe = (dev(np.zeros(cap, dtype=np.int64)), dev(np.zeros(cap, dtype=np.int8)),
                   dev(np.zeros(cap + 1, dtype=np.int64)), dev(np.zeros(cap + 1, dtype=np.int64)),
                   dev(np.zeros(N_OEF)), dev(oei), dev(np.zeros((2, npt))))
        self.m = cap + 1                   # scanned: flags of every slot and the total
        self.nb = (self.m + K.SCAN_B - 1) // K.SCAN_B
        self.bsum = dev(np.zeros(self.nb, dtype=np.int64))
        self.cursor = dev(np.zeros(self.m, dtype=np.int64))
        self.npt = npt

    def load_window(self, ends: Any | None = None) -> None:
        """Copy a window's boundary data (``OpenBoundaries.load_window`` filled them in the
        host OpenEnds ``ends``, default the Simulation's) to the device: a few small arrays."""
        src = self.host if ends is None else ends
        for k in END_FIELDS_WINDOW:
            self.st._put(getattr(self.ends, k), np.ascontiguousarray(getattr(src, k)))

    def read(self) -> dict[str, np.ndarray]:
        """The measured state back from the device into the host OpenEnds (and returned):
        eta_meas (gauges), zs, counters, next_id, filt_x."""
        out = {}
        for k in END_FIELDS_READ:
            v = self.st._to_host(getattr(self.ends, k))
            getattr(self.host, k)[:] = v
            out[k] = v
        return out

    def n_live(self) -> int:
        """Live slots after the last sort on the device (the Simulation's ``particles.n``)."""
        return int(self.st._to_host(self.oe[I])[N_LIVE])
