"""The jitted time stepping of the 1D Nwogu Boussinesq solver: right-hand sides, tridiagonal solve,
filter, RK4 predictor and corrector loop.

Grid arrays are padded with two ghost nodes on each side: node i of the model is index i + 2.
Reflective walls sit on the first and last model nodes: eta and h are mirrored even, u odd
(u = 0 on the wall).

Equations (Nwogu 1993; discretisation of Wei & Kirby 1995), with z_alpha = beta h:

    eta_t = E = -[(h + eta) u]_x - [A u_xx + B (h u)_xx]_x - w_s eta + f(x, t)
    U_t   = F = -g eta_x - u u_x - w_s u
    U     = u + a2 u_xx + b2 (h u)_xx

    A = (z_alpha^2/2 - h^2/6) h,  B = (z_alpha + h/2) h,  a2 = z_alpha^2/2,  b2 = z_alpha

(the weakly nonlinear, mild-slope form of Nwogu: gradients of z_alpha are neglected; u is the
horizontal velocity at z = z_alpha, U its dispersive combination that the time stepping evolves).

First derivatives use 5-point 4th-order central differences; the dispersive (second and third
derivative) terms use 3-point 2nd-order differences, so that U(u) is tridiagonal. The truncation
error is O(dx^4, dx^2 mu^2), as in Wei & Kirby (1995). w_s is the sponge damping rate [1/s]
and f the source function of Wei, Kirby & Sinha (1999).
"""

from __future__ import annotations

import numpy as np
from numba import njit

NG = 2  # ghost nodes on each side


@njit(cache=True)
def fill_ghosts(eta: np.ndarray, u: np.ndarray) -> None:
    """Mirror eta (even) and u (odd) about the wall nodes 2 and n-3; u = 0 on the walls."""
    n = eta.size
    lo = NG
    hi = n - 1 - NG
    u[lo] = 0.0
    u[hi] = 0.0
    for j in range(1, NG + 1):
        eta[lo - j] = eta[lo + j]
        u[lo - j] = -u[lo + j]
        eta[hi + j] = eta[hi - j]
        u[hi + j] = -u[hi - j]


@njit(cache=True)
def source_signal(t: float, amp: np.ndarray, omega: np.ndarray, phase: np.ndarray, ramp: float) -> float:
    """S(t) = r(t) sum_n D_n cos(omega_n t - phi_n), r a half-cosine ramp over `ramp` seconds."""
    s = 0.0
    for m in range(amp.size):
        s += amp[m] * np.cos(omega[m] * t - phase[m])
    if t < ramp:
        s *= 0.5 * (1.0 - np.cos(np.pi * t / ramp))
    return s


@njit(cache=True)
def rhs(eta: np.ndarray, u: np.ndarray, h: np.ndarray, coef_a: np.ndarray, coef_b: np.ndarray,
        sponge: np.ndarray, src_shape: np.ndarray, src: float, g: float, dx: float,
        work_q: np.ndarray, work_d: np.ndarray, e_out: np.ndarray, f_out: np.ndarray) -> None:
    """E and F (module docstring) at all model nodes; ghosts of eta, u must be filled.
    work_q, work_d: scratch arrays of the padded size (flux and dispersive flux).
    """
    n = eta.size
    inv12 = 1.0 / (12.0 * dx)
    inv2 = 1.0 / (2.0 * dx)
    invdx2 = 1.0 / (dx * dx)
    for i in range(n):
        work_q[i] = (h[i] + eta[i]) * u[i]
    for i in range(1, n - 1):
        uxx = u[i + 1] - 2.0 * u[i] + u[i - 1]
        huxx = h[i + 1] * u[i + 1] - 2.0 * h[i] * u[i] + h[i - 1] * u[i - 1]
        work_d[i] = (coef_a[i] * uxx + coef_b[i] * huxx) * invdx2
    for i in range(NG, n - NG):
        qx = (-work_q[i + 2] + 8.0 * (work_q[i + 1] - work_q[i - 1]) + work_q[i - 2]) * inv12
        dflx = (work_d[i + 1] - work_d[i - 1]) * inv2
        e_out[i] = -qx - dflx - sponge[i] * eta[i] + src_shape[i] * src
        etax = (-eta[i + 2] + 8.0 * (eta[i + 1] - eta[i - 1]) + eta[i - 2]) * inv12
        ux = (-u[i + 2] + 8.0 * (u[i + 1] - u[i - 1]) + u[i - 2]) * inv12
        f_out[i] = -g * etax - u[i] * ux - sponge[i] * u[i]


