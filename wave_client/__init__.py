"""wavesph wave_client: wave models (analytic theories, the Nwogu Boussinesq model) and the
coupling client that drives an SPH server with them over the protocol."""

G = 9.81  # gravitational acceleration [m/s^2]: one value for every wave model (raschii's default)
