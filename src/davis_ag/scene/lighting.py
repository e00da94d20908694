"""The sun and sky of a scene: a fixed light, so one shadow map serves every view."""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Lighting:
    """Sun and sky of a scene.

    Attributes:
        sun_elevation, sun_azimuth: Direction towards the sun, degrees (azimuth from +x, CCW).
        sky_texture: Equirectangular sky image shipped with Helios, or None for its default.
        sun_strength: Factor on the sun's direct light (our renderer; 1 in the paper's look).
        exposure: Factor on the radiance before the tone curve (our renderer).
        white_balance: Gains on linear red, green and blue (our renderer).
        noise_sigma: Sensor noise, standard deviation in grey levels of 255 (our renderer; 0: none).
        noise_seed: Seed of the sensor noise, combined with each view's number.
    """

    sun_elevation: float
    sun_azimuth: float
    sky_texture: str | None = None
    sun_strength: float = 1.0
    exposure: float = 1.0
    white_balance: tuple[float, float, float] = (1.0, 1.0, 1.0)
    noise_sigma: float = 0.0
    noise_seed: int = 0

    @property
    def is_paper(self) -> bool:
        """Whether only the sun's direction and sky differ from the paper's look (what Helios draws)."""
        return (self.sun_strength, self.exposure, tuple(self.white_balance), self.noise_sigma) == (
            1.0,
            1.0,
            (1.0, 1.0, 1.0),
            0.0,
        )

    @property
    def direction(self) -> tuple[float, float, float]:
        """Unit vector towards the sun."""
        el, az = math.radians(self.sun_elevation), math.radians(self.sun_azimuth)
        return (math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el))
