"""Nwogu extended Boussinesq far-field wave model (1D horizontal, variable depth).

`BoussinesqModel` satisfies `wave_client.model.WaveModel`; `wavesph waves SCENE.toml` runs it
alone (`wave_scene.py`, `standalone.py`, `wavesph/cli/waves.py`).
"""

from .dispersion import airy_celerity, nwogu_celerity, nwogu_wavenumber
from .solitary import kdv_solitary, nwogu_solitary, solitary_approach
from .solver import BoussinesqModel, BoussinesqUnstableError

__all__ = ["BoussinesqModel", "BoussinesqUnstableError", "airy_celerity", "kdv_solitary",
           "nwogu_celerity", "nwogu_solitary", "nwogu_wavenumber", "solitary_approach"]
