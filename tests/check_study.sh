#!/usr/bin/env bash
# The nightly check, end to end on rendered images with a CALIBRATED rig:
# calibrate once from the default dataset, then run the check on N nights of
# 8 fresh captures each: unmoved, one camera rotated 0.05 deg, one module
# shifted 0.1 mm (issue 6's acceptance figures). Each kind of night comes
# from one simulator run of 8*N captures, split into nights by capture index.
#
# Usage: tests/check_study.sh BIN WORKDIR [NIGHTS=20]
# Prints one line per kind: flagged/named counts; exits 1 if a figure misses
# the bar (no false alarm; >= 19/20 flagged and named).
set -euo pipefail
bin=$1; work=$2; nights=${3:-20}
mkdir -p "$work"
cd "$work"
if [ ! -f rig.yaml ]; then
  "$bin" simulate --out cal --seed 7 --no-scenes >/dev/null 2>&1
  "$bin" calibrate --captures cal --target cal/target.yaml --layout cal/layout.yaml --out rig.yaml \
    --report cal.json >/dev/null 2>&1
fi
total=$((8 * nights))
run_kind() {  # name, extra simulate flags..., expected explanation substring
  local name=$1 expect=$2; shift 2
  rm -rf "$name"
  "$bin" simulate --out "$name" --seed 1000 --calibration-captures "$total" --no-scenes "$@" >/dev/null 2>&1
  local flagged=0 named=0
  for ((n = 0; n < nights; n++)); do
    local night="$name.night$n"
    rm -rf "$night"; mkdir -p "$night"
    for ((k = 0; k < 8; k++)); do
      local idx; idx=$(printf "%03d" $((8 * n + k)))
      ln -s "$PWD/$name/calibration/$idx" "$night/$idx"
    done
    set +e
    out=$("$bin" check --rig rig.yaml --captures "$night" --target cal/target.yaml \
      --history-db "$name.sqlite" 2>/dev/null)
    rc=$?
    set -e
    [ $rc -eq 1 ] && flagged=$((flagged + 1))
    if [ -n "$expect" ] && echo "$out" | grep -q "verdict: recalibrate ($expect)"; then named=$((named + 1)); fi
    [ $rc -eq 2 ] && echo "$name night $n: bad input" >&2
  done
  echo "$name: flagged $flagged/$nights, named $named/$nights"
  eval "${name}_flagged=$flagged; ${name}_named=$named"
}
run_kind unmoved ""
run_kind camera "camera 2 moved" --bump-camera 2 --bump-rotation-deg 0.05
run_kind module "module 1 moved" --bump-module 1 --bump-translation-mm 0.1
ok=1
[ "$unmoved_flagged" -eq 0 ] || ok=0
need=$(( nights - nights / 20 ))
[ "$camera_flagged" -ge "$need" ] && [ "$camera_named" -ge "$need" ] || ok=0
[ "$module_flagged" -ge "$need" ] && [ "$module_named" -ge "$need" ] || ok=0
echo "$( [ $ok -eq 1 ] && echo PASS || echo FAIL ): unmoved 0 alarms required; bumps need >= $need/$nights flagged and named"
[ $ok -eq 1 ]
