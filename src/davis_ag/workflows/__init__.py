"""Stage 8, workflows: ``demo`` and ``reproduce`` composed from the stages before."""
