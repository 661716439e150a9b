"""wavesph protocol package."""