@njit(cache=True)
def apply_pins(eta: np.ndarray, uu: np.ndarray, pin_idx: np.ndarray, pin_in: np.ndarray,
               pin_ratio: np.ndarray) -> None:
    """Characteristic coupling boundary at node b (two-way coupling, seed 001 Alg. 2 line 4).

    Of the state just computed at b, keep the model's outgoing (right-going) part
    R = (eta + u / r) / 2 and replace the incoming (left-going) part by the one SPH measured,
    L = (eta_sph - u_sph / r) / 2:  eta_b = R + L,  u_b = r (R - L).  r = u/eta of a progressive
    wave (linear Nwogu, at the wave's frequency). U = u at b (identity row of M).
    """
    for p in range(pin_idx.size):
        b = pin_idx[p] + NG
        r = pin_ratio[p]
        right = 0.5 * (eta[b] + uu[b] / r)
        eta[b] = right + pin_in[p]
        uu[b] = r * (right - pin_in[p])


@njit(cache=True)
def close_boundary(eta: np.ndarray, u: np.ndarray, uu: np.ndarray, pin_idx: np.ndarray) -> None:
    """Make the coupling-boundary node b the right end of the active grid (two-way coupling).

    The two ghost nodes beyond b take the cubic extrapolation through b-3..b (held value at b):
    f_{b+1} = 4f_b - 6f_{b-1} + 4f_{b-2} - f_{b-3},  f_{b+2} = 10f_b - 20f_{b-1} + 15f_{b-2} - 4f_{b-3}.
    The dispersive flux at b takes a second difference across b, so the ghost error is divided
    by dx^3 in E at b-1: the cubic (O(dx^4)) extrapolation keeps the boundary 2nd-order
    (a linear or quadratic one makes it 1st-order: tested). The grid beyond is inactive (zero).
    """
    if pin_idx.size == 0:
        return
    b = pin_idx[pin_idx.size - 1] + NG
    n = eta.size
    for f in (eta, u):
        f[b + 1] = 4.0 * f[b] - 6.0 * f[b - 1] + 4.0 * f[b - 2] - f[b - 3]
        f[b + 2] = 10.0 * f[b] - 20.0 * f[b - 1] + 15.0 * f[b - 2] - 4.0 * f[b - 3]
    for i in range(b + NG + 1, n):
        eta[i] = 0.0
        u[i] = 0.0
    for i in range(b + 1, n):
        uu[i] = 0.0


@njit(cache=True)
def thomas_factor(lower: np.ndarray, diag: np.ndarray, upper: np.ndarray,
                  cprime: np.ndarray, minv: np.ndarray) -> None:
    """Factor a tridiagonal matrix once (Thomas algorithm): c'_i and 1/(b_i - a_i c'_{i-1})."""
    n = diag.size
    minv[0] = 1.0 / diag[0]
    cprime[0] = upper[0] * minv[0]
    for i in range(1, n):
        m = 1.0 / (diag[i] - lower[i] * cprime[i - 1])
        minv[i] = m
        cprime[i] = upper[i] * m
    cprime[n - 1] = 0.0


