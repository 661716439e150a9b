"""ISPH's pressure Poisson equation: the unknowns, the rows (assembled through
``pairs.gather`` with the row terms of terms.py), and the solvers (``ppe_solver``: the jitted
diagonally preconditioned BiCGSTAB, or BiCGSTAB with a pyamg AMG preconditioner)."""

from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numba import njit, prange

from ..pairs import fluid_only, fluidlike, gather, interacting
from ..particles import FLUID, INLET, OUTLET, WALL
from ..wcsph import FASTMATH
from .isph_terms import MAX_ROW, fluid_row_pair, wall_row_pair

PPE_SOLVERS = ("bicgstab", "amg")


@njit(cache=True)
def ppe_unknowns(ps, n, flag, wsum, idx):
    """idx[i] = the unknown of slot i (interior fluid, wetted wall, active buffer particle with
    fluid neighbours), -1 if none; returns the count."""
    k = 0
    for i in range(n):
        kd = ps.kind[i]
        if flag[i] == 0 or ((kd == WALL or kd == INLET or kd == OUTLET) and wsum[i] > 0.0):
            idx[i] = k
            k += 1
        else:
            idx[i] = -1
    return k


@njit(parallel=True, cache=True, fastmath=FASTMATH)
def ppe_assemble(ps, n, cells, prm, dt, idx, wsum, dwall, wscale, indptr, indices, data, b,
                 x0, slot, rho_k, rho_ref, relax):
    """Fill the PPE rows (module docstring, step 3) in CSR with MAX_ROW slots per row (the
    unused tail of a row is padding the caller compacts); b the right-hand side, x0 the warm
    start (the last pressure), slot[k] the particle of unknown k. Returns the largest row length.
    Wall rows are scaled by ``wscale`` (a typical fluid diagonal) for a balanced system."""
    inv_dt = 1.0 / dt
    longest = 0
    for i in prange(n):
        k = idx[i]
        if k >= 0:
            longest = max(longest, _assemble_row(ps, i, k, cells, prm, inv_dt, idx, wsum, dwall,
                                                 wscale, indptr, indices, data, b, x0, slot,
                                                 rho_k, rho_ref, relax))
    return longest


@njit(cache=True, fastmath=FASTMATH)
def _assemble_row(ps, i, k, cells, prm, inv_dt, idx, wsum, dwall, wscale, indptr, indices, data,
                  b, x0, slot, rho_k, rho_ref, relax):
    """Row k (particle i) of the PPE; returns its length."""
    h = prm.h
    s2 = 4.0 * h * h
    slot[k] = i
    x0[k] = ps.p[i]
    base = indptr[k]
    indices[base] = k   # position 0 of the row: the diagonal
    if ps.kind[i] == FLUID:
        ctx = (1.0 / h, prm.alpha_f, 0.01 * h * h, ps.vx[i], ps.vz[i], ps.rho[i], idx, indices,
               data, base, prm.gx / inv_dt, prm.gz / inv_dt)
        diag, div, known, cnt = gather(i, ps.x[i], ps.y[i], ps.z[i], ps.cell[i], ps, cells, s2,
                                       interacting, fluid_row_pair, ctx, (0.0, 0.0, 0.0, 1))
        data[base] = diag
        # density-invariance relaxation (Asai et al. 2012): a kernel density above the lattice's
        # pushes apart, below pulls together, so volume errors do not accumulate
        b[k] = -div * inv_dt + relax * (rho_k[i] - rho_ref) / rho_ref + known
    else:  # wall or buffer: p_s - sum_f w_sf p_f = dwall_s, scaled
        data[base] = wscale
        b[k] = wscale * dwall[i]
        ctx = (1.0 / h, prm.alpha_w, wscale / wsum[i], idx, indices, data, base)
        if ps.kind[i] == WALL:   # fluid and buffer unknowns (wall_state's sums)
            cnt = gather(i, ps.x[i], ps.y[i], ps.z[i], ps.cell[i], ps, cells, s2, fluidlike,
                         wall_row_pair, ctx, 1)
        else:   # a buffer's row: fluid unknowns (passes.buffer_rows)
            cnt = gather(i, ps.x[i], ps.y[i], ps.z[i], ps.cell[i], ps, cells, s2, fluid_only,
                         wall_row_pair, ctx, 1)
    for c in range(cnt, MAX_ROW):
        indices[base + c] = -1
    return cnt


@njit(cache=True)
def compact_rows(m, indptr, indices, data, out_ptr):
    """Drop the padding (-1 columns) of the m rows in place; out_ptr receives the CSR pointers."""
    w = 0
    out_ptr[0] = 0
    for k in range(m):
        for c in range(indptr[k], indptr[k + 1]):
            if indices[c] >= 0:
                indices[w] = indices[c]
                data[w] = data[c]
                w += 1
        out_ptr[k + 1] = w
    return w


