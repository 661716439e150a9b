"""The launch list of a GPU kdk step with open ends and/or rigid bodies (``step._step_kdk``).

A closed tank without bodies keeps ``cuda_stepper``'s 11 launches (kick, drift and binning in
one kernel). With open ends or bodies the binning must follow what moves particles after the
drift (buffers, clones, body placement), so the kick + drift and the binning are two kernels
and the open-end (``gpu_open_ends.py``) and body (``gpu_bodies.py``) kernels go in between, in
the CPU step's order:

    kick + drift (fluid)
    bodies: stage KICK_DRIFT, place                       (bodies_advance, place_bodies)
    open ends: boundary, buffers, mark, scan (3), apply   (update_buffers)
    bin, scan (3), scatter, cell order, permute           (sort_by_cell)
    open ends: extrapolate                                (extrapolate_buffers)
    wall, fluid; bodies: particle loads, accelerations    (_forces)
    kick
    bodies: stage KICK, place, speed bound                (bodies_advance, place_bodies)
    open ends: gauge line, gauge                          (measure_boundaries)
    finish
"""

from __future__ import annotations

from typing import Any

from ..bodies import KICK, KICK_DRIFT
from . import gpu_bodies as B
from . import gpu_kernels as K
from . import gpu_open_ends as G
from . import simulated


def _cfg(kernel: Any, grid: int, block: int, stream: Any) -> Any:
    """``kernel[grid, block, stream]``, configured at launch under the simulator: there
    ``kernel[...]`` sets the configuration on the kernel itself, so a kernel launched twice in
    a step with different grids (the scans) would run both with the last one."""
    if simulated():
        return lambda *args: kernel[grid, block, stream](*args)
    return kernel[grid, block, stream]


def launches(st: Any, parity: int, stream: Any = 0) -> list:
    """The step's kernel launches for CudaStepper ``st`` (with ``st.open`` and/or
    ``st.bodies``), as (name, configured kernel, args)."""
    ps, ps2 = st.bufs[parity], st.bufs[1 - parity]
    n, prm, cells, clk, ctl = st.n, st.prm, st.cells, st.clk, st.ctl
    gn, tpb, sb = st._grid_n, K.TPB, K.SCAN_B
    oed, bdd = st.open, st.bodies
    out = [("kick_drift", _cfg(G.k_kick_drift, gn, tpb, stream), (ps, n, prm, clk, ctl))]
    if bdd is not None:
        bd = bdd.bd
        out += [("body_stage", _cfg(B.k_stage, 1, 1, stream), (bd, KICK_DRIFT, clk, ctl)),
                ("body_place", _cfg(B.k_place, gn, tpb, stream), (ps, n, bd, ctl))]
    if oed is not None:
        ends, oe = oed.ends, oed.oe
        g1 = (n + 1 + tpb - 1) // tpb      # slots and the total of the clone flags
        out += [
            ("boundary", _cfg(G.k_boundary, 1, 1, stream), (ends, clk, ctl, oe)),
            ("buffers", _cfg(G.k_buffers, gn, tpb, stream), (ps, n, ends, prm, clk, ctl, oe)),
            ("mark", _cfg(G.k_mark, g1, tpb, stream), (ps, n, ends, ctl, oe)),
            ("clone_scan_blocks", _cfg(K.k_scan_blocks, oed.nb, sb, stream),
             (oe[G.FLAG], oe[G.OFF], oed.bsum, oed.m, ctl)),
            ("clone_scan_sums", _cfg(K.k_scan_sums, 1, sb, stream), (oed.bsum, oed.nb, ctl)),
            ("clone_scan_add", _cfg(K.k_scan_add, oed.nb, sb, stream),
             (oe[G.OFF], oed.bsum, oed.cursor, oe[G.FLAG], oed.m, ctl)),
            ("apply", _cfg(G.k_apply, gn, tpb, stream), (ps, n, ends, ctl, oe))]
    # with open ends the free slots' bin is large and its order immaterial: live cells only
    ncells = st.ncell if oed is not None else st.ncell + 1
    out += [
        ("bin", _cfg(K.k_bin, gn, tpb, stream), (ps, n, cells, st.count, ctl)),
        ("scan_blocks", _cfg(K.k_scan_blocks, st.nb, sb, stream),
         (st.count, st.start, st.bsum, st.m, ctl)),
        ("scan_sums", _cfg(K.k_scan_sums, 1, sb, stream), (st.bsum, st.nb, ctl)),
        ("scan_add", _cfg(K.k_scan_add, st.nb, sb, stream),
         (st.start, st.bsum, st.cursor, st.count, st.m, ctl)),
        ("scatter", _cfg(K.k_scatter, gn, tpb, stream), (ps, n, st.cursor, st.order, ctl)),
        ("cell_order", _cfg(K.k_cell_order, (ncells + tpb - 1) // tpb, tpb, stream),
         (st.start, st.order, ncells, ctl)),
        ("permute", _cfg(K.k_permute, gn, tpb, stream), (ps, ps2, st.order, n, ctl))]
    if oed is not None:
        out += [("extrapolate", _cfg(G.k_extrapolate, gn, tpb, stream),
                 (ps2, n, cells, oed.ends, prm, ctl, oed.oe))]
    out += [("wall", _cfg(K.k_wall, gn, tpb, stream), (ps2, n, cells, prm, ctl)),
            ("fluid", _cfg(K.k_fluid, gn, tpb, stream), (ps2, n, cells, prm, ctl))]
    if bdd is not None:
        out += [("body_loads", _cfg(B.k_particle_loads, gn, tpb, stream), (ps2, n, cells, prm, bd, ctl)),
                ("body_acc", _cfg(B.k_accelerations, 1, 1, stream), (bd, prm, ctl))]
    out += [("kick", _cfg(K.k_kick, gn, tpb, stream), (ps2, n, prm, clk, ctl))]
    if bdd is not None:
        out += [("body_stage2", _cfg(B.k_stage, 1, 1, stream), (bd, KICK, clk, ctl)),
                ("body_place2", _cfg(B.k_place, gn, tpb, stream), (ps2, n, bd, ctl)),
                ("body_v2", _cfg(B.k_v2, 1, 1, stream), (bd, clk, ctl))]
    if oed is not None:
        gl = (2 * oed.npt + tpb - 1) // tpb
        out += [("gauge_line", _cfg(G.k_gauge_line, gl, tpb, stream),
                 (ps2, cells, oed.ends, prm, ctl, oed.oe)),
                ("gauge", _cfg(G.k_gauge, 1, 1, stream), (oed.ends, prm, ctl, oed.oe))]
    out += [("finish", _cfg(K.k_finish, 1, 1, stream), (prm, clk, ctl))]
    return out
