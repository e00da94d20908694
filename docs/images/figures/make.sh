#!/bin/sh
# Remake every picture in this folder and docs/images/viewer.png from a small generated dataset.
# Run from the repository root: sh docs/images/figures/make.sh [WORK_DIR] (it generates 180 views first)
set -eu
HERE=docs/images/figures
WORK=${1:-out/figure-examples}
BIN=.venv/bin
$BIN/davis-ag generate --config $HERE/example.yaml --out "$WORK/data" --workers 1
$BIN/davis-ag evaluate --dataset "$WORK/data" --scenario sp --split all --episodes 100 --sessions 3 \
    --out "$WORK/results.json"
$BIN/davis-ag stats "$WORK/data" --out $HERE/stats.json | grep -v '^wrote ' > $HERE/stats.txt
for kind in visibility altitude oer; do
    $BIN/davis-ag plot $kind "$WORK/data" --out $HERE/$kind
done
# Figures of photographs: PNG only here (their SVGs embed the images, megabytes each).
$BIN/davis-ag plot phenotypes "$WORK/data" --formats png --out $HERE/phenotypes
$BIN/davis-ag plot actions --results "$WORK/results.json" --policy Oracle --out $HERE/actions
$BIN/davis-ag plot episode "$WORK/data" --results "$WORK/results.json" --policy Oracle \
    --episode "$($BIN/python -c "import json,sys; e=json.load(open(sys.argv[1]))['policies']['Oracle']['episodes']; print(max(range(len(e)), key=lambda i: (e[i]['length'], e[i]['reward'])))" "$WORK/results.json")" \
    --formats png --out $HERE/episode
# The viewer in headless Chromium: start at the lowest view nearest the plant, move right and
# up, masks on.
START=$($BIN/python -c "import json,sys; a=json.load(open(sys.argv[1])); low=min(e['pose'][2] for e in a.values()); print(min((n for n in a if a[n]['pose'][2]==low), key=lambda n: a[n]['pose'][0]**2+a[n]['pose'][1]**2))" "$WORK/data/Single-Strawberry/000/annotations.json")
$BIN/python tests/figures/chromium_pipe.py "$WORK/data" docs/images/viewer.png "$START" d,r,m
