"""Analytic wave theories behind the `WaveModel` contract (`wave_client.model`).

    from wave_client.theories import build_theory
    wave = build_theory("stokes", height=0.08, period=2.0, depth=1.0, order=2, ramp_time=4.0)
    wave.advance_to(1.3)
    eta = wave.elevation([0.0, 0.5])                    # [m] above still water
    u, w = wave.velocity(0.0, np.linspace(-1.0, 0.0, 20))  # z up from still water

Conventions: SI units, z up from the still-water level (bed at z = -depth), waves travel
towards +x, above the instantaneous surface the surface velocity is returned (never NaN).
"""

from __future__ import annotations

import inspect
from typing import Any

from wave_client.theories.base import G, WaveTheory, ramp_factor
from wave_client.theories.irregular import JonswapSea, jonswap_shape
from wave_client.theories.linear import AiryWave, StandingWave, wavenumber
from wave_client.theories.nonlinear import StokesWave, StreamFunctionWave
from wave_client.theories.solitary_wave import SolitaryWave

__all__ = [
    "G",
    "THEORIES",
    "AiryWave",
    "JonswapSea",
    "SolitaryWave",
    "StandingWave",
    "StokesWave",
    "StreamFunctionWave",
    "WaveTheory",
    "build_theory",
    "jonswap_shape",
    "ramp_factor",
    "wavenumber",
]

THEORIES: dict[str, type[WaveTheory]] = {
    "linear": AiryWave,
    "stokes": StokesWave,
    "stream": StreamFunctionWave,
    "standing": StandingWave,
    "irregular": JonswapSea,
    "solitary": SolitaryWave,
}


def build_theory(name: str, *, height: float, period: float | None, depth: float,
                 **options: Any) -> WaveTheory:
    """Build a theory by name; for ``irregular`` height is Hs and period is Tp; ``solitary``
    takes no period (None) and ``t0``, the time its crest passes x = 0.

    ``options`` are the class's keyword arguments (``ramp_time``, ``order``, ``n_fourier``,
    ``gamma``, ``n_components``, ``seed``, ``g``...); an unknown one is a ValueError.
    """
    try:
        cls = THEORIES[name]
    except KeyError:
        raise ValueError(f"model must be one of {sorted(THEORIES)}, got {name!r}") from None
    allowed = set(inspect.signature(cls.__init__).parameters) - {"self"}
    unknown = sorted(set(options) - allowed)
    if unknown:
        raise ValueError(f"model {name!r} takes no option(s) {unknown}; it takes {sorted(allowed)}")
    if period is None and cls is not SolitaryWave:
        raise ValueError(f"period: model {name!r} needs a wave period")
    return cls(height, period, depth, **options)
