#!/bin/sh
# Remake the pictures of docs/crops.md's structures section: for each crop one view of its row
# (the inner camera line, facing the row, the higher of its two heights, as docs/images/crops),
# beside its organ classes (structure in magenta, cover pale green), 640x360 each.
# Run from the repository root: sh docs/images/structures/make.sh [CROP ...] (minutes per crop).
set -eu
HERE=docs/images/structures
BIN=.venv/bin
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
CROPS=${*:-vsp-vine capsicum apple-wall tomato}
for crop in $CROPS; do
    row=$($BIN/python -c "
import sys
from davis_ag.scene.specs import CROPS, scenario_spec
from davis_ag.scene.view_grid import view_facing
crop = CROPS[sys.argv[1]]
print(view_facing(scenario_spec('row', crop), crop, 1, 90.0))" "$crop")
    $BIN/davis-ag preview --crop "$crop" --scenario row --views "$row" --size 640x360 --classes --force --out "$WORK"
    $BIN/python -c "
import sys
import numpy as np
from PIL import Image
work, crop, view, out = sys.argv[1:]
stem = f'{work}/{crop}-row-000-{int(view):04d}'
both = np.concatenate([np.asarray(Image.open(stem + '.jpeg').convert('RGB')),
                       np.asarray(Image.open(stem + '-classes.png').convert('RGB'))], axis=1)
small = Image.fromarray(both).resize((960, 270), Image.LANCZOS)  # a 256-colour PNG: under 300 KB
small.quantize(256, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE).save(f'{out}/{crop}-row.png', optimize=True)
" "$WORK" "$crop" "$row" "$HERE"
done
