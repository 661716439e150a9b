"""The built-in wave source of a standalone run: its request body and its validation.

    POST /runs {"scene": {... open_boundaries ...}, "mode": "standalone",
                "source": {"theory": "stokes", "H": 0.04, "T": 1.4, "order": 2, "ramp_periods": 2}}

The theory is wave_client's; server/theory_client.py drives it through the coupling door, so the
run takes a coupled run's path exactly.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, Literal

from pydantic import BaseModel, ConfigDict, Field

from wave_client.theories import build_theory

if TYPE_CHECKING:
    from sph_core.scene import Scene

# options each theory takes beyond H, T (build_theory keyword names)
THEORY_OPTIONS: dict[str, tuple[str, ...]] = {
    "linear": (), "stokes": ("order",), "stream": ("n_fourier",),
    "irregular": ("gamma", "n_components", "seed"), "solitary": ("t0",),
}
# first word of a build_theory error -> the body field it is about
_ERROR_FIELD = {"height": "H", "period": "T", "t0": "t0", "hs": "H", "tp": "T", "order": "order",
                "n_fourier": "n_fourier", "gamma": "gamma", "n_components": "n_components"}


class TheorySource(BaseModel):
    """A built-in wave source for a standalone run (``wave_client.theories``), SI units.

    Waves travel towards +x; the model's x origin is the SPH inlet face (x_model = x_SPH - x0)."""

    model_config = ConfigDict(extra="forbid")

    theory: Literal["linear", "stokes", "stream", "irregular", "solitary"] = Field(
        description="linear (Airy), stokes (order 2-5), stream (Fenton stream function), "
                    "irregular (JONSWAP; H = Hs, T = Tp), solitary (one KdV solitary wave; no T)")
    H: float = Field(gt=0, description="wave height [m] (Hs for irregular)")
    T: float | None = Field(None, gt=0, description="wave period [s] (Tp for irregular); "
                                                    "required except for solitary, which has none")
    ramp_periods: float = Field(2.0, ge=0, description="start-up ramp length in periods "
                                                       "(not for solitary: it starts from rest)")
    window: float | None = Field(None, gt=0, description="coupling window [s]; default "
                                                         "min(coupling.window_max, T/50)")
    order: int | None = Field(None, description="stokes: order 2-5 (default 5)")
    n_fourier: int | None = Field(None, description="stream: Fourier terms 2-64 (default 10)")
    gamma: float | None = Field(None, gt=0, description="irregular: JONSWAP peak enhancement")
    n_components: int | None = Field(None, gt=0, description="irregular: number of components")
    seed: int | None = Field(None, description="irregular: random phases seed")
    t0: float | None = Field(None, description="solitary: time [s] the crest passes the inlet "
                                               "face (default: eta there starts at 1e-3 H)")

    def options(self) -> dict[str, Any]:
        return {k: getattr(self, k) for k in THEORY_OPTIONS[self.theory] if getattr(self, k) is not None}

    def build(self, depth: float) -> Any:
        """The wave model at still-water depth ``depth`` [m] (ValueError names the parameter)."""
        if self.theory == "solitary":
            return build_theory("solitary", height=self.H, period=None, depth=depth,
                                **self.options())
        if self.T is None:
            raise ValueError(f"period: the {self.theory} theory needs T")
        return build_theory(self.theory, height=self.H, period=self.T, depth=depth,
                            ramp_time=self.ramp_periods * self.T, **self.options())


def source_errors(scene: "Scene", mode: str, source: TheorySource | None,
                  window_max: float = math.inf) -> list[tuple[list[str], str]]:
    """(location in the POST body, message) of what is wrong with ``source`` for this scene."""
    if source is None:
        if mode == "standalone" and scene.open_boundaries:
            return [(["source"], "a standalone run of a scene with open boundaries needs a wave "
                                 "source, e.g. {\"theory\": \"stokes\", \"H\": 0.04, \"T\": 1.4, "
                                 "\"order\": 2}; or use mode 'coupled' with a client")]
        return []
    if mode != "standalone" or not scene.open_boundaries:
        return [(["source"], "a wave source drives the open boundaries of a standalone run: "
                             "only for mode 'standalone' and a scene with open_boundaries")]
    errors = [(["source", name], f"the {source.theory} theory takes no {name} (it takes "
                       f"{list(THEORY_OPTIONS[source.theory]) or 'only H, T, ramp_periods, window'})")
              for name in ("order", "n_fourier", "gamma", "n_components", "seed", "t0")
              if getattr(source, name) is not None and name not in THEORY_OPTIONS[source.theory]]
    if (source.T is None) != (source.theory == "solitary"):
        errors.append((["source", "T"], "the solitary theory has no period: leave T out"
                       if source.theory == "solitary" else f"the {source.theory} theory needs T "
                                                            "[s], the wave period"))
    if source.window is not None and source.window > window_max:
        errors.append((["source", "window"], f"{source.window} s exceeds coupling.window_max = "
                                             f"{window_max} s"))
    if errors:
        return errors
    depth = float(scene.still_water_level) - scene.tank.z0
    try:
        source.build(depth)
    except ArithmeticError as exc:  # T = 1e-9 s divides by zero in raschii's breaking check
        return [(["source"], f"the {source.theory} theory cannot be computed for H = {source.H:g} m, "
                             f"T = {source.T:g} s at depth {depth:g} m ({type(exc).__name__})")]
    except ValueError as exc:
        word = str(exc).split("=")[0].split()[0].strip(":").lower()
        return [(["source", _ERROR_FIELD.get(word, "H")], f"{exc} (depth {depth:g} m at the inlet)")]
    return []
