"""``davis-ag export usd``: each scene as a USD stage (usd-core's ``pxr``), for usdview, Isaac Sim and Blender.

One stage a scene, ``OUT/<Group>/<NNN>/scene.usd`` (binary crate) with its textures beside it
(``textures/``, referenced by relative path), laid out as::

    /World                                  default prim; metersPerUnit 1, upAxis Z
      Environment/soil                      the ground (and anything of no plant, by organ class)
      Plants/plant_000/leaf, stem, ...      one mesh per plant and organ class
      Plants/plant_000/fruits/fruit_7       one mesh per fruit body, named by its fruit id
      Cameras/view_0001, ...                every view of the grid: UsdGeom.Camera
      Looks/...                             UsdPreviewSurface materials

Meshes are triangle soups in world metres with face-varying normals and, where a texture gives
the colour, texture coordinates ``primvars:st``; ``primvars:displayColor`` holds each triangle's
colour (linear). Materials: a textured organ reads its Helios texture (UsdUVTexture, alpha as
opacity with threshold 0.5 so leaves keep their cut-out shape); a plain one its Helios colour.
Every mesh carries ``davis_ag:organ`` (the class name), ``davis_ag:organClass``,
``davis_ag:plant`` and ``davis_ag:fruitId`` (-1 for none), and the class name as a
``UsdSemantics`` label of taxonomy ``class`` (what Isaac Sim's Replicator reads).

Cameras look down their -Z with +Y up (USD's convention), placed by one matrix transform from
the view's pose in annotations.json. The apertures are USD's default 20.955 wide (the image's
aspect high) and the focal length ``fx * 20.955 / width``: only the ratio of focal length to
aperture shapes the projection, so ``fx = focalLength * width / horizontalAperture``. Each camera
also carries ``davis_ag:image`` (the view's image name) and ``davis_ag:pose``.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import numpy as np

from davis_ag.data.point_cloud import Pinhole
from davis_ag.data.reader import Scene
from davis_ag.errors import UserError
from davis_ag.formats.layout import view_stem
from davis_ag.render.scene_geometry import COLOUR, TEXTURE
from davis_ag.render.textures import decode_srgb
from davis_ag.worlds.cameras import camera_to_world
from davis_ag.worlds.triangles import NONE, Part, WorldTriangles, identifier, parts, world_triangles

#: The stage's file name inside each scene's folder.
STAGE_FILE = "scene.usd"
#: USD's default horizontal aperture (tenths of a scene unit; only its ratio to the focal length counts).
APERTURE = 20.955
#: Nearest and farthest distance the cameras draw, m.
CLIPPING = (0.01, 1000.0)


def _pxr():
    try:
        from pxr import Gf, Sdf, Usd, UsdGeom, UsdSemantics, UsdShade, Vt
    except ImportError:
        raise UserError(
            "export usd needs usd-core: pip install 'usd-core>=26,<27' (or pip install -e '.[worlds]')"
        ) from None
    return Gf, Sdf, Usd, UsdGeom, UsdSemantics, UsdShade, Vt


def require_usd() -> None:
    """Refuse, before any work, when usd-core is not installed.

    Raises:
        UserError: naming the package and the extra.
    """
    _pxr()


def _material_keys(world: WorldTriangles) -> tuple[np.ndarray, list[tuple[int, int, tuple[int, int, int]]]]:
    """Each triangle's material index and the materials: (mode, texture, 8-bit Helios colour)."""
    geometry = world.geometry
    colour = np.rint(np.clip(geometry.colours[:, :3], 0, 1) * 255).astype(np.int64)
    colour[geometry.mode == TEXTURE] = 0  # the texture gives the colour
    texture = np.where(geometry.mode == COLOUR, -1, geometry.texture).astype(np.int64)
    keys = np.column_stack([geometry.mode.astype(np.int64), texture, colour])
    unique, inverse = np.unique(keys, axis=0, return_inverse=True)
    return inverse.ravel(), [(int(k[0]), int(k[1]), (int(k[2]), int(k[3]), int(k[4]))) for k in unique]


def _texture_names(files: list[str]) -> list[str]:
    """Each texture's file name under ``textures/`` (numbered where two share a name)."""
    names: list[str] = []
    for k, f in enumerate(files):
        name = Path(f).name
        names.append(f"{k}_{name}" if name in names else name)
    return names


