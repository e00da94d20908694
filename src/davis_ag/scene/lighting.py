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
    """

    sun_elevation: float
    sun_azimuth: float
    sky_texture: str | None = None

    @property
    def direction(self) -> tuple[float, float, float]:
        """Unit vector towards the sun."""
        el, az = math.radians(self.sun_elevation), math.radians(self.sun_azimuth)
        return (math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el))
