"""davis-ag: generate, read and benchmark DAVIS-Ag active-vision datasets."""

__version__ = "0.1.0"

from davis_ag import benchmark as _benchmark  # noqa: E402,F401 - registers davis_ag/TVM-v0
