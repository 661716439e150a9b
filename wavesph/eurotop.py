"""EurOtop (2018) design formulas for smooth impermeable slopes, the empirical reference an
engineer checks a run's overtopping and run-up against.

EurOtop, Manual on wave overtopping of sea defences and related structures, 2nd ed. (2018),
Van der Meer, Allsop, Bruce, De Rouck, Kortenhaus, Pullen, Schüttrumpf, Troch, Zanuttigh;
www.overtopping-manual.com. Chapter 5, mean value approach (the formulas with the mean of the
fitted coefficients, for comparison with measurements; design adds one standard deviation).
Influence factors gamma_b (berm), gamma_f (roughness), gamma_beta (obliquity) and gamma_v
(vertical wall on the slope) are 1 for a smooth straight slope under normal incidence.

Breaker parameter xi_m-1,0 = tan(alpha) / sqrt(Hm0 / L_m-1,0), L_m-1,0 = g T_m-1,0^2 / (2 pi),
Hm0 and T_m-1,0 = m_-1 / m_0 of the incident waves at the toe.

Mean overtopping discharge q [m^3/s per m], eq. 5.10 (breaking) with its maximum eq. 5.11:

    q / sqrt(g Hm0^3) = a / sqrt(tan alpha) gamma_b xi exp(-(b Rc / (xi Hm0 gamma_b gamma_f gamma_beta gamma_v))^1.3)
    q / sqrt(g Hm0^3) <= c exp(-(d Rc / (Hm0 gamma_f gamma_beta))^1.3)

a = 0.023 (sigma 0.003), b = 2.7 (sigma 0.20), c = 0.09 (sigma 0.0135), d = 1.5 (sigma 0.15).

Run-up level exceeded by 2 % of the incident waves, eq. 5.1 with its maximum eq. 5.2:

    Ru2% / Hm0 = 1.65 gamma_b gamma_f gamma_beta xi,  at most  1.00 gamma_f gamma_beta (4 - 1.5 / sqrt(gamma_b xi))
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from wave_client import G

# (mean, standard deviation) of the mean-value coefficients, EurOtop (2018) section 5.3
A_BREAKING = (0.023, 0.003)
B_BREAKING = (2.7, 0.20)
C_LIMIT = (0.09, 0.0135)
D_LIMIT = (1.5, 0.15)


def breaker_parameter(hm0: float, tm10: float, tan_alpha: float, g: float = G) -> float:
    """xi_m-1,0 of the incident sea (Hm0 [m], T_m-1,0 [s]) on a slope tan(alpha)."""
    for name, v in (("hm0", hm0), ("tm10", tm10), ("tan_alpha", tan_alpha)):
        if not v > 0:
            raise ValueError(f"{name}: must be > 0, got {v}")
    return tan_alpha / math.sqrt(hm0 / (g * tm10**2 / (2.0 * math.pi)))


@dataclass(frozen=True)
class Overtopping:
    """EurOtop mean q [m^2/s] with its band (each coefficient one standard deviation towards less
    water, q_lo, and more, q_hi), xi_m-1,0 and the governing equation."""

    q: float
    q_lo: float
    q_hi: float
    xi: float
    regime: str


def smooth_slope_overtopping(hm0: float, tm10: float, rc: float, tan_alpha: float,
                             gamma_f: float = 1.0, gamma_beta: float = 1.0, gamma_b: float = 1.0,
                             gamma_v: float = 1.0, g: float = G) -> Overtopping:
    """EurOtop (2018) eq. 5.10 / 5.11, mean value approach: the mean overtopping discharge of a
    sea (Hm0 [m], T_m-1,0 [s] at the toe) over a slope tan(alpha) with crest freeboard Rc [m]."""
    if rc < 0:
        raise ValueError(f"rc: the freeboard must be >= 0 m (an emerged crest), got {rc}")
    xi = breaker_parameter(hm0, tm10, tan_alpha, g)

    def q_at(shift: float) -> tuple[float, str]:
        a, b = A_BREAKING[0] + shift * A_BREAKING[1], B_BREAKING[0] - shift * B_BREAKING[1]
        c, d = C_LIMIT[0] + shift * C_LIMIT[1], D_LIMIT[0] - shift * D_LIMIT[1]
        breaking = a / math.sqrt(tan_alpha) * gamma_b * xi * math.exp(
            -((b * rc / (xi * hm0 * gamma_b * gamma_f * gamma_beta * gamma_v)) ** 1.3))
        limit = c * math.exp(-((d * rc / (hm0 * gamma_f * gamma_beta)) ** 1.3))
        scale = math.sqrt(g * hm0**3)
        if breaking <= limit:
            return breaking * scale, "breaking (eq. 5.10)"
        return limit * scale, "non-breaking maximum (eq. 5.11)"

    q, regime = q_at(0.0)
    return Overtopping(q, q_at(-1.0)[0], q_at(+1.0)[0], xi, regime)


def smooth_slope_ru2(hm0: float, tm10: float, tan_alpha: float, gamma_f: float = 1.0,
                     gamma_beta: float = 1.0, gamma_b: float = 1.0, g: float = G) -> float:
    """EurOtop (2018) eq. 5.1 / 5.2, mean value approach: Ru2% [m above still water]."""
    xi = breaker_parameter(hm0, tm10, tan_alpha, g)
    rising = 1.65 * gamma_b * gamma_f * gamma_beta * xi
    limit = gamma_f * gamma_beta * (4.0 - 1.5 / math.sqrt(gamma_b * xi))
    return hm0 * min(rising, limit)
