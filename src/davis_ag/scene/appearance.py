"""A scene's appearance: the paper's (one kind of sky, soil and exposure) or randomised per scene.

For sim-to-real work (section VI-A of the paper) synthetic images usually need varied light and
surfaces. ``random`` draws, per scene and from the scene's seed alone (a stream of its own, so
the plants, the grid and the paper's sun draws are the same as under ``paper``):

- the sun's direction (elevation 20-80 deg, any azimuth) and strength (0.45-1.35 x the paper's
  direct light);
- the sky, one of Helios's sky images (:data:`SKIES`), and the soil, one of its ground textures
  (:data:`SOILS`);
- exposure (0.6-1.6 x, log-uniform) and white balance (red and blue gains 1 +- up to 0.12, as
  a colour temperature shift; green 1);
- sensor noise: Gaussian, standard deviation 0.5-4 grey levels of 255, drawn anew for every
  view from the scene seed and the view's number (so a resumed scene writes the same pixels) by
  the renderer's fragment shaders, in the same pass (:mod:`davis_ag.render.opengl`).

Labels do not change: ids, masks, classes and depth come from the geometry, which appearance
leaves alone. ``paper`` changes nothing: its scenes are the ones drawn before this option.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace
from typing import Final, Literal, get_args

from davis_ag.errors import UserError
from davis_ag.scene.lighting import Lighting
from davis_ag.seeds import APPEARANCE_STREAM, stream_rng

AppearanceMode = Literal["paper", "random"]
APPEARANCES: tuple[str, ...] = get_args(AppearanceMode)
DEFAULT_APPEARANCE: Final = "paper"
#: The paper's soil image.
PAPER_SOIL = "dirt.jpg"
#: Helios's sky images (pyhelios3d's Visualizer textures), equirectangular.
SKIES = ("SkyDome_clouds.jpg", "SkyDome_field.jpg", "SkyDome_mountains.jpg", "SkyDome_trees.jpg")
#: Helios's ground textures: bare soil and grass cover.
SOILS = ("dirt.jpg", "dirt2.jpg", "grass2.jpg", "grass3.jpg")
SUN_ELEVATION = (20.0, 80.0)
SUN_STRENGTH = (0.45, 1.35)
EXPOSURE = (0.6, 1.6)
WHITE_BALANCE_SHIFT = 0.12
NOISE_SIGMA = (0.5, 4.0)


@dataclass(frozen=True)
class Appearance:
    """What a scene looks like beyond its geometry.

    Attributes:
        mode: ``paper`` or ``random``.
        soil: Soil texture (a Helios texture file name).
        sky: Sky texture, or None for Helios's default sky.
        sun_elevation, sun_azimuth: Direction towards the sun, deg; None keeps the paper's draw.
        sun_strength: Factor on the sun's direct light.
        exposure: Factor on the radiance before the tone curve.
        white_balance: Gains on linear red, green and blue.
        noise_sigma: Sensor noise, standard deviation in grey levels (0-255); 0 for none.
        seed: The scene seed (the sensor noise's, with each view's number).
    """

    mode: str
    soil: str = PAPER_SOIL
    sky: str | None = None
    sun_elevation: float | None = None
    sun_azimuth: float | None = None
    sun_strength: float = 1.0
    exposure: float = 1.0
    white_balance: tuple[float, float, float] = (1.0, 1.0, 1.0)
    noise_sigma: float = 0.0
    seed: int = 0

    def lighting(self, base: Lighting) -> Lighting:
        """The scene's lighting: ``base`` (the paper's sun) with what this appearance draws."""
        from davis_ag.scene.build import helios_texture

        if self.mode == "paper":
            return base
        return replace(
            base,
            sun_elevation=base.sun_elevation if self.sun_elevation is None else self.sun_elevation,
            sun_azimuth=base.sun_azimuth if self.sun_azimuth is None else self.sun_azimuth,
            sky_texture=helios_texture(self.sky) if self.sky else None,
            sun_strength=self.sun_strength,
            exposure=self.exposure,
            white_balance=self.white_balance,
            noise_sigma=self.noise_sigma,
            noise_seed=self.seed,
        )

    def summary(self) -> dict:
        """JSON-ready record for scene.json."""
        record = asdict(self)
        record.pop("seed")
        record["white_balance"] = list(self.white_balance)
        record["noise"] = (
            "gaussian per pixel, per view, seeded by (scene seed, view number)" if self.noise_sigma else None
        )
        return record


def resolve_appearance(value: str | None) -> str:
    """An appearance name from a flag or config value.

    Raises:
        UserError: naming the value and the choices.
    """
    if value is None:
        return DEFAULT_APPEARANCE
    text = str(value).strip().lower()
    if text not in APPEARANCES:
        raise UserError(f"appearance {value!r}: choose {' or '.join(APPEARANCES)}")
    return text


def draw_appearance(mode: str, scene_seed: int) -> Appearance:
    """A scene's appearance, drawn from its seed alone (see the module docstring).

    Args:
        mode: ``paper`` or ``random``.
        scene_seed: The scene's seed.
    """
    mode = resolve_appearance(mode)
    if mode == "paper":
        return Appearance("paper", seed=scene_seed)
    rng = stream_rng(scene_seed, APPEARANCE_STREAM)
    shift = float(rng.uniform(-WHITE_BALANCE_SHIFT, WHITE_BALANCE_SHIFT))
    return Appearance(
        mode="random",
        soil=str(rng.choice(SOILS)),
        sky=str(rng.choice(SKIES)),
        sun_elevation=float(rng.uniform(*SUN_ELEVATION)),
        sun_azimuth=float(rng.uniform(0.0, 360.0)),
        sun_strength=float(rng.uniform(*SUN_STRENGTH)),
        exposure=float(math.exp(rng.uniform(math.log(EXPOSURE[0]), math.log(EXPOSURE[1])))),
        white_balance=(1.0 + shift, 1.0, 1.0 - shift),
        noise_sigma=float(rng.uniform(*NOISE_SIGMA)),
        seed=scene_seed,
    )
