"""Do the GPU step's kernels compile for a real GPU? Each kernel of sph_core/cuda/gpu_kernels.py
and gpu_schemes.py through ``numba.cuda.compile_ptx`` (sm_90 by default), without a GPU: host
arrays stand in for device arrays (the same numba types). A kernel that the simulator runs may
still fail here (docs/developer/gpu.md: every callee must be inlined).

Needs ``pip install "numba-cuda[cu13]"`` (NVVM); must run WITHOUT NUMBA_ENABLE_CUDASIM.

    NUMBA_NUM_THREADS=1 python bench/gpu_ptx_check.py [--cc 9.0]

Output: one JSON object per kernel: ``bench``, ``kernel``, ``ok``, ``ptx_lines`` (or ``error``),
``params`` (the kernel's .param count).
"""

from __future__ import annotations

import argparse
import json
import os

import numpy as np


def _args() -> dict:
    """Each kernel's argument tuple, from a small dam break (every scheme's rows exist always)."""
    from sph_core.cuda import gpu_kernels as K
    from sph_core.simulation import Simulation
    from sph_core.state import Cells
    from wavesph.cases.dambreak import dambreak_scene

    sim = Simulation(dambreak_scene(a=0.05, dp=0.01, t_end=1.0, tank_length=0.1))
    ps, c, prm = sim.particles, sim.cells, sim.prm
    buf = (ps.f, ps.kind, ps.ids, ps.cell)
    buf2 = (ps.f2, ps.kind2, ps.ids2, ps.cell2)
    i64 = np.zeros(8, dtype=np.int64)
    cells = Cells(c.start, i64, c.order, c.ncx, c.ncz, c.xmin, c.zmin, c.inv_cs, c.reach, c.ncy,
                  c.ymin)
    clk = np.zeros(K.N_CLK)
    ctl = np.zeros(K.N_CTL, dtype=np.int64)
    n = int(ps.n)
    return {
        "k_begin": (clk, ctl),
        "k_finish": (prm, clk, ctl),
        "k_kick_drift_bin": (buf, n, prm, cells, i64, clk, ctl),
        "k_scan_blocks": (i64, i64, i64, n, ctl),
        "k_scan_sums": (i64, n, ctl),
        "k_scan_add": (i64, i64, i64, i64, n, ctl),
        "k_scatter": (buf, n, i64, i64, ctl),
        "k_cell_order": (i64, i64, n, ctl),
        "k_permute": (buf, buf2, i64, n, ctl),
        "k_wall": (buf, n, cells, prm, ctl),
        "k_fluid": (buf, n, cells, prm, ctl),
        "k_kick": (buf, n, prm, clk, ctl),
        "k_bin": (buf, n, cells, i64, ctl),
        "k_permute_pc": (buf, buf2, i64, n, ctl),
        "k_predict": (buf, n, prm, clk, ctl),
        "k_correct": (buf, n, prm, clk, ctl),
        "k_shift_fickian": (buf, n, cells, prm, clk, ctl),
        "k_dplus_surface": (buf, n, cells, prm, clk, ctl),
        "k_dplus_tangential": (buf, n, cells, prm, ctl),
        "k_shift_move": (buf, n, ctl),
        "k_muscl_gradients": (buf, n, cells, prm, ctl),
        "k_fluid_riemann": (buf, n, cells, prm, ctl),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cc", default="9.0", help="compute capability, e.g. 9.0")
    ap.add_argument("--only", nargs="*", help="kernel names (default: all)")
    a = ap.parse_args()
    if os.environ.get("NUMBA_ENABLE_CUDASIM", "0") not in ("", "0"):
        raise SystemExit("unset NUMBA_ENABLE_CUDASIM: the simulator compiles nothing")
    import numba
    from numba import cuda

    from sph_core.cuda import gpu_kernels as K
    from sph_core.cuda import gpu_schemes as S

    cc = tuple(int(v) for v in a.cc.split("."))
    for name, args in _args().items():
        if a.only and name not in a.only:
            continue
        kernel = getattr(K, name, None) or getattr(S, name)
        sig = tuple(numba.typeof(v) for v in args)
        out = {"bench": "gpu_ptx_check", "kernel": name, "cc": a.cc}
        try:
            ptx, _ = cuda.compile_ptx(kernel.py_func, sig, cc=cc)
            out.update(ok=True, ptx_lines=ptx.count("\n"),
                       params=sum(1 for ln in ptx.splitlines() if ln.strip().startswith(".param")))
        except Exception as exc:  # report and go on: one line per kernel
            out.update(ok=False, error=f"{type(exc).__name__}: {str(exc).splitlines()[0][:300]}")
        print(json.dumps(out), flush=True)


if __name__ == "__main__":
    main()
