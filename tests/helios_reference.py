"""A mark for the render checks that take Helios's Visualizer's pixels as the reference.

Through a GPU's EGL driver Helios's Visualizer drew silhouettes wider than the camera model's (an
NVIDIA H200, docs/rendering.md), so these checks hold where it draws on llvmpipe, as on CI and the
2-core machine; on a GPU machine they are skipped with the reason, and our renderer's own checks
against the camera model still run.
"""

from __future__ import annotations

import pytest

from davis_ag.render.egl_context import draws_on_gpu, renderer_name

helios_reference = pytest.mark.skipif(
    draws_on_gpu(renderer_name()),
    reason="Helios's Visualizer draws wider silhouettes through a GPU's driver than on llvmpipe "
    "(docs/rendering.md): its pixels are the reference on llvmpipe only",
)
