"""``davis-ag export usd``: the stage read back with pxr against scene.json and annotations.json."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from davis_ag import cli

pxr = pytest.importorskip("pxr", reason="usd-core is the worlds extra")


def test_the_stage_holds_every_fruit_and_every_camera_as_recorded(
    world_root: Path, world_scene_dir: Path, tmp_path: Path
) -> None:
    from pxr import Usd, UsdGeom, UsdSemantics, UsdShade, UsdValidation

    out = tmp_path / "usd"
    assert cli.main(["export", "usd", str(world_root), str(out)]) == 0
    path = out / world_scene_dir.relative_to(world_root) / "scene.usd"
    stage = Usd.Stage.Open(str(path))
    assert UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.z and UsdGeom.GetStageMetersPerUnit(stage) == 1.0
    assert stage.GetDefaultPrim().GetPath() == "/World"
    # USD's own validators (schema types, material bindings, shader inputs) find nothing.
    validators = UsdValidation.ValidationRegistry().GetOrLoadAllValidators()
    assert [e.GetMessage() for e in UsdValidation.ValidationContext(validators).Validate(stage)] == []
    scene = json.loads((world_scene_dir / "scene.json").read_text())
    annotations = json.loads((world_scene_dir / "annotations.json").read_text())

    # Every fruit its own prim, named by its id, under its plant, where scene.json says it is.
    meshes = [UsdGeom.Mesh(p) for p in stage.Traverse() if p.IsA(UsdGeom.Mesh)]
    fruit = {m.GetPrim().GetAttribute("davis_ag:fruitId").Get(): m for m in meshes}
    fruit.pop(-1)
    assert sorted(fruit) == [f["id"] for f in scene["fruits"]]
    for record in scene["fruits"]:
        mesh = fruit[record["id"]]
        assert mesh.GetPath() == f"/World/Plants/plant_{record['plant']:03d}/fruits/fruit_{record['id']}"
        points = np.asarray(mesh.GetPointsAttr().Get())
        assert np.allclose((points.min(axis=0) + points.max(axis=0)) / 2, record["center"], atol=1e-5)
        assert np.allclose(points.max(axis=0) - points.min(axis=0), record["size"], atol=1e-5)
        assert UsdSemantics.LabelsAPI(mesh.GetPrim(), "class").GetLabelsAttr().Get() == ["fruit"]
    # Every plant has its organs; the soil is no plant's; each mesh has a material.
    organs = {
        (m.GetPrim().GetAttribute("davis_ag:plant").Get(), m.GetPrim().GetAttribute("davis_ag:organ").Get())
        for m in meshes
    }
    assert (-1, "soil") in organs
    assert {(p["index"], "leaf") for p in scene["plants"]} <= organs
    for mesh in meshes:
        bound = UsdShade.MaterialBindingAPI(mesh.GetPrim()).ComputeBoundMaterial()[0]
        subsets = UsdGeom.Subset.GetAllGeomSubsets(mesh)
        assert bound or subsets, mesh.GetPath()
    textures = [p.GetAttribute("inputs:file").Get() for p in stage.Traverse() if p.GetName() == "Texture"]
    assert textures and all((path.parent / t.path).is_file() for t in textures)

    # Every view a camera whose transform and lens are the dataset's.
    cameras = {
        p.GetAttribute("davis_ag:image").Get(): UsdGeom.Camera(p) for p in stage.Traverse() if p.IsA(UsdGeom.Camera)
    }
    assert sorted(cameras) == sorted(annotations)
    camera_record = scene["camera"]
    for name in ("0001.jpeg", sorted(annotations)[len(annotations) // 2]):
        camera = cameras[name]
        matrix = np.asarray(camera.ComputeLocalToWorldTransform(Usd.TimeCode.Default()))  # row vectors
        forward = -matrix[2, :3]  # USD cameras look down their -Z
        x, y, z, yaw, pitch = annotations[name]["pose"]
        assert np.allclose(matrix[3, :3], [x, y, z], atol=1e-6)
        assert math.degrees(math.atan2(forward[1], forward[0])) == pytest.approx(yaw, abs=1e-4)
        assert math.degrees(math.asin(forward[2])) == pytest.approx(pitch, abs=1e-4)
        assert matrix[1, 2] > 0  # the image's up points up
        lens = camera.GetCamera(Usd.TimeCode.Default())
        fx = lens.focalLength * camera_record["width"] / lens.horizontalAperture
        assert fx == pytest.approx(camera_record["fx"], rel=1e-6)
        assert lens.verticalAperture / lens.horizontalAperture == pytest.approx(
            camera_record["height"] / camera_record["width"]
        )
