"""davis-ag: generate, read and benchmark DAVIS-Ag active-vision datasets."""

__version__ = "0.1.0"
