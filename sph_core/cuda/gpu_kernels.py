"""CUDA kernels of the GPU step: thin shells around the per-particle bodies of ``bodies.py``.

One thread per particle slot (or per cell, or per scan element). Every kernel first reads the
device's stop flag ``ctl[STOP]`` and returns at once when it is set, so the host can queue many
steps without waiting: a step whose guard trips (or that reaches t_stop) stops all the kernels
queued after it, and the host learns of it at its next read of ``ctl``.

Device scalars (two small arrays, so dt and the guards never leave the GPU during a run):
    clk (float64): T, DT (next stable dt), DTS (this step's dt), T_STOP, V2, A2, RMAX (this
                   step's reductions), V2LAST (max |v|^2 of the last completed step)
    ctl (int64):   STOP, STATUS, N_FLAG, STEPS, MAX_STEPS, N_BAD, N_BAND, N_OUT, LAST

A particle buffer reaches a kernel as the tuple ``buf = (f, kind, ids, cell)`` and the kernel
builds the named views (``state.Particles``) from it: passing the 33-array NamedTuple itself
would make ~260 kernel parameters (seven per array) per buffer, marshalled in Python at every
launch.
"""

from __future__ import annotations

from numba import cuda, float64, int64, njit, types

from ..particles import FLUID, N_SORTED_KDK, WALL
from ..state import particles_view
from ..wcsph import (ST_DENSITY, ST_LEFT_DOMAIN, ST_NONFINITE, ST_REACHED_T, ST_STEP_LIMIT,
                     adami_state, fluid_rates, stable_dt)
from ..terms import fluid_consts, fluid_i
from . import lock_simulator_shared_arrays, simulated

# every callee of a kernel is inlined (the form compile_ptx verifies without a GPU): inlined
# twins of the two plain @njit helpers the fluid pass takes (the same source)
_fluid_consts = njit(inline="always")(fluid_consts.py_func)
_fluid_i = njit(inline="always")(fluid_i.py_func)
from .per_particle import cell_of, kick_drift_particle, kick_particle, permute_slot

T, DT, DTS, T_STOP, V2, A2, RMAX, V2LAST = range(8)
N_CLK = 8
STOP, STATUS, N_FLAG, STEPS, MAX_STEPS, N_BAD, N_BAND, N_OUT, LAST = range(9)
N_CTL = 9

# the simulator's shared arrays made thread-safe (lock_simulator_shared_arrays says why)
if simulated():
    lock_simulator_shared_arrays()

# threads per block; the simulator runs each thread as a Python thread, so it gets small blocks
TPB = 32 if simulated() else 256
SCAN_B = 64 if simulated() else 1024   # elements per block of the cell-count prefix sum


class _NoneArgs:
    """numba-cuda's launch marshals no None, and a 2D step's ``Params.three`` and
    ``Cells.three`` are None (2D is decided when compiled: terms.py): such a field goes in as
    the null pointer numba-cuda's data model passes for it (OpaqueModel: one i8* parameter).
    The simulator takes None as it is."""

    def prepare_args(self, ty, val, **kwargs):
        if isinstance(ty, types.NoneType):
            return types.CPointer(types.int8), 0
        return ty, val


def kernel(fn):
    """``fn`` as a CUDA kernel whose tuple arguments may hold None (``_NoneArgs``): every
    kernel of the step is made here."""
    return cuda.jit(fn) if simulated() else cuda.jit(extensions=[_NoneArgs()])(fn)


def _schedule_py(clk, ctl):
    """Stop at t_stop or max_steps, else set this step's dt (clamped to land on t_stop)."""
    t = clk[T]
    if t >= clk[T_STOP]:
        ctl[STOP] = 1
        ctl[STATUS] = ST_REACHED_T
        return
    if ctl[STEPS] >= ctl[MAX_STEPS]:
        ctl[STOP] = 1
        ctl[STATUS] = ST_STEP_LIMIT
        return
    dts = clk[DT]
    ctl[LAST] = 0
    if t + dts >= clk[T_STOP]:
        dts = clk[T_STOP] - t
        ctl[LAST] = 1
    clk[DTS] = dts


