"""wavesph wave_client package."""
