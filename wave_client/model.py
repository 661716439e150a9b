"""The `WaveModel` contract: what the coupling client needs from any wave model.

Analytic theories (`wave_client.theories`), the Boussinesq solver (`wave_client.boussinesq`) and
any third-party model plug into the coupling client through this duck type; `sph_core`'s boundary
adapters accept the same duck type without importing this module.

Vertical datum: wave models measure z upward **from the still-water level** (z = 0 at the
still surface, z = -depth at the bed). SPH scenes use absolute coordinates; whoever crosses the
two (the coupling client, the SPH boundary adapters) converts explicitly.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike


@runtime_checkable
class WaveModel(Protocol):
    """A wave model that the coupling client can drive window by window.

    Attributes
    ----------
    t:
        The model's current time [s].
    depth:
        Still-water depth at the coupling boundary [m] (used by the absorption correction,
        v = v_theory - Δη·sqrt(g/d)).
    """

    t: float
    depth: float

    def advance_to(self, t: float) -> None:
        """Advance the model to time ``t`` [s]. Analytic theories just set ``self.t``."""
        ...

    def elevation(self, x: ArrayLike) -> np.ndarray:
        """Free-surface elevation eta(x, self.t) [m] above the still-water level."""
        ...

    def velocity(self, x: ArrayLike, z: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """Velocity (u, w) [m/s] at (x, z) and ``self.t``; x and z broadcast together.

        z is measured up from the still-water level, z in [-depth, eta(x)]. Above the
        instantaneous surface a model returns a finite value (never NaN) and documents which.
        """
        ...

    def impose(self, x: float, eta: float, u_ref: float) -> None:
        """Two-way feedback: the elevation eta [m] and the velocity u_ref [m/s] at the reference
        depth measured by SPH at x, for the model's next step. Analytic theories ignore it."""
        ...
