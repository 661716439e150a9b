"""wavesph server package."""
