"""Question: how much does each integrator amplify a sound wave per step, and why does the
leapfrog's pressure read the density a full step ahead of its half-step value?

    python bench/leapfrog_acoustics.py

Linear acoustics of one Fourier mode, the way ``sph_core/wcsph.py`` advances it: dv/dt = -i k
c^2/rho0 rho', drho'/dt = D = -i k rho0 v, with s = k c dt the mode's phase per step (dt = cfl h
/ c, so s = cfl k h: about 0.1-0.4 for the modes an SPH kernel resolves at cfl 0.25). Each
integrator is written as the linear map of one step on its stored state; the largest |eigenvalue|
of that map is the amplification per step (1: neutral, > 1: the mode grows with nothing to damp it
but delta-SPH and artificial viscosity).

- ``kdk``: the leapfrog as in ``kdk_kick_drift`` / ``kdk_kick``: half-kick v and rho with the
  stored rates (D from v^{n-1/2}, the last force pass's velocity), drift, the force pass reads p
  from rho^{n+1/2} + e dt/2 D and computes D from v^{n+1/2}, half-kick again. ``e`` = 1 puts
  the density at t^n + dt (rho^n + dt D), e = 2 one full step past its half-step value.
- ``symplectic_pc``: ``pc_predict`` / ``pc_correct`` linearised (rho (2 - eps)/(2 + eps) ->
  rho + dt D).

One JSON object per integrator with ``integrator``, ``e`` and ``growth_per_step`` at each s (the
largest |eigenvalue| - 1).
"""

from __future__ import annotations

import json

import numpy as np

S_VALUES = (0.05, 0.1, 0.2, 0.3, 0.4)


def kdk_map(s: float, e: float) -> np.ndarray:
    """One leapfrog step on (v, rho, a, D) in units c = rho0 = dt = 1, k = s."""
    ik = 1j * s
    m = np.zeros((4, 4), complex)
    for col in range(4):
        v, r, a, d = np.eye(4)[col].astype(complex)
        v += 0.5 * a
        r += 0.5 * d
        p = r + e * 0.5 * d          # the density the force pass turns into pressure
        a, d = -ik * p, -ik * v      # the force pass: a from p, D from v^{n+1/2}
        v += 0.5 * a
        r += 0.5 * d
        m[:, col] = (v, r, a, d)
    return m


def pc_map(s: float) -> np.ndarray:
    """One symplectic predictor-corrector step on (v, rho)."""
    ik = 1j * s
    m = np.zeros((2, 2), complex)
    for col in range(2):
        v0, r0 = np.eye(2)[col].astype(complex)
        vh, rh = v0 + 0.5 * (-ik * r0), r0 + 0.5 * (-ik * v0)
        m[:, col] = (v0 - ik * rh, r0 - ik * vh)
    return m


def growth(m: np.ndarray) -> float:
    return float(np.max(np.abs(np.linalg.eigvals(m))) - 1.0)


def main() -> None:
    rows = [("kdk", 1.0, lambda s: kdk_map(s, 1.0)), ("kdk", 2.0, lambda s: kdk_map(s, 2.0)),
            ("symplectic_pc", None, pc_map)]
    for name, e, make in rows:
        print(json.dumps({"integrator": name, "e": e,
                          "growth_per_step": {f"s={s}": float(f"{growth(make(s)):.3g}")
                                              for s in S_VALUES}}))


if __name__ == "__main__":
    main()
