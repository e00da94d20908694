"""Our renderer: a Helios scene drawn with OpenGL (moderngl, headless EGL), colour, ids and depth.

Same contract as :class:`davis_ag.render.helios.HeliosRenderer`: built from a scene's Context, a
:class:`~davis_ag.scene.camera.Camera` and its :class:`~davis_ag.scene.lighting.Lighting`;
:meth:`OpenGLRenderer.render` takes a viewpoint and returns the colour image, the primitive ids
and the depth image.

- Geometry: the whole scene in one vertex buffer (:mod:`davis_ag.render.scene_geometry`), read
  from the Context once.
- Lighting as Helios's ``phong_shadowed`` model: diffuse and specular light from the sun, ambient
  light blended between a sky and a ground colour by the normal, shadows, sRGB decoding, Helios's
  colour boost of vertex colours, an ACES-fitted tone curve, the sky dome behind everything.
- One shadow map per scene: the sun is fixed, so the depth of the shadow casters seen from the
  sun is drawn once, fitted to the casters (the plants); the soil receives shadows and casts none.
- Pinhole: Helios's vertical field of view and projection (OpenGL's, pixel centres at +0.5, row 0
  at the top once read back), so ids and depth line up with :meth:`Camera.project`.
- Antialiasing (``antialiasing``): ``"fxaa"`` (default) draws colour, ids and depth in one 1x
  pass, then smooths the colour along silhouettes (where the depth jumps) with FXAA; ``"msaa"``
  draws the colour with 4x multisampling and the ids and depth in a light 1x pass; ``"none"`` is
  the 1x pass alone. Ids and depth are exact in every mode (a multisampled id attachment would mix
  ids at edges). docs/performance.md measures each against Helios's frames.
- Looks: ``"helios"`` reproduces Helios's frames, its texture handling included (images larger
  than 2048 pixels resized as Helios does, sampled at the nearest texel without mipmaps), to
  test fidelity; ``"default"`` samples every texture at full resolution with mipmaps and linear
  filtering.

Where a GPU with an EGL driver is present, the same code draws on it; which EGL device is used
follows the EGL vendor library's choice (``__EGL_VENDOR_LIBRARY_FILENAMES``); see docs/rendering.md.
"""

from __future__ import annotations

from importlib import resources

import numpy as np

from davis_ag.render.egl_context import create_context, egl_current, egl_restore
from davis_ag.render.projection import camera_matrices, gl_matrix, helios_shadow_box, light_matrix, matmul32
from davis_ag.render.scene_geometry import SceneGeometry, read_scene_geometry
from davis_ag.render.silhouettes import DrawnSilhouettes
from davis_ag.render.textures import default_sky_texture, load_texture, texture_layers
from davis_ag.render.vertices import GROUND_REPEAT, SHADOW_FORMAT, VERTEX_FORMAT, interleaved_vertices
from davis_ag.scene.camera import Camera
from davis_ag.scene.lighting import Lighting
from davis_ag.scene.view_grid import Viewpoint
from davis_ag.seeds import view_noise_seed

LOOKS = ("default", "helios")
#: Helios's shading constants (its Visualizer's defaults): Phong weights and shininess, the
#: ambient sky and ground colours, exposure (the boost of vertex colours: :mod:`davis_ag.render.vertices`).
MATERIAL = (1.0, 0.8, 0.2, 32.0)
SKY_AMBIENT = (0.5, 0.6, 0.75)
GROUND_AMBIENT = (0.35, 0.30, 0.22)
EXPOSURE = 1.0
#: Side of the one shadow map, texels.
SHADOW_MAP_SIZE = 4096
#: Depth offset of the shadow test, in the map's [0, 1] depth (besides a polygon offset).
SHADOW_BIAS = 1e-4


def _shader(name: str) -> str:
    return (resources.files("davis_ag.render") / "shaders" / name).read_text()


def _fragment(name: str, defines: tuple[str, ...] = ()) -> str:
    lines = ["#version 330 core", *(f"#define {d}" for d in defines), _shader("common.glsl"), _shader(name)]
    return "\n".join(lines)