def _view_py(buf):
    """The named row views (state.Particles) of the buffer tuple (f, kind, ids, cell)."""
    return particles_view(buf[0], buf[1], buf[2], buf[3])


def _stable_dt_py(v2max, a2max, rmax, prm):
    return stable_dt(v2max, a2max, rmax, prm)


# device functions on the GPU (inlined: numba-cuda compiles an inlined @njit callee for the
# device; docs/developer/gpu.md). Under the simulator they stay Python: clk/ctl are its array
# wrappers there, which compiled code cannot take.
if simulated():
    _schedule = _schedule_py
    _view = _view_py
    _stable_dt = _stable_dt_py
else:
    _schedule = njit(inline="always")(_schedule_py)
    _particles_view = njit(inline="always")(particles_view)

    @njit(inline="always")
    def _view(buf):
        return _particles_view(buf[0], buf[1], buf[2], buf[3])

    _stable_dt = njit(inline="always")(stable_dt.py_func)


@kernel
def k_begin(clk, ctl):
    """Start a run call: clear the stop flag and schedule the first step."""
    if cuda.grid(1) == 0:
        ctl[STOP] = 0
        ctl[STATUS] = ST_REACHED_T
        _schedule(clk, ctl)


@kernel
def k_finish(prm, clk, ctl):
    """End of a step (one thread): the clock, the verdict (step._verdict), the next dt
    (wcsph.stable_dt; unchanged after a tripped guard, as in step.run), the reductions cleared,
    the next step scheduled."""
    if cuda.grid(1) != 0 or ctl[STOP] != 0:
        return
    clk[T] = clk[T_STOP] if ctl[LAST] != 0 else clk[T] + clk[DTS]
    ctl[STEPS] += 1
    v2 = clk[V2]
    clk[V2LAST] = v2
    status = ST_REACHED_T
    flag = 0
    if ctl[N_BAD] > 0:
        status = ST_NONFINITE
        flag = ctl[N_BAD]
    elif ctl[N_OUT] > 0:
        status = ST_LEFT_DOMAIN
        flag = ctl[N_OUT]
    elif ctl[N_BAND] > 0:
        status = ST_DENSITY
        flag = ctl[N_BAND]
    if status == ST_REACHED_T:
        # a step whose guard trips keeps its dt for the next, as step.run does (the host may
        # exclude particles and go on)
        clk[DT] = _stable_dt(v2, clk[A2], clk[RMAX], prm)
    ctl[N_BAD] = 0
    ctl[N_BAND] = 0
    ctl[N_OUT] = 0
    clk[V2] = 0.0
    clk[A2] = 0.0
    clk[RMAX] = 0.0
    if status != ST_REACHED_T:
        ctl[STOP] = 1
        ctl[STATUS] = status
        ctl[N_FLAG] = flag
        return
    _schedule(clk, ctl)


@kernel
def k_kick_drift_bin(buf, n, prm, cells, count, clk, ctl):
    """kdk first half-kick + drift (fluid), then the cell of every slot and its count."""
    if ctl[STOP] != 0:
        return
    i = cuda.grid(1)
    if i < n:
        ps = _view(buf)
        if ps.kind[i] == FLUID:
            if kick_drift_particle(i, ps, clk[DTS], prm):
                cuda.atomic.add(ctl, N_OUT, 1)
        c = cell_of(i, ps, cells)
        ps.cell[i] = c
        cuda.atomic.add(count, c, 1)


@cuda.jit(device=True)
def _block_scan(s, t, v):
    """Inclusive prefix sum (Hillis-Steele) of the block's shared array s, thread t's entry v."""
    s[t] = v
    cuda.syncthreads()
    off = 1
    while off < SCAN_B:
        a = s[t - off] if t >= off else 0
        cuda.syncthreads()
        s[t] += a
        cuda.syncthreads()
        off *= 2