def _define_materials(stage, world: WorldTriangles, materials: list, texture_names: list[str]) -> list:
    Gf, Sdf, _, UsdGeom, _, UsdShade, _ = _pxr()
    UsdGeom.Scope.Define(stage, "/World/Looks")
    made = []
    for k, (mode, texture, colour) in enumerate(materials):
        kind = {COLOUR: "colour", TEXTURE: "texture"}.get(mode, "masked")
        suffix = identifier(Path(texture_names[texture]).stem) if texture >= 0 else "{:02x}{:02x}{:02x}".format(*colour)
        material = UsdShade.Material.Define(stage, f"/World/Looks/{kind}_{k}_{suffix}")
        shader = UsdShade.Shader.Define(stage, material.GetPath().AppendChild("Surface"))
        shader.CreateIdAttr("UsdPreviewSurface")
        shader.CreateInput("roughness", Sdf.ValueTypeNames.Float).Set(0.8)
        material.CreateSurfaceOutput().ConnectToSource(shader.ConnectableAPI(), "surface")
        diffuse = shader.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f)
        if mode != TEXTURE:
            diffuse.Set(Gf.Vec3f(*decode_srgb(np.asarray(colour) / 255.0).tolist()))
        if texture >= 0:
            reader = UsdShade.Shader.Define(stage, material.GetPath().AppendChild("st"))
            reader.CreateIdAttr("UsdPrimvarReader_float2")
            reader.CreateInput("varname", Sdf.ValueTypeNames.String).Set("st")
            image = UsdShade.Shader.Define(stage, material.GetPath().AppendChild("Texture"))
            image.CreateIdAttr("UsdUVTexture")
            image.CreateInput("file", Sdf.ValueTypeNames.Asset).Set(f"./textures/{texture_names[texture]}")
            image.CreateInput("st", Sdf.ValueTypeNames.Float2).ConnectToSource(reader.ConnectableAPI(), "result")
            for wrap in ("wrapS", "wrapT"):
                image.CreateInput(wrap, Sdf.ValueTypeNames.Token).Set("repeat")
            image.CreateInput("sourceColorSpace", Sdf.ValueTypeNames.Token).Set("sRGB")
            if mode == TEXTURE:
                diffuse.ConnectToSource(image.ConnectableAPI(), "rgb")
            alpha = image.CreateOutput("a", Sdf.ValueTypeNames.Float)
            shader.CreateInput("opacity", Sdf.ValueTypeNames.Float).ConnectToSource(alpha)
            shader.CreateInput("opacityThreshold", Sdf.ValueTypeNames.Float).Set(0.5)
        made.append(material)
    return made


def _define_mesh(stage, path: str, world: WorldTriangles, part: Part, material_of: np.ndarray, materials: list):
    Gf, Sdf, _, UsdGeom, UsdSemantics, UsdShade, Vt = _pxr()
    geometry, faces = world.geometry, part.faces
    mesh = UsdGeom.Mesh.Define(stage, path)
    points = geometry.positions[faces].reshape(-1, 3)
    mesh.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(np.ascontiguousarray(points, dtype=np.float32)))
    mesh.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(np.full(len(faces), 3, dtype=np.int32)))
    mesh.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(np.arange(len(points), dtype=np.int32)))
    mesh.CreateExtentAttr([Gf.Vec3f(*points.min(axis=0).tolist()), Gf.Vec3f(*points.max(axis=0).tolist())])
    mesh.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)  # triangles as they are, not smoothed
    mesh.CreateDoubleSidedAttr(True)  # leaves and soil are single patches seen from both sides
    normals = np.ascontiguousarray(geometry.normals[faces].reshape(-1, 3), dtype=np.float32)
    mesh.CreateNormalsAttr(Vt.Vec3fArray.FromNumpy(normals))
    mesh.SetNormalsInterpolation(UsdGeom.Tokens.faceVarying)
    primvars = UsdGeom.PrimvarsAPI(mesh)
    if (geometry.texture[faces] >= 0).any():
        st = primvars.CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray, UsdGeom.Tokens.faceVarying)
        st.Set(Vt.Vec2fArray.FromNumpy(np.ascontiguousarray(geometry.uvs[faces].reshape(-1, 2), dtype=np.float32)))
    linear = decode_srgb(world.rgb[faces] / 255.0).astype(np.float32)
    mesh.CreateDisplayColorPrimvar(UsdGeom.Tokens.uniform).Set(Vt.Vec3fArray.FromNumpy(np.ascontiguousarray(linear)))
    prim = mesh.GetPrim()
    name = world.class_name(part.organ)
    prim.CreateAttribute("davis_ag:organ", Sdf.ValueTypeNames.String).Set(name)
    prim.CreateAttribute("davis_ag:organClass", Sdf.ValueTypeNames.Int).Set(part.organ)
    prim.CreateAttribute("davis_ag:plant", Sdf.ValueTypeNames.Int).Set(part.plant)
    prim.CreateAttribute("davis_ag:fruitId", Sdf.ValueTypeNames.Int).Set(part.fruit)
    UsdSemantics.LabelsAPI.Apply(prim, "class").CreateLabelsAttr([name])
    used = material_of[faces]
    binding = UsdShade.MaterialBindingAPI.Apply(prim)
    kinds = np.unique(used)
    if len(kinds) == 1:
        binding.Bind(materials[int(kinds[0])])
        return
    for kind in kinds:  # one face subset per material
        subset = binding.CreateMaterialBindSubset(
            f"material_{int(kind)}", Vt.IntArray.FromNumpy(np.flatnonzero(used == kind).astype(np.int32))
        )
        UsdShade.MaterialBindingAPI.Apply(subset.GetPrim()).Bind(materials[int(kind)])


