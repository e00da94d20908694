"""Which renderer draws: the name a bench table prints, and whether it is a GPU's."""

from __future__ import annotations

import pytest

from davis_ag.render.egl_context import draws_on_gpu, renderer_name


@pytest.mark.parametrize(
    ("renderer", "gpu"),
    [
        ("llvmpipe (LLVM 15.0.6, 256 bits)", False),  # Mesa on the CPU, this project's machine
        ("softpipe", False),
        ("SwiftShader Device (LLVM 10.0.0)", False),
        ("NVIDIA H200/PCIe/SSE2", True),  # NVIDIA's EGL driver, as a lent machine reported it
        ("AMD Radeon Graphics (radeonsi, gfx1030, LLVM 15.0.7, DRM 3.49)", True),
    ],
)
def test_a_software_rasteriser_is_not_a_gpu(renderer: str, gpu: bool) -> None:
    assert draws_on_gpu(renderer) is gpu


def test_the_renderer_that_draws_here_is_named() -> None:
    name = renderer_name()
    assert name.strip() and draws_on_gpu(name) == ("llvmpipe" not in name.lower())