@kernel
def k_bin(buf, n, cells, count, ctl):
    """The cell of every slot and its count (compute_cells + the counting sort's counts): the
    sort's first launch where kick and drift are not fused with it (symplectic_pc, open ends,
    bodies)."""
    if ctl[STOP] != 0:
        return
    i = cuda.grid(1)
    if i < n:
        ps = _view(buf)
        c = cell_of(i, ps, cells)
        ps.cell[i] = c
        cuda.atomic.add(count, c, 1)


@kernel
def k_scan_blocks(count, start, bsum, m, ctl):
    """Exclusive prefix sum of count[0:m] within blocks of SCAN_B (Hillis-Steele in shared
    memory); each block's total goes to bsum."""
    if ctl[STOP] != 0:
        return
    s = cuda.shared.array(SCAN_B, int64)
    t = cuda.threadIdx.x
    g = cuda.blockIdx.x * SCAN_B + t
    v = count[g] if g < m else 0
    _block_scan(s, t, v)
    if g < m:
        start[g] = s[t] - v
    if t == SCAN_B - 1:
        bsum[cuda.blockIdx.x] = s[t]


@kernel
def k_scan_sums(bsum, nb, ctl):
    """Exclusive prefix sum of the block totals bsum[0:nb] (one block, chunks of SCAN_B)."""
    if ctl[STOP] != 0:
        return
    s = cuda.shared.array(SCAN_B, int64)
    t = cuda.threadIdx.x
    carry = 0
    base = 0
    while base < nb:
        g = base + t
        v = bsum[g] if g < nb else 0
        _block_scan(s, t, v)
        if g < nb:
            bsum[g] = carry + s[t] - v
        carry += s[SCAN_B - 1]
        cuda.syncthreads()
        base += SCAN_B


