#!/bin/sh
# Remake every picture in this folder and docs/images/viewer.png from a small generated dataset.
# Run from the repository root: sh docs/images/figures/make.sh [WORK_DIR]   (about 30 min on 2 cores)
set -eu
HERE=docs/images/figures
WORK=${1:-out/figure-examples}
BIN=.venv/bin
$BIN/davis-ag generate --config $HERE/example.yaml --out "$WORK/data" --workers 1
$BIN/davis-ag evaluate --dataset "$WORK/data" --scenario sp --split all --episodes 100 --sessions 3 \
    --out "$WORK/results.json"
$BIN/davis-ag stats "$WORK/data" --out $HERE/stats.json > $HERE/stats.txt
for kind in visibility altitude oer phenotypes; do
    $BIN/davis-ag plot $kind "$WORK/data" --out $HERE/$kind
done
$BIN/davis-ag plot actions --results "$WORK/results.json" --out $HERE/actions
$BIN/davis-ag plot episode "$WORK/data" --results "$WORK/results.json" --policy Oracle \
    --episode "$($BIN/python -c "import json,sys; e=json.load(open(sys.argv[1]))['policies']['Oracle']['episodes']; print(max(range(len(e)), key=lambda i: (e[i]['length'], e[i]['reward'])))" "$WORK/results.json")" \
    --out $HERE/episode
# The viewer in headless Chromium: start at a view, move right and up, masks on.
$BIN/python tests/figures/chromium_pipe.py "$WORK/data" docs/images/viewer.png 0005 d,r,m
