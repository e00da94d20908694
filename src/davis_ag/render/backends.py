"""Which renderer draws a scene, and in which look: the names the commands, configs and scene.json use.

- ``opengl`` (default): ours, :class:`davis_ag.render.opengl.OpenGLRenderer`.
- ``helios``: pyhelios's own Visualizer, :class:`davis_ag.render.helios.HeliosRenderer`, kept as
  the reference our renderer is tested against.

Looks (ours only): ``default`` draws textures at full resolution with mipmaps and linear
filtering; ``helios`` reproduces Helios's frames, its reduced, unfiltered textures included.
The Helios renderer always draws the ``helios`` look.
"""

from __future__ import annotations

from davis_ag.errors import UserError
from davis_ag.formats.scene_file import RendererRecord
from davis_ag.scene.camera import Camera
from davis_ag.scene.lighting import Lighting

RENDERERS = ("opengl", "helios")
LOOKS = ("default", "helios")
DEFAULT_RENDERER = "opengl"
DEFAULT_LOOK = "default"


def resolve_look(renderer: str, look: str | None) -> str:
    """The look a renderer will draw: ``look``, or the renderer's own when None.

    Raises:
        UserError: for an unknown renderer or look, or a look the renderer cannot draw.
    """
    if renderer not in RENDERERS:
        raise UserError(f"renderer {renderer!r}: choose {' or '.join(RENDERERS)}")
    if look is not None and look not in LOOKS:
        raise UserError(f"look {look!r}: choose {' or '.join(LOOKS)}")
    if renderer == "helios":
        if look not in (None, "helios"):
            raise UserError("the helios renderer draws only the helios look: drop --look or use --renderer opengl")
        return "helios"
    return look or DEFAULT_LOOK


#: Antialiasing of our renderer's colour (ids and depth are exact in every mode): FXAA along
#: silhouettes of a 1x pass (default), 4x multisampled colour with a 1x id pass, or none.
ANTIALIASING = ("fxaa", "msaa", "none")
DEFAULT_ANTIALIASING = "fxaa"
#: What scene.json says of each mode.
ANTIALIASING_DESCRIPTIONS = {
    "fxaa": "FXAA along silhouettes of one 1x pass that also gives ids and depth",
    "msaa": "4x multisampled colour, ids and depth from a 1x pass",
    "none": "none: one 1x pass",
}
#: Earlier versions took colour samples per pixel: 4 was multisampling, 1 none.
SAMPLES = {"4": "msaa", "1": "none"}


def resolve_antialiasing(value: str | int | None) -> str:
    """An antialiasing mode from a flag or a config value (``fxaa``, ``msaa``, ``none``; the
    samples per pixel earlier versions took, 4 or 1, still mean ``msaa`` and ``none``).

    Raises:
        UserError: naming the value and the choices.
    """
    if value is None:
        return DEFAULT_ANTIALIASING
    if isinstance(value, bool) or not isinstance(value, (str, int)):
        raise UserError(f"antialiasing {value!r}: choose one of {', '.join(ANTIALIASING)}")
    text = str(value).strip().lower()
    text = SAMPLES.get(text, text)
    if text not in ANTIALIASING:
        raise UserError(f"antialiasing {value!r}: choose one of {', '.join(ANTIALIASING)}")
    return text


def antialiasing_of(renderer: RendererRecord) -> str:
    """The antialiasing mode a scene.json's renderer entry names: its description (as
    :data:`ANTIALIASING_DESCRIPTIONS` writes it), Helios's Visualizer
    (4x multisampling), or an earlier version's 4x / 1x wording."""
    text = renderer.antialiasing or ""
    by_description = {description: mode for mode, description in ANTIALIASING_DESCRIPTIONS.items()}
    if text in by_description:
        return by_description[text]
    return "msaa" if text.startswith("4x") or renderer.name == "helios" else "none"


def open_renderer(
    renderer: str,
    context,
    camera: Camera,
    lighting: Lighting,
    look: str | None = None,
    antialiasing: str = DEFAULT_ANTIALIASING,
):
    """A renderer of a scene; use it as a context manager.

    Args:
        renderer: ``opengl`` or ``helios``.
        context: The scene's Helios Context.
        camera: Image size and field of view.
        lighting: Sun and sky.
        look: ``default`` or ``helios`` (None: the renderer's default).
        antialiasing: Ours only: one of :data:`ANTIALIASING`. Ids are exact in every mode.

    Returns:
        An object with ``render(view) -> (colour, primitive_ids, depth)`` and ``close()``.
    """
    look = resolve_look(renderer, look)
    if renderer == "helios":
        from davis_ag.render.helios import HeliosRenderer

        return HeliosRenderer(context, camera, lighting)
    from davis_ag.render.opengl import OpenGLRenderer

    return OpenGLRenderer(context, camera, lighting, look=look, antialiasing=resolve_antialiasing(antialiasing))
