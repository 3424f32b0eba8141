#!/usr/bin/env bash
# `stereorig score` against an independent recomputation (tests/reference/
# score_crosscheck.py: scipy's k-d tree, numpy's eigen solver, its own ICP):
# simulate the default rig's scenes, reconstruct the cup (a cylinder: one
# rotation barely fixed), the sphere (three) and the plate (two slides and a
# turn in its plane; it also reaches the left view's edge) with the truth rig,
# score them, and compare every module's point count, mean |e| and std.
#
# Usage: tests/score_crosscheck.sh BIN WORKDIR
# Exits 0 if all agree, 1 if not (the script prints each figure both ways).
set -euo pipefail
bin=$1; work=$2
scenes=(cup sphere plate)
rm -rf "$work"; mkdir -p "$work/clouds"
"$bin" simulate --out "$work/data" --seed 3 --calibration-captures 0 --threads 2 >/dev/null 2>&1
for s in "${scenes[@]}"; do
  "$bin" reconstruct --rig "$work/data/truth/rig.yaml" --capture "$work/data/scenes/$s/active" \
    --out "$work/clouds/$s.ply" >/dev/null
done
"$bin" score --dataset "$work/data" --scenes "$(IFS=,; echo "${scenes[*]}")" --no-passive \
  --report "$work/score.json" >/dev/null
/usr/bin/python3 "$(dirname "$0")/reference/score_crosscheck.py" "$work/score.json" "$work/data" "$work/clouds"
