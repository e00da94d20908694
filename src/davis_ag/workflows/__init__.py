"""Stage 12, workflows: ``demo`` and ``reproduce`` composed from the stages before."""