class OpenGLRenderer:
    """Draws views of one scene: colour, primitive ids and depth.

    Args:
        context: The Helios Context with the scene (or a :class:`SceneGeometry` already read).
        camera: Image size and field of view.
        lighting: Sun direction and sky.
        look: ``"default"`` or ``"helios"`` (see the module docstring).
        antialiasing: ``"fxaa"``, ``"msaa"`` or ``"none"`` (see the module docstring).
    """

    def __init__(
        self, context, camera: Camera, lighting: Lighting, look: str = "default", antialiasing: str = "fxaa"
    ) -> None:
        if look not in LOOKS:
            raise ValueError(f"look {look!r}: choose one of {', '.join(LOOKS)}")
        if antialiasing not in ("fxaa", "msaa", "none"):
            raise ValueError(f"antialiasing {antialiasing!r}: choose fxaa, msaa or none")
        self.camera, self.lighting, self.look, self.antialiasing = camera, lighting, look, antialiasing
        geometry = context if isinstance(context, SceneGeometry) else read_scene_geometry(context)
        self.geometry = geometry
        # Our context is current only while we draw: another GL user in this process (Helios's
        # Visualizer) finds its own context current again after every call of ours.
        previous = egl_current()
        self.ctx = create_context()
        try:
            self._build(geometry)
        except BaseException:
            self.close()
            raise
        finally:
            egl_restore(previous)

    # -----------------------------------------------------------------------------------------
    # Set-up

    def _build(self, geometry: SceneGeometry) -> None:
        import moderngl

        ctx = self.ctx
        helios = self.look == "helios"
        look = ("HELIOS_LOOK",) if helios else ()
        # Sensor noise is compiled in only where drawn: llvmpipe would pay for a branch on a uniform.
        noisy = (*look, "SENSOR_NOISE") if self.lighting.noise_sigma > 0 else look
        self._programs = {
            "scene": ctx.program(vertex_shader=_shader("scene.vert"), fragment_shader=_fragment("scene.frag", noisy)),
            "ids": ctx.program(
                vertex_shader=_shader("scene.vert"), fragment_shader=_fragment("scene.frag", ("IDS_ONLY", *look))
            ),
            "shadow": ctx.program(vertex_shader=_shader("shadow.vert"), fragment_shader=_fragment("shadow.frag", look)),
            "sky": ctx.program(vertex_shader=_shader("sky.vert"), fragment_shader=_fragment("sky.frag", noisy)),
        }
        if self.antialiasing == "fxaa":
            self._programs["fxaa"] = ctx.program(
                vertex_shader=_shader("sky.vert"), fragment_shader=_shader("fxaa.frag")
            )
        if self.antialiasing == "none":  # colour and ids without the depth output, for render(depth=False)
            self._programs["no_depth"] = ctx.program(
                vertex_shader=_shader("scene.vert"), fragment_shader=_fragment("scene.frag", ("NO_DEPTH", *noisy))
            )
        # The programs that shade the scene: the same uniforms for each.
        self._shading = [self._programs[k] for k in ("scene", "no_depth") if k in self._programs]
        # Samplers first: the shadow pass below samples leaf textures already.
        for program in self._programs.values():
            self._set(program, "textures", 0)
            self._set(program, "shadow_map", 1)
            self._set(program, "sky", 2)
        self._upload_textures(geometry)
        vertex, order = interleaved_vertices(geometry, ground_repeat=None if helios else GROUND_REPEAT)
        self._vbo = ctx.buffer(vertex.tobytes())
        self._scene = ctx.vertex_array(self._programs["scene"], [(self._vbo, *VERTEX_FORMAT)], skip_errors=True)
        self._ids = ctx.vertex_array(self._programs["ids"], [(self._vbo, *VERTEX_FORMAT)], skip_errors=True)
        if "no_depth" in self._programs:
            self._no_depth = ctx.vertex_array(
                self._programs["no_depth"], [(self._vbo, *VERTEX_FORMAT)], skip_errors=True
            )
        self._silhouettes = DrawnSilhouettes(
            ctx,
            self._programs["ids"],
            self._vbo,
            VERTEX_FORMAT,
            geometry.uuids[order],
            np.ascontiguousarray(vertex["position"]).reshape(-1, 3, 3),
            self.camera,
            self._prepare_view,
        )
        self._shadow = ctx.vertex_array(
            self._programs["shadow"],
            [(self._vbo, *SHADOW_FORMAT)],
            skip_errors=True,
        )
        self._sky = ctx.vertex_array(self._programs["sky"], [])

        # One shadow map for the scene, fitted to the casters.
        lo, hi = geometry.caster_bounds()
        self._light = light_matrix(self.lighting.direction, lo, hi)
        self._shadow_map = ctx.depth_texture((SHADOW_MAP_SIZE, SHADOW_MAP_SIZE))
        self._shadow_map.compare_func = ""
        self._shadow_map.filter = (moderngl.NEAREST, moderngl.NEAREST)
        caster_first = np.lexsort((~geometry.caster[order],))  # casters only, drawn alone
        caster_vertex = vertex.reshape(-1, 3)[caster_first][: int(geometry.caster.sum())].reshape(-1)
        self._caster_vbo = ctx.buffer(caster_vertex.tobytes())
        caster_vao = ctx.vertex_array(
            self._programs["shadow"],
            [(self._caster_vbo, *SHADOW_FORMAT)],
            skip_errors=True,
        )
        shadow_fbo = ctx.framebuffer(depth_attachment=self._shadow_map)
        shadow_fbo.use()
        shadow_fbo.clear(depth=1.0)
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.depth_func = "<="
        ctx.polygon_offset = (1.0, 1.0)
        self._programs["shadow"]["light_projection"].write(gl_matrix(self._light))
        self._bind_textures()
        if caster_vertex.size:
            caster_vao.render(moderngl.TRIANGLES)
        caster_vao.release()
        shadow_fbo.release()

        # Framebuffers: 1x colour, ids and depth (textures, which the FXAA pass samples); the FXAA
        # pass's output, or 4x colour.
        w, h = self.camera.width, self.camera.height
        self._colour = ctx.texture((w, h), 4)
        self._id_buffer = ctx.renderbuffer((w, h), 1, dtype="u4")
        self._depth_buffer = ctx.texture((w, h), 1, dtype="f4")
        depth_test = ctx.depth_renderbuffer((w, h))
        self._fbo = ctx.framebuffer([self._colour, self._id_buffer, self._depth_buffer], depth_test)
        self._colour_fbo = self._fbo  # where the finished colour is read from
        if self.antialiasing == "none":
            self._no_depth_fbo = ctx.framebuffer([self._colour, self._id_buffer], depth_test)
        if self.antialiasing == "fxaa":
            self._colour.filter = (moderngl.LINEAR, moderngl.LINEAR)
            self._colour.repeat_x = self._colour.repeat_y = False
            self._colour_fbo = ctx.framebuffer([ctx.renderbuffer((w, h), 4)])
            self._fxaa = ctx.vertex_array(self._programs["fxaa"], [])
            self._set(self._programs["fxaa"], "colour", 3)
            self._set(self._programs["fxaa"], "depths", 4)
            self._set(self._programs["fxaa"], "texel", (1.0 / w, 1.0 / h))
        if self.antialiasing == "msaa":
            samples = min(4, ctx.max_samples)
            # Colour only: the shader's id and depth outputs have no attachment here and are dropped.
            self._ms_fbo = ctx.framebuffer(
                [ctx.renderbuffer((w, h), 4, samples=samples)], ctx.depth_renderbuffer((w, h), samples=samples)
            )
            self._resolve_fbo = ctx.framebuffer([self._colour])
            self._ids_fbo = ctx.framebuffer([self._id_buffer, self._depth_buffer], ctx.depth_renderbuffer((w, h)))

        # Uniforms that hold for every view.
        for program in (*self._shading, self._programs["ids"]):
            self._set(program, "light_projection", gl_matrix(self._light))
        exposure = EXPOSURE * self.lighting.exposure
        white_balance = tuple(float(v) for v in self.lighting.white_balance)
        self._set(self._programs["sky"], "exposure", exposure)
        self._set(self._programs["sky"], "white_balance", white_balance)
        for program in (*self._shading, self._programs["sky"]):
            self._set(program, "noise_sigma", float(self.lighting.noise_sigma))
        for name, value in (
            ("sun", self.lighting.direction),
            ("exposure", exposure),
            ("sun_strength", float(self.lighting.sun_strength)),
            ("white_balance", white_balance),
            ("sky_ambient", SKY_AMBIENT),
            ("ground_ambient", GROUND_AMBIENT),
            ("material", MATERIAL),
            ("shadow_bias", SHADOW_BIAS),
            ("light_depth_range", float(1.0 / np.linalg.norm(self._light[2, :3]))),
        ):
            for program in self._shading:
                self._set(program, name, value)

    def _upload_textures(self, geometry: SceneGeometry) -> None:
        import moderngl

        ctx = self.ctx
        helios = self.look == "helios"
        data, scale = texture_layers(geometry.texture_files or [], self.look)
        layers, height, width = data.shape[:3]
        self._textures = ctx.texture_array((width, height, layers), 4, data.tobytes(), dtype="f2")
        if helios:
            self._textures.filter = (moderngl.NEAREST, moderngl.NEAREST)
            self._textures.repeat_x = self._textures.repeat_y = False
        else:
            self._textures.build_mipmaps()
            self._textures.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
        for program in self._programs.values():
            if "layer_scale" in program:
                program["layer_scale"].write(scale.tobytes())

        sky = load_texture(self.lighting.sky_texture or default_sky_texture(), "helios" if helios else "default")
        self._sky_texture = ctx.texture((sky.shape[1], sky.shape[0]), 4, sky.tobytes())
        if helios:
            self._sky_texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
        else:
            self._sky_texture.filter = (moderngl.LINEAR, moderngl.LINEAR)
        self._sky_texture.repeat_x, self._sky_texture.repeat_y = True, False
        self._set(self._programs["sky"], "sky_scale", (1.0, 1.0))

    def _bind_textures(self) -> None:
        self._textures.use(0)
        self._shadow_map.use(1)
        self._sky_texture.use(2)

    @staticmethod
    def _set(program, name: str, value) -> None:
        if name in program:
            if isinstance(value, bytes):
                program[name].write(value)
            else:
                program[name].value = value

    # -----------------------------------------------------------------------------------------
    # Drawing

    def _view_uniforms(self, view: Viewpoint) -> None:
        eye = np.asarray(view.position, dtype=np.float64)
        view_matrix, projection = camera_matrices(self.camera, view)
        view_projection = matmul32(projection, view_matrix)
        rotation = view_matrix.astype(np.float64)
        rotation[:3, 3] = 0.0
        for program in (*self._shading, self._programs["ids"]):
            self._set(program, "view_projection", gl_matrix(view_projection))
            self._set(program, "view", gl_matrix(view_matrix))
            self._set(program, "eye", tuple(eye))
        if self.look == "helios":  # Helios computes shadows only inside a box around its camera's view volume
            target = np.asarray(view.look_at(1.0), dtype=np.float64)
            box = helios_shadow_box(self.camera, eye, target, self.lighting.direction)
            for program in self._shading:
                self._set(program, "shadow_box", gl_matrix(box))
        if self.lighting.noise_sigma > 0:  # a new noise pattern for every view, fixed by the scene's seed
            seed = view_noise_seed(self.lighting.noise_seed, view.index, (*view.position, view.yaw, view.pitch))
            for program in (*self._shading, self._programs["sky"]):
                self._set(program, "noise_seed", seed)
        self._set(
            self._programs["sky"],
            "inverse_rotation_projection",
            gl_matrix(np.linalg.inv(projection.astype(np.float64) @ rotation)),
        )

    def _prepare_view(self, view: Viewpoint) -> None:
        """Set the programs' uniforms for ``view`` and bind the textures."""
        self._view_uniforms(view)
        self._bind_textures()

    def draw(self, view: Viewpoint, depth: bool = True) -> None:
        """Draw a view into the renderer's buffers (read them with :meth:`read`); without
        ``depth``, antialiasing ``none`` leaves the depth image out (FXAA needs it)."""
        import moderngl

        ctx = self.ctx
        self._prepare_view(view)
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.depth_func = "<="
        ctx.polygon_offset = (1.0, 1.0)
        if self.antialiasing == "msaa":
            self._pass(self._ms_fbo, self._scene)
            ctx.copy_framebuffer(self._resolve_fbo, self._ms_fbo)
            self._ids_fbo.use()
            self._ids_fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
            self._ids.render(moderngl.TRIANGLES)
        elif not depth and self.antialiasing == "none":
            self._pass(self._no_depth_fbo, self._no_depth)
        else:
            self._pass(self._fbo, self._scene)
        if self.antialiasing == "fxaa":
            self._colour_fbo.use()
            self._colour.use(location=3)
            self._depth_buffer.use(location=4)
            ctx.disable(moderngl.DEPTH_TEST)
            self._fxaa.render(moderngl.TRIANGLES, vertices=3)
            ctx.enable(moderngl.DEPTH_TEST)

    def _pass(self, fbo, vao) -> None:
        """Scene, then the sky where nothing was drawn (its depth is the far plane)."""
        import moderngl

        fbo.use()
        fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        vao.render(moderngl.TRIANGLES)
        self.ctx.polygon_offset = (0.0, 0.0)
        self._sky.render(moderngl.TRIANGLES, vertices=3)
        self.ctx.polygon_offset = (1.0, 1.0)

    def read(self, depth: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        """The last view drawn: colour, primitive ids and depth (None without ``depth``; see :meth:`render`)."""
        w, h = self.camera.width, self.camera.height
        colour = np.frombuffer(self._colour_fbo.read(components=3, attachment=0), dtype=np.uint8).reshape(h, w, 3)
        ids = np.frombuffer(self._fbo.read(components=1, attachment=1, dtype="u4"), dtype=np.uint32).reshape(h, w)
        if not depth:
            return colour[::-1].copy(), ids[::-1].copy(), None
        values = np.frombuffer(self._fbo.read(components=1, attachment=2, dtype="f4"), dtype=np.float32)
        return colour[::-1].copy(), ids[::-1].copy(), values.reshape(h, w)[::-1].copy()

    def render(self, view: Viewpoint, depth: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        """Draw one view; without ``depth`` the depth image is neither returned nor, with
        antialiasing ``none``, drawn (one fragment output and one interpolated value less).

        Returns:
            Colour (height, width, 3) uint8; primitive ids (height, width) uint32, UUID + 1 of the
            primitive seen at each pixel centre, 0 for none; depth (height, width) float32, metres
            along the optical axis, 0 where nothing is hit, or None without ``depth``. Row 0 is the
            top of the image. Colour and ids are the same with and without ``depth``.
        """
        previous = egl_current()
        try:
            with self.ctx:
                self.draw(view, depth)
                return self.read(depth)
        finally:
            egl_restore(previous)

    def silhouette_pixels(self, view: Viewpoint, key: int, uuids: np.ndarray) -> int:
        """Pixels whose centre some primitive of ``uuids`` covers with nothing else drawn: the area
        an object (a fruit) would have in the view if nothing hid it
        (:meth:`davis_ag.render.silhouettes.DrawnSilhouettes.pixels`).

        Args:
            view: The pose.
            key: A name for the group (a fruit id): its triangles are looked up once per renderer.
            uuids: The group's primitive UUIDs.
        """
        previous = egl_current()
        try:
            with self.ctx:
                return self._silhouettes.pixels(view, key, uuids)
        finally:
            egl_restore(previous)

    def close(self) -> None:
        """Release the GL context and everything in it."""
        ctx, self.ctx = getattr(self, "ctx", None), None
        if ctx is not None:
            previous = egl_current()
            ctx.mglo.__enter__()  # release our objects in our context, not in whichever is current
            ctx.release()
            egl_restore(previous)

    def __enter__(self) -> OpenGLRenderer:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
