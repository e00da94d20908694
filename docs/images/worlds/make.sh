#!/bin/sh
# Remake the pictures of docs/worlds.md: one single-plant vine scene (Canopy Generator plant,
# seed 5, 320x180, a 3 x 3 m grid of 1.5 m steps) exported three ways, each drawn from the
# exported files alone: the labelled PLY (vine-mesh.png), the USD stage read back with pxr
# (vine-usd.png) and the nerfstudio set with a frame's projected fruit (vine-nerfstudio.png).
# Run from the repository root: sh docs/images/worlds/make.sh (a few minutes).
set -eu
HERE=docs/images/worlds
BIN=.venv/bin
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
cat > "$WORK/vine.yaml" <<'YAML'
seed: 5
image_size: 320x180
grid: {extent: [3.0, 3.0], step: 1.5}
groups:
  - {scenario: sp, crop: vine, scenes: 1}
YAML
$BIN/davis-ag generate --config "$WORK/vine.yaml" --out "$WORK/data"
$BIN/davis-ag export mesh "$WORK/data" "$WORK/mesh"
$BIN/davis-ag export usd "$WORK/data" "$WORK/usd"
$BIN/davis-ag export nerfstudio "$WORK/data" "$WORK/ns"
$BIN/python -m davis_ag.figures.world_pictures "$WORK/mesh/Single-Vine/000.ply" "$HERE/vine-mesh.png" --margin 0.1 --elevation 15
$BIN/python -m davis_ag.figures.export_pictures usd "$WORK/usd/Single-Vine/000/scene.usd" "$HERE/vine-usd.png"
$BIN/python -m davis_ag.figures.export_pictures nerfstudio "$WORK/ns/Single-Vine/000/transforms.json" \
    "$WORK/data/Single-Vine/000/scene.json" "$HERE/vine-nerfstudio.png"