@njit(cache=True)
def thomas_solve(lower: np.ndarray, cprime: np.ndarray, minv: np.ndarray, rhs_: np.ndarray,
                 x: np.ndarray, off: int) -> None:
    """Solve the factored system for x[off:off+n] with right-hand side rhs_[off:off+n]."""
    n = minv.size
    x[off] = rhs_[off] * minv[0]
    for i in range(1, n):
        x[off + i] = (rhs_[off + i] - lower[i] * x[off + i - 1]) * minv[i]
    for i in range(n - 2, -1, -1):
        x[off + i] -= cprime[i] * x[off + i + 1]


@njit(cache=True)
def apply_operator(lower: np.ndarray, diag: np.ndarray, upper: np.ndarray, u: np.ndarray,
                   out: np.ndarray, off: int) -> None:
    """out = M u on the model nodes (M tridiagonal, U = M u)."""
    n = diag.size
    for i in range(n):
        s = diag[i] * u[off + i]
        if i > 0:
            s += lower[i] * u[off + i - 1]
        if i < n - 1:
            s += upper[i] * u[off + i + 1]
        out[off + i] = s


@njit(cache=True)
def shapiro_filter(f: np.ndarray, work: np.ndarray, i_end: int) -> None:
    """Fourth-order Shapiro filter f_i -= (f_{i-2} - 4f_{i-1} + 6f_i - 4f_{i+1} + f_{i+2}) / 16.

    Removes the 2 dx mode and damps kdx small modes by only (kdx)^4/16; ghosts must be filled.
    Padded indices [NG, i_end) are filtered.
    """
    for i in range(NG, i_end):
        work[i] = (f[i - 2] - 4.0 * f[i - 1] + 6.0 * f[i] - 4.0 * f[i + 1] + f[i + 2]) * 0.0625
    for i in range(NG, i_end):
        f[i] -= work[i]


@njit(cache=True)
def push_history(e_hist: np.ndarray, f_hist: np.ndarray, e_new: np.ndarray, f_new: np.ndarray) -> None:
    """Shift the three-level histories of E and F back by one step and store the newest."""
    for i in range(NG, e_new.size - NG):
        e_hist[2, i] = e_hist[1, i]
        e_hist[1, i] = e_hist[0, i]
        e_hist[0, i] = e_new[i]
        f_hist[2, i] = f_hist[1, i]
        f_hist[1, i] = f_hist[0, i]
        f_hist[0, i] = f_new[i]


@njit(cache=True)
def rk4_step(t0: float, dt: float, eta: np.ndarray, u: np.ndarray, uu: np.ndarray,
             e0: np.ndarray, f0: np.ndarray, h: np.ndarray, coef_a: np.ndarray, coef_b: np.ndarray,
             lower: np.ndarray, cprime: np.ndarray, minv: np.ndarray, sponge: np.ndarray,
             src_shape: np.ndarray, src_amp: np.ndarray, src_omega: np.ndarray, src_phase: np.ndarray,
             src_ramp: float, g: float, dx: float, pin_idx: np.ndarray, pin_in: np.ndarray, pin_ratio: np.ndarray,
             eta_s: np.ndarray, u_s: np.ndarray, uu_s: np.ndarray, ke: np.ndarray, kf: np.ndarray,
             acc_e: np.ndarray, acc_f: np.ndarray, work_q: np.ndarray, work_d: np.ndarray) -> None:
    """One classical Runge-Kutta step of (eta, U) from t0; starts the multistep history.

    e0, f0 hold R(t0); on return eta, u, uu are at t0 + dt (R at t0 + dt is not evaluated).
    """
    n = eta.size
    for i in range(NG, n - NG):
        acc_e[i] = e0[i]
        acc_f[i] = f0[i]
        ke[i] = e0[i]
        kf[i] = f0[i]
    for stage in range(3):
        frac = 1.0 if stage == 2 else 0.5
        weight = 1.0 if stage == 2 else 2.0
        for i in range(NG, n - NG):
            eta_s[i] = eta[i] + frac * dt * ke[i]
            uu_s[i] = uu[i] + frac * dt * kf[i]
        apply_pins(eta_s, uu_s, pin_idx, pin_in, pin_ratio)
        thomas_solve(lower, cprime, minv, uu_s, u_s, NG)
        fill_ghosts(eta_s, u_s)
        close_boundary(eta_s, u_s, uu_s, pin_idx)
        ts = t0 + frac * dt
        src = source_signal(ts, src_amp, src_omega, src_phase, src_ramp)
        rhs(eta_s, u_s, h, coef_a, coef_b, sponge, src_shape, src, g, dx, work_q, work_d, ke, kf)
        for i in range(NG, n - NG):
            acc_e[i] += weight * ke[i]
            acc_f[i] += weight * kf[i]
    for i in range(NG, n - NG):
        eta[i] += dt / 6.0 * acc_e[i]
        uu[i] += dt / 6.0 * acc_f[i]
    apply_pins(eta, uu, pin_idx, pin_in, pin_ratio)
    thomas_solve(lower, cprime, minv, uu, u, NG)
    fill_ghosts(eta, u)
    close_boundary(eta, u, uu, pin_idx)