@njit(cache=True, fastmath=FASTMATH)
def _spmv(indptr, indices, data, x, y, m):
    for k in range(m):
        s = 0.0
        for c in range(indptr[k], indptr[k + 1]):
            s += data[c] * x[indices[c]]
        y[k] = s


@njit(cache=True, fastmath=FASTMATH)
def bicgstab_jacobi(indptr, indices, data, b, x, m, tol, max_iter, w):
    """BiCGSTAB (van der Vorst 1992) preconditioned by the diagonal (first in each row), in
    place on the warm start x; w is (8, >= m) scratch. No set-up and no Python per iteration:
    on these small systems (10^3-10^4 unknowns, warm-started) that beats building an AMG
    hierarchy every step. Returns (iterations, relative residual)."""
    r = w[0]
    rh = w[1]
    p = w[2]
    v = w[3]
    ph = w[4]
    sv = w[5]
    sh = w[6]
    t = w[7]
    _spmv(indptr, indices, data, x, t, m)
    bn = 0.0
    rn = 0.0
    for k in range(m):
        r[k] = b[k] - t[k]
        rh[k] = r[k]
        p[k] = 0.0
        v[k] = 0.0
        bn += b[k] * b[k]
        rn += r[k] * r[k]
    bn = math.sqrt(bn)
    if bn == 0.0:
        bn = 1.0
    rel = math.sqrt(rn) / bn
    rho = 1.0
    alpha = 1.0
    omega = 1.0
    it = 0
    while rel > tol and it < max_iter:
        rho1 = 0.0
        for k in range(m):
            rho1 += rh[k] * r[k]
        if rho1 == 0.0 or omega == 0.0:  # breakdown: restart from the current residual
            for k in range(m):
                rh[k] = r[k]
                p[k] = 0.0
                v[k] = 0.0
            rho = alpha = omega = 1.0
            rho1 = 0.0
            for k in range(m):
                rho1 += r[k] * r[k]
        beta = (rho1 / rho) * (alpha / omega)
        rho = rho1
        for k in range(m):
            p[k] = r[k] + beta * (p[k] - omega * v[k])
            ph[k] = p[k] / data[indptr[k]]
        _spmv(indptr, indices, data, ph, v, m)
        rv = 0.0
        for k in range(m):
            rv += rh[k] * v[k]
        if rv == 0.0:  # breakdown with nothing left to gain: return the current iterate
            break
        alpha = rho / rv
        sn = 0.0
        for k in range(m):
            sv[k] = r[k] - alpha * v[k]
            sn += sv[k] * sv[k]
        it += 1
        if math.sqrt(sn) / bn <= tol:
            for k in range(m):
                x[k] += alpha * ph[k]
            rel = math.sqrt(sn) / bn
            break
        for k in range(m):
            sh[k] = sv[k] / data[indptr[k]]
        _spmv(indptr, indices, data, sh, t, m)
        ts = 0.0
        tt = 0.0
        for k in range(m):
            ts += t[k] * sv[k]
            tt += t[k] * t[k]
        omega = ts / tt if tt > 0.0 else 0.0
        rn = 0.0
        for k in range(m):
            x[k] += alpha * ph[k] + omega * sh[k]
            r[k] = sv[k] - omega * t[k]
            rn += r[k] * r[k]
        rel = math.sqrt(rn) / bn
    return it, rel


def solve_ppe(solver: str, m: int, ptr: np.ndarray, indices: np.ndarray, data: np.ndarray,
              b: np.ndarray, x0: np.ndarray, tol: float, max_iter: int,
              scratch: np.ndarray) -> tuple[np.ndarray, int, float]:
    """Solve the m x m CSR system (diagonal first in each row) by ``solver`` (PPE_SOLVERS) from
    the warm start ``x0`` (overwritten by ``bicgstab``); returns (solution, iterations,
    relative residual |b - A x| / |b|)."""
    if solver == "bicgstab":
        work = scratch.reshape(-1)[: 8 * m].reshape(8, m) if scratch.size >= 8 * m else np.empty((8, m))
        it, rel = bicgstab_jacobi(ptr, indices, data, b, x0, m, tol, max_iter, work)
        return x0, int(it), float(rel)
    if solver != "amg":
        raise ValueError(f"ppe_solver: one of {PPE_SOLVERS}, got {solver!r}")
    import pyamg  # only this solver needs it
    nnz = int(ptr[m])
    a = sp.csr_matrix((data[:nnz], indices[:nnz], ptr[: m + 1]), shape=(m, m))
    pre = pyamg.smoothed_aggregation_solver(a, symmetry="nonsymmetric",
                                            max_coarse=200).aspreconditioner()
    count = [0]

    def _count(_xk: np.ndarray) -> None:
        count[0] += 1

    sol, _info = spla.bicgstab(a, b, x0=x0, rtol=tol, atol=0.0, maxiter=max_iter, M=pre,
                               callback=_count)
    bn = float(np.linalg.norm(b)) or 1.0
    return sol, int(count[0]), float(np.linalg.norm(b - a @ sol)) / bn
