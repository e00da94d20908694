#!/bin/sh
# Remake the plant-library crops' pictures of docs/crops.md and the README: for each crop one
# 1280x720 single-plant view with its boxes and its organ classes, and one view of its row from
# the inner camera line, facing the row, from the higher of its two heights.
# Run from the repository root: sh docs/images/crops/make.sh [CROP ...] (minutes per crop).
set -eu
HERE=docs/images/crops
BIN=.venv/bin
CROPS=${*:-apple apple-wall almond olive pistachio walnut capsicum cherry-tomato vsp-vine wye-vine}
for crop in $CROPS; do
    # The single plant: the middle altitude's view straight south of the plant.
    sp=$($BIN/python -c "
import sys
from davis_ag.scene.specs import CROPS, scenario_spec
from davis_ag.scene.view_grid import view_facing
crop = CROPS[sys.argv[1]]
print(view_facing(scenario_spec('sp', crop), crop, 1, 90.0))" "$crop")
    row=$($BIN/python -c "
import sys
from davis_ag.scene.specs import CROPS, scenario_spec
from davis_ag.scene.view_grid import view_facing
crop = CROPS[sys.argv[1]]
print(view_facing(scenario_spec('row', crop), crop, 1, 90.0))" "$crop")
    $BIN/davis-ag preview --crop "$crop" --views "$sp" --classes --force --out $HERE
    $BIN/davis-ag preview --crop "$crop" --scenario row --views "$row" --force --out $HERE
done
