#!/usr/bin/env bash
# `stereorig score` against an independent recomputation (tests/reference/
# score_crosscheck.py: scipy's k-d tree, numpy's eigen solver, its own ICP):
# simulate the default rig's scenes, reconstruct the cup (a cylinder: one
# rotation barely fixed), the sphere (three) and the plate (two slides and a
# turn in its plane; it also reaches the left view's edge) with the truth rig,
# score them, and compare every module's point count, mean |e| and std; and
# each scene's passive capture (reconstructed with the options score's
# passive run uses: reconstruct/runtime_options.h, PassiveOptions), scored
# under the active cloud's alignment, with the counts within 0.5 mm.
# Then `score --diagnose` on the sphere: that it prints and writes its parts.
#
# Usage: tests/score_crosscheck.sh BIN WORKDIR
# Exits 0 if all agree, 1 if not (the script prints each figure both ways).
set -euo pipefail
bin=$1; work=$2
scenes=(cup sphere plate)
rm -rf "$work"; mkdir -p "$work/clouds"
"$bin" simulate --out "$work/data" --seed 3 --calibration-captures 0 --threads 2 >/dev/null 2>&1
printf 'crop_to_lit_region: false\nmatch:\n  min_distinctness: 0\n  grid_line_test: false\n  line_index: false\n' \
  >"$work/passive_options.yaml"
for s in "${scenes[@]}"; do
  "$bin" reconstruct --rig "$work/data/truth/rig.yaml" --capture "$work/data/scenes/$s/active" \
    --out "$work/clouds/$s.ply" >/dev/null
  "$bin" reconstruct --rig "$work/data/truth/rig.yaml" --capture "$work/data/scenes/$s/passive" \
    --options "$work/passive_options.yaml" --out "$work/clouds/${s}_passive.ply" >/dev/null
done
"$bin" score --dataset "$work/data" --scenes "$(IFS=,; echo "${scenes[*]}")" \
  --report "$work/score.json" >/dev/null
/usr/bin/python3 "$(dirname "$0")/reference/score_crosscheck.py" "$work/score.json" "$work/data" "$work/clouds"

# The same dataset through `score --diagnose` (fill_diagnosis.h), end to
# end: every module's summary, its silhouette profile line and its four
# images. (Its figures are tested on hand-built maps in
# fill_diagnosis_test.cc; this checks that the command puts them out.)
"$bin" score --dataset "$work/data" --scenes sphere --no-passive --diagnose "$work/diagnose" >"$work/diagnose.txt"
for m in 0 1; do
  grep -q "m$m diagnosis: fill" "$work/diagnose.txt" || { echo "no m$m diagnosis"; exit 1; }
  for image in left status lost error; do
    [ -s "$work/diagnose/sphere_m${m}_$image.png" ] || { echo "no sphere_m${m}_$image.png"; exit 1; }
  done
done
profiles=$(grep -c "mean d - truth by distance to the silhouette" "$work/diagnose.txt")
[ "$profiles" -eq 2 ] || { echo "silhouette profiles: $profiles, expected 2 (one per module)"; exit 1; }
echo "score --diagnose: 2 modules' summaries, silhouette profiles and images"
