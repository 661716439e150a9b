"""A solitary wave's run-up on a plane beach in the nonlinear shallow-water equations (NSWE):
the reference that bench/runup.py reads the SPH run-up against, section by section.

Synolakis' (1987) run-up law is the NSWE's own answer for non-breaking waves, so this solver
reproduces it (tests/test_wavesph/test_shallow_runup.py). It also says where the water is while
it runs up: how much of it passes each section of the beach, and how thin the swash is. At
H/d 0.05 on the 1:19.85 beach the water above the still shoreline at its largest is a lens
5.1 d long and 0.025 d thick on average (half a particle spacing at d/dp 20); this is what the
SPH run-up has to carry (docs/studies/runup.md, "Where the SPH swash loses its water").

Method: finite volumes on a uniform grid; HLL fluxes with the hydrostatic reconstruction of
Audusse et al. (2004, SIAM J. Sci. Comput. 25:2050), which keeps water at rest still and depths
non-negative at the moving shoreline; minmod-limited (MUSCL) surface elevation, depth and
velocity; Heun's two-stage Runge-Kutta step (SSP) at Courant number 0.4. The initial wave is
Synolakis': eta = H sech^2(k (x - X1)), u = c eta / (d + eta), its crest the half-width
L = arccosh(sqrt 20) / k before the toe. Frictionless and without dispersion, as the law is.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from wave_client import G
from wave_client.theories import SolitaryWave

DRY = 1e-7          # [m] below this depth a cell carries no velocity
WET = 1e-5          # [m] the shoreline: the last cell deeper than this


@dataclass(frozen=True)
class SwashReference:
    """The NSWE run-up of one solitary wave. Sections are named by their still-water depth as
    a fraction of d (1: the toe, 0: the still shoreline)."""
    height: float                    # H [m]
    depth: float                     # d [m]
    cot_beta: float
    runup: float                     # R: the shoreline's highest elevation above still water [m]
    t_runup: float                   # [s] after the start (the crest L before the toe)
    excess: dict[float, float]       # section -> largest excess volume shoreward of it [m^2/m]
    x: np.ndarray                    # cell centres, the toe at x = 0 [m]
    bed: np.ndarray                  # bed elevation, still water at 0 [m]
    h_at_runup: np.ndarray           # water depth at the instant of R [m]

    def film_at(self, z: float) -> float:
        """Water depth [m] at the instant of R where the bed stands z [m] above still water."""
        i = int(np.argmin(np.abs(self.bed - z)))
        return float(self.h_at_runup[i])


def synolakis_law(h_over_d: float, cot_beta: float) -> float:
    """Synolakis (1987): the non-breaking run-up R/d of a solitary wave on a plane beach."""
    return 2.831 * math.sqrt(cot_beta) * h_over_d**1.25


def _minmod(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.where(a * b > 0, np.sign(a) * np.minimum(np.abs(a), np.abs(b)), 0.0)


def _rates(h: np.ndarray, q: np.ndarray, bed: np.ndarray, dx: float) -> tuple[np.ndarray, np.ndarray, float]:
    """dh/dt, dq/dt and the largest wave speed. Both ends are transmissive (copied ghosts);
    the right end lies dry beyond the run-up."""
    hp, qp, bp = (np.pad(a, 2, mode="edge") for a in (h, q, bed))
    up = np.where(hp > DRY, qp / np.maximum(hp, DRY), 0.0)
    ep = hp + bp
    s_e, s_h, s_u = (_minmod(a[1:-1] - a[:-2], a[2:] - a[1:-1]) for a in (ep, hp, up))
    hc, ec, uc = hp[1:-1], ep[1:-1], up[1:-1]
    # each (ghost-padded) cell's right (+) and left (-) face values; the bed follows eta - h
    h_p, h_m = np.maximum(hc + 0.5 * s_h, 0.0), np.maximum(hc - 0.5 * s_h, 0.0)
    b_p, b_m = ec + 0.5 * s_e - h_p, ec - 0.5 * s_e - h_m
    u_p, u_m = uc + 0.5 * s_u, uc - 0.5 * s_u
    # face between padded cells i and i+1: left state i's (+), right state i+1's (-)
    hl, hr, ul, ur, bl, br = h_p[:-1], h_m[1:], u_p[:-1], u_m[1:], b_p[:-1], b_m[1:]
    bf = np.maximum(bl, br)
    hls, hrs = np.maximum(0.0, hl + bl - bf), np.maximum(0.0, hr + br - bf)
    cl, cr = np.sqrt(G * hls), np.sqrt(G * hrs)
    sl, sr = np.minimum(ul - cl, ur - cr), np.maximum(ul + cl, ur + cr)
    span = np.where(sr - sl > 1e-12, sr - sl, 1e-12)

    def hll(fl, fr, ql, qr):
        mid = (sr * fl - sl * fr + sl * sr * (qr - ql)) / span
        return np.where(sl >= 0, fl, np.where(sr <= 0, fr, mid))

    f1 = hll(hls * ul, hrs * ur, hls, hrs)
    f2 = hll(hls * ul**2 + 0.5 * G * hls**2, hrs * ur**2 + 0.5 * G * hrs**2, hls * ul, hrs * ur)
    n = h.size
    # the hydrostatic reconstruction's face corrections, and the cell's own slope source
    # (second order: the reconstructed bed across the cell)
    corr_l = 0.5 * G * (hl**2 - hls**2)     # to the face's left cell
    corr_r = 0.5 * G * (hr**2 - hrs**2)     # to the face's right cell
    f1, f2, corr_l, corr_r = f1[: n + 1], f2[: n + 1], corr_l[: n + 1], corr_r[: n + 1]
    src = -G * 0.5 * (h_p[1:-1] + h_m[1:-1]) * (b_p[1:-1] - b_m[1:-1]) / dx
    dh = -(f1[1:] - f1[:-1]) / dx
    dq = -((f2[1:] + corr_l[1:]) - (f2[:-1] + corr_r[:-1])) / dx + src
    return dh, dq, float(max(np.abs(sl).max(), np.abs(sr).max()))


def solitary_runup(height: float, depth: float, cot_beta: float = 19.85, *,
                   cells_per_depth: int = 100,
                   sections: tuple[float, ...] = (1.0, 0.5, 0.25, 0.125, 0.0625, 0.0),
                   courant: float = 0.4) -> SwashReference:
    """Run the NSWE until the shoreline has fallen back a quarter of its run-up (or the wave's
    passage time twice over). ``cells_per_depth``: d / dx (at H/d 0.05, 100 and 50 cells per d
    give R/d 0.303 and 0.293)."""
    if not (height > 0 and depth > 0 and cot_beta > 0):
        raise ValueError("height, depth and cot_beta must be positive")
    if cells_per_depth < 10:
        raise ValueError(f"cells_per_depth: at least 10, got {cells_per_depth}")
    if any(not 0.0 <= s <= 1.0 for s in sections):
        raise ValueError(f"sections: still depths as fractions of d in [0, 1], got {sections}")
    H, d = height, depth
    wave = SolitaryWave(H, depth=d)
    k, c = wave.k, wave.c
    half = math.acosh(math.sqrt(20.0)) / k              # Synolakis' L
    law = synolakis_law(H / d, cot_beta) * d
    dx = d / cells_per_depth
    x0 = -half - 5.0 / k                                 # sech^2(5) = 2e-4: the tail is in
    # dry beach up to three times the law's run-up, at most 2 d above still water (a breaking
    # wave runs up far less than the law); a shoreline that reaches its end is refused below
    x1 = d * cot_beta + min(3.0 * law, 2.0 * d) * cot_beta + 10 * dx
    x = np.arange(x0 + dx / 2, x1, dx)
    bed = np.where(x > 0, x / cot_beta, 0.0) - d
    still = np.maximum(-bed, 0.0)
    eta = H / np.cosh(k * (x + half)) ** 2
    h = np.where(bed < 0, np.maximum(eta - bed, 0.0), 0.0)
    q = np.where(bed < 0, h * c * eta / (d + eta), 0.0)
    masks = {s: x > (1.0 - s) * d * cot_beta for s in sections}
    excess = dict.fromkeys(sections, 0.0)
    t, best_r, t_r, h_r = 0.0, -math.inf, 0.0, h
    t_max = 2.0 * (half + 5.0 / k + d * cot_beta) / math.sqrt(G * d) + 4.0 * half / c
    while t < t_max:
        dh, dq, a = _rates(h, q, bed, dx)
        dt = courant * dx / max(a, 1e-9)
        h1 = np.maximum(h + dt * dh, 0.0)
        q1 = np.where(h1 > DRY, q + dt * dq, 0.0)
        dh1, dq1, _ = _rates(h1, q1, bed, dx)
        h = np.maximum(0.5 * (h + h1 + dt * dh1), 0.0)
        q = np.where(h > DRY, 0.5 * (q + q1 + dt * dq1), 0.0)
        t += dt
        above = h - still
        for s, m in masks.items():
            excess[s] = max(excess[s], float(above[m].sum() * dx))
        wet = np.nonzero(h > WET)[0]
        if wet[-1] >= x.size - 5:
            raise RuntimeError(f"solitary_runup: the shoreline reached the grid's end, "
                               f"{bed[-1]:.3g} m above still water")
        r = float(bed[wet[-1]] + h[wet[-1]])
        if r > best_r:
            best_r, t_r, h_r = r, t, h.copy()
        elif best_r > 0.25 * law and r < 0.75 * best_r:
            break
    return SwashReference(H, d, cot_beta, best_r, t_r, excess, x, bed, h_r)
