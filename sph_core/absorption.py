"""Gain of the open ends' active absorption (seed 002 correction): du = n_x G (eta_meas - eta_gauge).

The buffer adds one velocity du, uniform over the depth, to the source's profile: it is a piston
wave maker that must emit the wave cancelling the unwanted one the gauge sees. A linear
progressive wave eta = a cos(k x - omega t) in depth d carries the volume flux
    q = int_{-d}^{0} u dz = (omega / k) eta        (mass: d eta/dt + dq/dx = 0)
(equivalently, the depth mean of u = a omega cosh k(z + d) / sinh kd cos(...) is a omega/(k d)).
A depth-uniform velocity carrying that flux is
    U = q / d = (omega / (k d)) eta = (c / d) eta,   c = omega / k the phase speed,
so the gain that emits (or swallows) exactly the wave the gauge measures is
    G(omega) = omega / (k d) = sqrt(g/d) sqrt(tanh(kd) / kd)            ("linear"),
which tends to the seed-002 shallow-water gain sqrt(g/d) as kd -> 0 ("shallow") and falls
below it with kd: sqrt(g/d) over-drives the absorber by 1 / sqrt(tanh(kd)/kd) - 1 = 1.5 % at
kd 0.3, 9 % at 0.75, 20 % at 1.2, 44 % at 2. A gain G' = rho G re-emits a wave (rho - 1)/(rho + 1)
of the absorbed one: 0.7 / 4.2 / 9 / 18 % at those kd (the evanescent modes of a real piston are
ignored: the buffer is one kernel support wide, well inside the near field, and the gauge 2h
inside the face reads them too). Schaeffer & Klopman (2000) apply c(omega)/d frequency by
frequency with a digital filter; "linear" evaluates it at the source's wave period (the peak
period of a spectrum), exact for regular waves.
"""

from __future__ import annotations

import math
from typing import Any

ABSORPTION_KINDS = ("shallow", "linear")


def linear_wavenumber(omega: float, depth: float, g: float = 9.81) -> float:
    """Linear-dispersion wavenumber k [1/m]: omega^2 = g k tanh(k d) (Newton from Eckart's
    approximation, converged to round-off)."""
    if not (omega > 0 and depth > 0):
        raise ValueError(f"omega ({omega}) and depth ({depth}) must be > 0")
    k0 = omega * omega / g
    k = k0 / math.sqrt(math.tanh(k0 * depth))
    for _ in range(50):
        th = math.tanh(k * depth)
        f = g * k * th - omega * omega
        df = g * th + g * k * depth * (1.0 - th * th)
        step = f / df
        k -= step
        if abs(step) < 1e-14 * k:
            break
    return k


def absorption_gain(kind: str, g: float, depth: float, period: float | None = None) -> float:
    """Gain G [1/s] of the depth-uniform correction du = n_x G (eta_meas - eta_gauge).

    ``shallow``: sqrt(g/d) (seed 002). ``linear``: omega/(k d) at the wave ``period`` [s]
    (module docstring); with no period known it is the shallow gain, its kd -> 0 limit."""
    if kind not in ABSORPTION_KINDS:
        raise ValueError(f"absorption: one of {ABSORPTION_KINDS}, got {kind!r}")
    if not (depth > 0 and g > 0):
        raise ValueError(f"depth ({depth}) and g ({g}) must be > 0")
    shallow = math.sqrt(g / depth)
    if kind == "shallow" or period is None:
        return shallow
    if not (math.isfinite(period) and period > 0):
        raise ValueError(f"absorption period: must be a positive number of seconds, got {period}")
    omega = 2.0 * math.pi / period
    return omega / (linear_wavenumber(omega, depth, g) * depth)


def source_period(source: Any) -> float | None:
    """The wave period [s] a boundary-data source carries, if any: a ``WaveModelBoundary``
    over a theory with ``period`` (regular waves; the peak period of a spectrum)."""
    period = getattr(getattr(source, "model", None), "period", None)
    try:
        period = float(period) if period is not None else None
    except (TypeError, ValueError):
        return None
    return period if period is not None and math.isfinite(period) and period > 0 else None
