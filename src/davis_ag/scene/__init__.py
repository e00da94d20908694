"""Stage 2, the scene: the paper's crop and scenario settings, plants grown with Helios, soil and sun,
and the pure geometry of cameras and the view grid (no Helios import at module level)."""
