"""A smooth 1:2 seawall under an irregular sea: the overtopping case (bench/overtopping.py,
examples/scenes/seawall_overtopping.toml).

The flume (2D, per metre of width): still water SEAWALL_DEPTH on a flat floor z = 0, an open
inlet at x = 0 (imposed elevation, active absorption), one peak wavelength of flat floor, then a
smooth impermeable slope TAN_ALPHA up to a crest Rc above still water, a crest CREST_WIDTH wide
and a 1:1 back slope into a pit PIT_LENGTH long that keeps the overtopped water (it holds
~0.4 m^3/m, more than 500 waves at the default freeboard put over) over a pool POOL_DEPTH deep.
Probes: `toe`, the elevation half a dp before the slope's toe; `crest`, the overtopping volume
through the crest's landward edge.

The sea: JONSWAP (gamma 3.3) with Hm0 HS and peak period TP, N_COMPONENTS linear components in
[0.5, 3] fp so the record repeats only after ~900 s (500 waves at the toe take ~680 s), ramped over two
peak periods (`sea`).
"""

from __future__ import annotations

import math

import numpy as np

from wave_client.theories import G, JonswapSea
from wave_client.theories.linear import wavenumber

SEAWALL_DEPTH = 0.3   # still water [m]
HS = 0.075            # Hm0 of the source [m]
TP = 1.4              # peak period [s]
JONSWAP_GAMMA = 3.3   # JONSWAP peak enhancement
N_COMPONENTS = 1600   # the record repeats after 1 / df = 896 s
SEED = 1
SEA_RAMP_PERIODS = 2.0
TAN_ALPHA = 0.5       # seaward slope 1:2
CREST_WIDTH = 0.10    # [m]
PIT_LENGTH = 1.2      # [m], behind the 1:1 back slope (to within dp/2: the far wall on the lattice)
POOL_DEPTH = 0.1      # [m] of water at rest in the pit: overtopped water lands in it (on a dry
#                       floor its thin fast sheets left the density band at the pit's far wall)
# excluded particles (density out of band; DualSPHysics' RhopOut removes them without limit):
# splashes in the pit, counted at the crest already, and at Hs/dp 4 the thin run-down films of
# the 1:2 slope (207 over a 558 s record, 0.073 m^3/m against 0.079 overtopped:
# docs/studies/overtopping.md); the limit (default 0.01) still stops a blow-up of the flume
EXCLUDE_LIMIT = 0.3
RC_OVER_HS = 4.0 / 3.0  # default freeboard: Rc = 0.1 m


def sea(seed: int = SEED) -> JonswapSea:
    """The inlet's irregular sea (the example's [source] table)."""
    return JonswapSea(HS, TP, SEAWALL_DEPTH, gamma=JONSWAP_GAMMA, n_components=N_COMPONENTS,
                      seed=seed, ramp_time=SEA_RAMP_PERIODS * TP)


def spectral_hm0_tm10(s: JonswapSea) -> tuple[float, float]:
    """(Hm0, T_m-1,0 = m_-1 / m_0) of a sea's discretised spectrum: the incident sea the inlet
    makes, as EurOtop takes it at the toe."""
    m_1 = float(np.sum(s.spectrum / s.frequencies) * s.df)
    return 4.0 * math.sqrt(s.m0), m_1 / s.m0


def seawall_scene(dp: float, rc: float = RC_OVER_HS * HS, t_end: float = 60.0) -> dict:
    """The scene (a dict for sph_core.scene.make_scene) at spacing ``dp`` [m] with crest
    freeboard ``rc`` [m]."""
    k = float(wavenumber(np.array([2.0 * math.pi / TP]), SEAWALL_DEPTH, G)[0])
    x_toe = dp * round((2.0 * math.pi / k) / dp)
    z_crest = round(SEAWALL_DEPTH + rc, 9)
    x_c0 = x_toe + z_crest / TAN_ALPHA
    x_c1 = x_c0 + CREST_WIDTH
    x_back = x_c1 + z_crest
    # the far wall a whole number of dp from x0: the pool then meets it at spacing dp (a fraction
    # of dp left a gap the pool slumped into at the start; sph_core.geometry warns of it)
    x_end = dp * round((x_back + PIT_LENGTH) / dp)
    return {
        "name": "seawall-overtopping", "dp": dp, "t_end": round(t_end, 4),
        "still_water_level": SEAWALL_DEPTH,
        "tank": {"x0": 0.0, "x1": round(x_end, 6), "z0": 0.0,
                 "z1": round(z_crest + 2.5 * HS, 6)},
        "water_blocks": [{"x0": 0.0, "x1": round(x_toe + SEAWALL_DEPTH / TAN_ALPHA, 6), "z0": 0.0,
                          "z1": SEAWALL_DEPTH},
                         {"x0": round(x_c1, 6), "x1": round(x_end, 6), "z0": 0.0,
                          "z1": POOL_DEPTH}],
        "beds": [{"points": [[x_toe, 0.0], [round(x_c0, 6), z_crest], [round(x_c1, 6), z_crest],
                             [round(x_back, 6), 0.0]]}],
        "open_boundaries": [{"side": "left", "elevation": "imposed"}],
        "constants": {"exclude_limit": EXCLUDE_LIMIT},
        "output": {"probe_every": 0.05},
        "probes": [{"kind": "elevation", "name": "toe", "x": round(x_toe - 0.5 * dp, 6)},
                   {"kind": "overtopping", "name": "crest", "x": round(x_c1, 6)}],
    }
