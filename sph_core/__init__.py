"""wavesph sph_core package."""
