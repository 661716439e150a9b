"""Linear potential-flow reference for a box heaving in a closed 2D tank (heave_period).

The same geometry as the SPH run (``rigid_bodies.floating_box_scene``): a tank of length L with
water of depth h at rest (the level the closed tank's water has at the box's equilibrium), a box
of breadth B centred at L/2 floating at draft d, released from a heave offset Z0 with the outer
surface at the level it had (volume is conserved: eta0 = -B Z0 / (L - B)). Linear theory
(small motion, no viscosity): Laplace for phi in the fluid below the mean surface and the box,
dphi/dn = 0 on bed and walls, dphi/dz = W on the box bottom, dphi/dx = 0 on its sides, and

    eta_t = phi_z,  phi_t = -g eta          on the free surface
    M W_t = -rho g B Z - rho int_bottom phi_t dx,   Z_t = W.

Finite differences (5-point, spacing ``dx`` that must divide L, h, d and the box edges; ghost
nodes for the Neumann conditions); the Dirichlet-to-Neumann map of the surface and the box's
infinite-frequency added mass a_inf = rho int_bottom psi (psi: phi = 0 on the surface, psi_z = 1
on the bottom) are computed once by a sparse LU, then (eta, phi_s, Z, W) are integrated by RK4.
This includes the reflections from the tank's ends, as the SPH run does; the radiation damping
seen over the run is the waves the box sends into the rest of the tank.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu


def heave_release(length: float, depth: float, breadth: float, draft: float, mass: float,
                  z0: float, t_end: float, dx: float = 0.005, dt: float = 5e-4,
                  rho: float = 1000.0, g: float = 9.81) -> tuple[np.ndarray, np.ndarray]:
    """Times [s] and heave Z(t) [m] (up, from equilibrium) of the box released at Z = z0."""
    nx = round(length / dx)
    nz = round(depth / dx)
    ia = round((0.5 * length - 0.5 * breadth) / dx)
    ib = round((0.5 * length + 0.5 * breadth) / dx)
    jb = round((depth - draft) / dx)
    for v, name in ((length, "length"), (depth, "depth"), (depth - draft, "depth - draft"),
                    (0.5 * (length - breadth), "box edge")):
        if abs(v / dx - round(v / dx)) > 1e-6:
            raise ValueError(f"dx: must divide the {name} ({v} m)")

    def in_box(i: int, j: int) -> bool:   # strictly inside (no fluid node)
        return ia < i < ib and j > jb

    def surface(i: int, j: int) -> bool:
        return j == nz and not (ia < i < ib)

    idx = -np.ones((nx + 1, nz + 1), dtype=np.int64)
    k = 0
    for i in range(nx + 1):
        for j in range(nz + 1):
            if not in_box(i, j) and not surface(i, j):
                idx[i, j] = k
                k += 1
    n = k
    surf_i = np.array([i for i in range(nx + 1) if surface(i, nz)])
    ns = surf_i.size
    bottom = [(i, jb) for i in range(ia, ib + 1)]
    rows, cols, vals = [], [], []
    rhs_s = sp.lil_matrix((n, ns))      # contribution of the surface values (Dirichlet)
    rhs_w = np.zeros(n)                 # contribution of W = 1 (bottom Neumann)
    spos = {int(i): s for s, i in enumerate(surf_i)}

    def couple(r: int, a: int, b: int) -> None:
        """Row r's coefficient 1 on node (a, b): a known surface value goes to the right side."""
        if surface(a, b):
            rhs_s[r, spos[a]] -= 1.0
        else:
            rows.append(r)
            cols.append(idx[a, b])
            vals.append(1.0)

    for i in range(nx + 1):
        for j in range(nz + 1):
            r = idx[i, j]
            if r < 0:
                continue
            rows.append(r)
            cols.append(r)
            vals.append(-4.0)
            for di, dj in ((1, 0), (-1, 0), (0, 1), (0, -1)):
                a, b = i + di, j + dj
                if 0 <= a <= nx and 0 <= b <= nz and not in_box(a, b):
                    couple(r, a, b)
                else:
                    # ghost node: mirror of the opposite neighbour; a box-bottom ghost (above the
                    # bottom) adds 2 dx W (dphi/dz = W), the others are dphi/dn = 0
                    couple(r, i - di, j - dj)
                    if dj == 1 and ia < i < ib and j == jb:
                        rhs_w[r] -= 2.0 * dx
    lu = splu(sp.csc_matrix((vals, (rows, cols)), shape=(n, n)))
    phi_s = lu.solve(rhs_s.toarray())      # fluid phi per unit surface value: [n, ns]
    psi = lu.solve(rhs_w)                  # fluid phi for W = 1 with phi = 0 on the surface

    def dz_surface(field: np.ndarray, sval: np.ndarray) -> np.ndarray:
        """phi_z at the surface nodes (one-sided, second order)."""
        j1 = idx[surf_i, nz - 1]
        j2 = idx[surf_i, nz - 2]
        return (3.0 * sval - 4.0 * field[j1] + field[j2]) / (2.0 * dx)

    wts = np.full(len(bottom), dx)
    wts[0] = wts[-1] = 0.5 * dx
    bidx = np.array([idx[i, j] for i, j in bottom])
    d1 = dz_surface(phi_s, np.eye(ns))     # [ns, ns]: phi_z from surface phi
    d2 = dz_surface(psi, np.zeros(ns))     # [ns]: phi_z from W
    b1 = wts @ phi_s[bidx]                 # [ns]: int_bottom phi per surface phi
    # kinetic energy of the W = 1 flow = rho/2 int_bottom psi psi_z: a_inf = rho int psi > 0;
    # with phi = Phi[phi_s] + W psi, int_bottom phi_t = b1 . phi_s_t + W_t int psi
    a_inf = rho * float(wts @ psi[bidx])
    if a_inf <= 0:
        raise RuntimeError(f"heave_release: added mass {a_inf} <= 0 (sign error in the set-up)")
    m_tot = mass + a_inf
    ws = np.full(ns, dx)                   # surface widths (trapezoid at the ends and box)
    ws[[0, -1]] = 0.5 * dx
    ws[surf_i == ia] = 0.5 * dx
    ws[surf_i == ib] = 0.5 * dx

    def rates(y: np.ndarray) -> np.ndarray:
        eta, ph, z, w = y[:ns], y[ns:2 * ns], y[-2], y[-1]
        ph_t = -g * eta
        w_t = (-rho * g * breadth * z - rho * b1 @ ph_t) / m_tot
        return np.concatenate([d1 @ ph + w * d2, ph_t, [w, w_t]])

    y = np.concatenate([np.full(ns, -breadth * z0 / (length - breadth)), np.zeros(ns), [z0, 0.0]])
    steps = int(round(t_end / dt))
    ts = np.arange(steps + 1) * dt
    zs = np.zeros(steps + 1)
    zs[0] = z0
    for s in range(steps):
        k1 = rates(y)
        k2 = rates(y + 0.5 * dt * k1)
        k3 = rates(y + 0.5 * dt * k2)
        k4 = rates(y + dt * k3)
        y = y + dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
        zs[s + 1] = y[-2]
    heave_release.last = {"a_inf": a_inf, "volume_rate_check": float(ws @ d2 + breadth)}
    return ts, zs