def _define_cameras(stage, scene: Scene) -> int:
    Gf, Sdf, _, UsdGeom, _, _, _ = _pxr()
    pinhole = Pinhole.of_scene(scene)
    pitch = APERTURE / pinhole.width  # aperture units per pixel
    UsdGeom.Scope.Define(stage, "/World/Cameras")
    count = 0
    for view in scene:
        if view.pose is None:
            continue
        camera = UsdGeom.Camera.Define(stage, f"/World/Cameras/view_{view_stem(view.name)}")
        camera.CreateProjectionAttr(UsdGeom.Tokens.perspective)
        camera.CreateHorizontalApertureAttr(APERTURE)
        camera.CreateVerticalApertureAttr(pinhole.height * pitch)
        camera.CreateFocalLengthAttr(pinhole.fx * pitch)
        camera.CreateHorizontalApertureOffsetAttr((pinhole.cx - pinhole.width / 2) * pitch)
        camera.CreateVerticalApertureOffsetAttr((pinhole.height / 2 - pinhole.cy) * pitch)  # image rows run down
        camera.CreateClippingRangeAttr(Gf.Vec2f(*CLIPPING))
        # USD multiplies row vectors: its matrix is the column-vector camera-to-world transposed.
        camera.AddTransformOp().Set(Gf.Matrix4d(camera_to_world(view.pose).T.tolist()))
        prim = camera.GetPrim()
        prim.CreateAttribute("davis_ag:image", Sdf.ValueTypeNames.String).Set(view.name)
        prim.CreateAttribute("davis_ag:pose", Sdf.ValueTypeNames.DoubleArray).Set([float(v) for v in view.pose])
        count += 1
    return count


def write_stage(world: WorldTriangles, folder: Path) -> dict[str, int]:
    """Write one scene's stage and its textures into ``folder`` (made new).

    Args:
        world: The scene's labelled triangles.
        folder: Where ``scene.usd`` and ``textures/`` go.

    Returns:
        Counts: ``meshes``, ``fruit``, ``cameras``, ``triangles``.
    """
    _, _, Usd, UsdGeom, _, _, Vt = _pxr()
    folder.mkdir(parents=True)
    texture_names = _texture_names(world.geometry.texture_files)
    stage = Usd.Stage.CreateNew(str(folder / STAGE_FILE))
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    root = UsdGeom.Xform.Define(stage, "/World")
    stage.SetDefaultPrim(root.GetPrim())
    stage.GetRootLayer().customLayerData = {
        "davis_ag": {"scene": world.scene.id, "classes": Vt.StringArray(list(world.class_names)), "units": "m, Z up"}
    }
    material_of, keys = _material_keys(world)
    materials = _define_materials(stage, world, keys, texture_names)
    meshes = fruit = 0
    for part in parts(world):
        if part.plant == NONE:
            path = f"/World/Environment/{part.name}"
        elif part.fruit != NONE:
            path = f"/World/Plants/{part.group}/fruits/{part.name}"
            fruit += 1
        else:
            path = f"/World/Plants/{part.group}/{part.name}"
        _define_mesh(stage, path, world, part, material_of, materials)
        meshes += 1
    for prim in stage.Traverse():  # the groups above the meshes: transformable, no geometry
        if not prim.GetTypeName():
            prim.SetTypeName("Xform")
    cameras = _define_cameras(stage, world.scene)
    stage.GetRootLayer().Save()
    used = {texture for _, texture, _ in keys if texture >= 0}
    for k in sorted(used):
        (folder / "textures").mkdir(exist_ok=True)
        shutil.copyfile(world.geometry.texture_files[k], folder / "textures" / texture_names[k])
    return {"meshes": meshes, "fruit": fruit, "cameras": cameras, "triangles": world.count}


def export_usd(scenes: list[Scene], out: Path) -> dict[str, int]:
    """Write every scene's stage under ``out`` (a scene already there, from an export that was
    stopped, is kept: each is published whole by one rename).

    Args:
        scenes: From :func:`davis_ag.worlds.triangles.geometry_scenes`.
        out: The claimed export folder.

    Returns:
        Totals over the scenes written: ``scenes``, ``meshes``, ``fruit``, ``cameras``, ``triangles``.
    """
    totals = {"scenes": 0, "meshes": 0, "fruit": 0, "cameras": 0, "triangles": 0}
    for scene in scenes:
        final = out / scene.id
        if (final / STAGE_FILE).is_file():
            continue
        working = final.with_name(f".{final.name}.tmp")
        shutil.rmtree(working, ignore_errors=True)
        counts = write_stage(world_triangles(scene), working)
        os.replace(working, final)
        totals["scenes"] += 1
        for key, value in counts.items():
            totals[key] += value
    return totals
