"""``davis-ag export usd|mesh|nerfstudio DIR OUT``: the 3-D exports' arguments and runs (docs/worlds.md).

:mod:`davis_ag.commands.export` owns the output rule for every format (claim, resume, ``--force``);
this module adds the three formats' sub-parsers and runs them on the claimed folder.
"""

from __future__ import annotations

import argparse

from davis_ag.commands import arguments

#: The 3-D exports: each needs scenes made by ``davis-ag generate`` (scene.json).
WORLD_FORMATS = ("usd", "mesh", "nerfstudio")


def add_formats(formats: argparse._SubParsersAction) -> None:
    """Add the sub-parsers of ``usd``, ``mesh`` and ``nerfstudio`` to ``export``'s formats."""
    for name, help_text, description in (
        (
            "usd",
            "a USD stage per scene: plants by organ, every fruit, the views' cameras (usdview, Isaac Sim, Blender)",
            "One USD stage per scene (OUT/<group>/<scene>/scene.usd, its textures beside it): the soil, "
            "every plant as meshes grouped by plant and organ class, every fruit body its own prim "
            "named by its fruit id, UsdPreviewSurface materials, metres and Z up, and every view as a "
            "UsdGeom.Camera with the dataset's intrinsics and pose. Reopens each scene's geometry "
            "(live_geometry.npz, or a regrow from scene.json: 20-60 s a plant the first time).",
        ),
        (
            "mesh",
            "the scene's triangles with organ class, fruit id and plant per face (PLY or GLB)",
            "One mesh per scene (OUT/<group>/<scene>.ply or .glb): every triangle in world metres with "
            "its colour, organ class, fruit id and plant: PLY face properties, or GLB nodes per plant, "
            "organ and fruit with the labels in each mesh's extras. Reopens each scene's geometry as "
            "usd does.",
        ),
        (
            "nerfstudio",
            "nerfstudio's transforms.json per scene: intrinsics, camera-to-world poses, images, depth, masks",
            "One transforms.json per scene (OUT/<group>/<scene>/transforms.json): the pinhole (OPENCV), "
            "each view's camera-to-world matrix in nerfstudio's OpenGL convention, and its image, "
            "depth (uint16 mm), fruit mask and class image referenced by relative path (or copied "
            "with --copy).",
        ),
    ):
        sub = formats.add_parser(name, help=help_text, description=description)
        sub.add_argument("dir", type=arguments.path, metavar="DIR", help="dataset root, group folder or scene folder")
        sub.add_argument("out", type=arguments.path, metavar="OUT", help="export folder (new, or a previous export)")
        sub.add_argument("--force", action="store_true", help="replace a finished export in OUT")
        if name == "mesh":
            sub.add_argument(
                "--format", dest="mesh_format", choices=("ply", "glb"), default="ply", help="file type (default ply)"
            )
        if name == "nerfstudio":
            sub.add_argument(
                "--copy",
                action="store_true",
                help="copy the images, depth and masks beside transforms.json (default: refer to the "
                "dataset's by relative path)",
            )


def check_scenes(args: argparse.Namespace) -> list:
    """The scenes to export, each checked to have scene.json, before anything is written."""
    from davis_ag.worlds.triangles import geometry_scenes

    if args.format == "usd":
        from davis_ag.worlds.usd import require_usd

        require_usd()
    return geometry_scenes(args.dir, args.format)


def run_world(args: argparse.Namespace, scenes: list) -> int:
    """Write the 3-D export of ``scenes`` into the claimed ``args.out``; prints the counts."""
    if args.format == "usd":
        from davis_ag.worlds.usd import export_usd

        c = export_usd(scenes, args.out)
        print(
            f"{c['scenes']} scenes: {c['meshes']} meshes ({c['fruit']} fruit), {c['cameras']} cameras, "
            f"{c['triangles']:,} triangles; wrote {args.out}"
        )
    elif args.format == "mesh":
        from davis_ag.worlds.mesh import export_meshes

        c = export_meshes(scenes, args.out, args.mesh_format)
        print(f"{c['scenes']} scenes: {c['triangles']:,} triangles as {args.mesh_format.upper()}; wrote {args.out}")
    else:
        from davis_ag.worlds.nerfstudio import export_nerfstudio

        c = export_nerfstudio(scenes, args.out, args.copy)
        print(f"{c['scenes']} scenes: {c['frames']} frames; wrote {args.out}")
    return 0
