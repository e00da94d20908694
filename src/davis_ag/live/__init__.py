"""Stage 11, views on demand: a generated scene reopened live, drawn from any pose, and the continuous-pose
visibility environment (``davis_ag/TVMContinuous-v0``) built on it.

This stage comes after ``benchmark``: it regrows plants and renders (so it needs ``generate``,
``render`` and ``labels``), and it reuses the benchmark's scene selection and reward. The grid
benchmark (TVM-v0) stays free of Helios and renderers; this one cannot be.
"""