@kernel
def k_scan_add(start, bsum, cursor, count, m, ctl):
    """Add the block offsets: start = first slot of each cell; cursor = start; counts cleared."""
    if ctl[STOP] != 0:
        return
    g = cuda.grid(1)
    if g < m:
        v = start[g] + bsum[g // SCAN_B]
        start[g] = v
        cursor[g] = v
        count[g] = 0


@kernel
def k_scatter(buf, n, cursor, order, ctl):
    """order[k] = slot that goes to position k (unordered within a cell)."""
    if ctl[STOP] != 0:
        return
    i = cuda.grid(1)
    if i < n:
        k = cuda.atomic.add(cursor, buf[3][i], 1)
        order[k] = i


@kernel
def k_cell_order(start, order, ncells, ctl):
    """Sort each cell's slots by index (insertion sort, a few per cell), so the order is the
    stable counting sort's of neighbours.counting_sort, whatever order the atomics gave."""
    if ctl[STOP] != 0:
        return
    c = cuda.grid(1)
    if c < ncells:
        a = start[c]
        b = start[c + 1]
        for k in range(a + 1, b):
            v = order[k]
            q = k - 1
            while q >= a and order[q] > v:
                order[q + 1] = order[q]
                q -= 1
            order[q + 1] = v


def _named_kernel(fn, name, doc):
    """fn as the CUDA kernel ``name`` (its __name__, __qualname__ and docstring set first)."""
    fn.__name__ = fn.__qualname__ = name
    fn.__doc__ = doc
    return kernel(fn)


def permute_kernel(name, nrows, doc):
    """The kernel of neighbours.permute for buffers of ``nrows`` carried rows (k_permute,
    gpu_schemes.k_permute_pc): sorted position k gathers slot order[k]'s rows, kind, ids and
    cell from the buffer into its twin."""
    def k_permute(buf, buf2, order, n, ctl):
        if ctl[STOP] != 0:
            return
        k = cuda.grid(1)
        if k < n:
            permute_slot(buf, buf2, order[k], k, nrows)
    return _named_kernel(k_permute, name, doc)


k_permute = permute_kernel(
    "k_permute", N_SORTED_KDK,
    """neighbours.permute: gather the carried rows, kind, ids and cell into the twin.""")


@kernel
def k_wall(buf, n, cells, prm, ctl):
    """wcsph.wall_pass (Adami walls)."""
    if ctl[STOP] != 0:
        return
    i = cuda.grid(1)
    if i < n and buf[1][i] == WALL:
        ps = _view(buf)
        ps.p[i], ps.rho[i], ps.vwx[i], ps.vwy[i], ps.vwz[i] = adami_state(i, ps, cells, prm)


def fluid_kernel(name, riemann, doc):
    """The kernel of wcsph.fluid_pass with ``riemann`` None (delta-SPH, k_fluid) or True
    (Riemann SPH, gpu_schemes.k_fluid_riemann): wcsph.fluid_rates of every fluid slot."""
    def k_fluid(buf, n, cells, prm, ctl):
        if ctl[STOP] != 0:
            return
        i = cuda.grid(1)
        if i < n and buf[1][i] == FLUID:
            ps = _view(buf)
            k = _fluid_consts(prm)
            (ps.ax[i], ps.ay[i], ps.az[i], ps.drho[i], ps.pw[i], ps.dvnx[i], ps.dvny[i],
             ps.dvnz[i]) = fluid_rates(i, ps, cells, prm, riemann, k, _fluid_i(i, ps, k))
    return _named_kernel(k_fluid, name, doc)


k_fluid = fluid_kernel("k_fluid", None, """wcsph.fluid_pass (delta-SPH form).""")


def _block_max_py(clk, v2, a2, r):
    """Block max-reduction of each thread's (|v|^2, |a|^2, rho) in shared memory, thread 0's
    result into clk[V2], clk[A2], clk[RMAX] (one atomic each per block): the kick's and the
    corrector's reductions (every thread of the block calls it: it synchronises)."""
    sv = cuda.shared.array(TPB, float64)
    sa = cuda.shared.array(TPB, float64)
    sr = cuda.shared.array(TPB, float64)
    t = cuda.threadIdx.x
    sv[t] = v2
    sa[t] = a2
    sr[t] = r
    cuda.syncthreads()
    half = TPB // 2
    while half > 0:
        if t < half:
            sv[t] = max(sv[t], sv[t + half])
            sa[t] = max(sa[t], sa[t + half])
            sr[t] = max(sr[t], sr[t + half])
        cuda.syncthreads()
        half //= 2
    if t == 0:
        cuda.atomic.max(clk, V2, sv[0])
        cuda.atomic.max(clk, A2, sa[0])
        cuda.atomic.max(clk, RMAX, sr[0])


# Under the simulator a device function (the simulator gives it the block's shared memory and
# barriers, as it does to _block_scan); on the GPU an inlined callee, the form compile_ptx
# verifies without a GPU (docs/developer/gpu.md; k_kick and k_correct compile to sm_90 PTX).
_block_max = (cuda.jit(device=True)(_block_max_py) if simulated()
              else njit(inline="always")(_block_max_py))


@kernel
def k_kick(buf, n, prm, clk, ctl):
    """wcsph.kdk_kick: second half-kick, guard counts, block-reduced max |v|^2, |a|^2, rho."""
    if ctl[STOP] != 0:
        return
    i = cuda.grid(1)
    v2 = 0.0
    a2 = 0.0
    r = 0.0
    if i < n and buf[1][i] == FLUID:
        v2, a2, r, guard = kick_particle(i, _view(buf), clk[DTS], prm)
        if guard == 1:
            cuda.atomic.add(ctl, N_BAD, 1)
        elif guard == 2:
            cuda.atomic.add(ctl, N_BAND, 1)
    _block_max(clk, v2, a2, r)