@njit(cache=True)
def advance_steps(n_steps: int, t0: float, dt: float, n_hist: int, tol: float, max_iter: int,
                  filter_every: int, step0: int,
                  eta: np.ndarray, u: np.ndarray, uu: np.ndarray, e_hist: np.ndarray, f_hist: np.ndarray,
                  h: np.ndarray, coef_a: np.ndarray, coef_b: np.ndarray,
                  lower: np.ndarray, diag: np.ndarray, upper: np.ndarray,
                  cprime: np.ndarray, minv: np.ndarray,
                  sponge: np.ndarray, src_shape: np.ndarray, src_amp: np.ndarray, src_omega: np.ndarray,
                  src_phase: np.ndarray, src_ramp: float, g: float, dx: float,
                  pin_idx: np.ndarray, pin_in: np.ndarray, pin_ratio: np.ndarray,
                  eta_new: np.ndarray, u_new: np.ndarray, uu_new: np.ndarray,
                  e_new: np.ndarray, f_new: np.ndarray,
                  eta_prev: np.ndarray, u_prev: np.ndarray,
                  work_q: np.ndarray, work_d: np.ndarray, stats: np.ndarray) -> int:
    """Advance n_steps steps of the Adams-Bashforth-Moulton predictor-corrector.

    Predictor (AB3):  f* = f^n + dt/12 (23 R^n - 16 R^{n-1} + 5 R^{n-2})
    Corrector (AM4):  f^(k+1) = f^n + dt/24 (9 R^(k) + 19 R^n - 5 R^{n-1} + R^{n-2}),
    iterated until sum|d eta|/sum|eta| and sum|d u|/sum|u| between successive iterates are below
    `tol` (Wei & Kirby 1995), for f = (eta, U), R = (E, F). While the history is shorter than
    three levels (start, or after the state was set), classical RK4 steps fill it.

    e_hist, f_hist: (3, n) with rows R^n, R^{n-1}, R^{n-2}, filled for the first n_hist rows.
    pin_idx, pin_in, pin_ratio: the coupling-boundary node (empty, or one), the incoming
    characteristic L measured by SPH and u/eta ratio r (`apply_pins`).
    stats: [corrector iterations summed, max iterations of one step, non-converged steps].
    Returns the new history length.
    """
    n = eta.size
    p0, p1, p2 = 23.0 / 12.0, -16.0 / 12.0, 5.0 / 12.0
    c_new, c0, c1, c2 = 9.0 / 24.0, 19.0 / 24.0, -5.0 / 24.0, 1.0 / 24.0
    for step in range(n_steps):
        t1 = t0 + (step + 1) * dt
        if n_hist < 3:
            # start (or restart) the history with 4th-order Runge-Kutta steps
            rk4_step(t1 - dt, dt, eta, u, uu, e_hist[0], f_hist[0], h, coef_a, coef_b, lower, cprime,
                     minv, sponge, src_shape, src_amp, src_omega, src_phase, src_ramp, g, dx,
                     pin_idx, pin_in, pin_ratio, eta_new, u_new, uu_new, e_new, f_new, eta_prev, u_prev,
                     work_q, work_d)
            src = source_signal(t1, src_amp, src_omega, src_phase, src_ramp)
            rhs(eta, u, h, coef_a, coef_b, sponge, src_shape, src, g, dx,
                work_q, work_d, e_new, f_new)
            push_history(e_hist, f_hist, e_new, f_new)
            n_hist += 1
            if not np.isfinite(eta[NG]):
                return -(step + 1)
            continue
        # predictor
        for i in range(NG, n - NG):
            eta_new[i] = eta[i] + dt * (p0 * e_hist[0, i] + p1 * e_hist[1, i] + p2 * e_hist[2, i])
            uu_new[i] = uu[i] + dt * (p0 * f_hist[0, i] + p1 * f_hist[1, i] + p2 * f_hist[2, i])
        apply_pins(eta_new, uu_new, pin_idx, pin_in, pin_ratio)
        thomas_solve(lower, cprime, minv, uu_new, u_new, NG)
        fill_ghosts(eta_new, u_new)
        close_boundary(eta_new, u_new, uu_new, pin_idx)
        src = source_signal(t1, src_amp, src_omega, src_phase, src_ramp)
        rhs(eta_new, u_new, h, coef_a, coef_b, sponge, src_shape, src, g, dx,
            work_q, work_d, e_new, f_new)
        # corrector iterations
        it = 0
        while True:
            it += 1
            for i in range(NG, n - NG):
                eta_prev[i] = eta_new[i]
                u_prev[i] = u_new[i]
                eta_new[i] = eta[i] + dt * (c_new * e_new[i] + c0 * e_hist[0, i] + c1 * e_hist[1, i]
                                            + c2 * e_hist[2, i])
                uu_new[i] = uu[i] + dt * (c_new * f_new[i] + c0 * f_hist[0, i] + c1 * f_hist[1, i]
                                          + c2 * f_hist[2, i])
            apply_pins(eta_new, uu_new, pin_idx, pin_in, pin_ratio)
            thomas_solve(lower, cprime, minv, uu_new, u_new, NG)
            fill_ghosts(eta_new, u_new)
            close_boundary(eta_new, u_new, uu_new, pin_idx)
            rhs(eta_new, u_new, h, coef_a, coef_b, sponge, src_shape, src, g, dx,
                work_q, work_d, e_new, f_new)
            de = 0.0
            se = 0.0
            du = 0.0
            su = 0.0
            for i in range(NG, n - NG):
                de += abs(eta_new[i] - eta_prev[i])
                se += abs(eta_new[i])
                du += abs(u_new[i] - u_prev[i])
                su += abs(u_new[i])
            ok_e = de <= tol * se
            ok_u = du <= tol * su
            if (ok_e and ok_u) or it >= max_iter:
                if not (ok_e and ok_u):
                    stats[2] += 1.0
                break
        stats[0] += it
        if it > stats[1]:
            stats[1] = it
        # shift history and accept the new state
        push_history(e_hist, f_hist, e_new, f_new)
        for i in range(n):
            eta[i] = eta_new[i]
            u[i] = u_new[i]
            uu[i] = uu_new[i]
        if filter_every > 0 and (step0 + step + 1) % filter_every == 0:
            shapiro_filter(eta, work_q, n - NG)
            shapiro_filter(u, work_q, n - NG)
            apply_pins(eta, u, pin_idx, pin_in, pin_ratio)
            fill_ghosts(eta, u)
            close_boundary(eta, u, uu, pin_idx)
            apply_operator(lower, diag, upper, u, uu, NG)
            rhs(eta, u, h, coef_a, coef_b, sponge, src_shape, src, g, dx,
                work_q, work_d, e_hist[0], f_hist[0])
        if not np.isfinite(eta[NG]) or not np.isfinite(se):
            return -(step + 1)
    return n_hist
