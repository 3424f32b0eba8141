#!/usr/bin/env bash
# The nightly check, end to end on rendered images with a CALIBRATED rig:
# calibrate once from the default dataset, then run the check on N nights of
# 8 fresh captures each: unmoved, one camera rotated 0.05 deg, one module
# shifted 0.1 mm (issue 6's acceptance figures), one camera's focal length
# changed and one camera's principal point moved (its lens drifted: a focus
# ring turned, thermal drift). Each kind of night comes from one simulator
# run of 8*N captures, split into nights by capture index.
#
# Usage: [STUDY_SPEC=spec.yaml] tests/check_study.sh BIN WORKDIR [NIGHTS=20] [KIND...]
#   KIND: unmoved | camera | module | module:M (module M shifted, on a rig of
#   three or more modules, where the closures can name it: "module M moved
#   or a lens changed") | focal:P (camera 2's fx, fy scaled by 1 + P/100) |
#   principal:DX,DY (camera 1's principal point moved, px).
#   STUDY_SPEC: a simulator spec (docs/simulator.md) for the rig, calibrated
#   and disturbed alike; default the embedded two-module rig.
#   Default: unmoved camera module focal:0.015 principal:0.05,0 (the
#   smallest lens drifts flagged on 20 of 20 nights and named on 19-20).
# Prints one line per kind: flagged/named counts, and how many nights said a
# camera's change is explained by neither fit; exits 1 if a figure misses
# the issue's bar (no false alarm; >= 19/20 flagged and named). Named: the
# verdict names the disturbed camera alone (a shifted module: the pair whose
# closure fails, "module 0 and module 1 disagree: ...", since it cannot tell
# which of the two changed), in words the truth
# does not contradict: a rotated camera "moved", a drifted lens "lens
# changed", either "moved or its lens changed (either explains its corners)"
# (the check cannot always tell, calib/check/camera_change.h); "changed:
# neither a new pose nor a new lens alone explains ..." is not named (one of
# them alone is what happened). Specific: how many said exactly what
# happened ("moved" for a rotation, "lens changed" for a drift).
set -euo pipefail
bin=$1; work=$2; nights=${3:-20}
# BIN as given (build/stereorig, say) is relative to where the study was
# started, not to WORKDIR, where it runs: a relative BIN ended the study at
# its first command with no word and no line printed.
[ -x "$bin" ] || { echo "check_study.sh: $bin: no such executable (BIN)" >&2; exit 2; }
bin=$(realpath "$bin")
shift $(( $# < 3 ? $# : 3 ))
kinds=("$@")
spec=()
[ -z "${STUDY_SPEC:-}" ] || spec=(--spec "$(realpath "$STUDY_SPEC")")
[ ${#kinds[@]} -gt 0 ] || kinds=(unmoved camera module focal:0.015 principal:0.05,0)
mkdir -p "$work"
cd "$work"
if [ ! -f rig.yaml ]; then
  "$bin" simulate --out cal --seed 7 --no-scenes "${spec[@]}" >/dev/null 2>&1
  "$bin" calibrate --captures cal --target cal/target.yaml --layout cal/layout.yaml --out rig.yaml \
    --report cal.json >/dev/null 2>&1
fi
total=$((8 * nights))
need=$(( nights - nights / 20 ))
# Named: the bar allows one night in 20 that does not name the camera, and
# any fewer nights (the CI's 5, the first of the same 20) may hold that one:
# one miss per 20 nights or part of them. Flagged stays at `need` (the bold
# kinds are flagged on every night of 20). Since session 47 (each view's own
# noise) focal +0.015 % names camera 2 on 19 of 20 nights, its first night
# naming the pair (module 1's stereo figure had failed by a hair before).
need_named=$(( nights - (nights + 19) / 20 ))
ok=1
run_kind() {  # name, named explanation (ERE; "" = the check must say ok), specific explanation (ERE), simulate flags...
  local name=$1 expect=$2 exact=$3; shift 3
  rm -rf "$name"
  "$bin" simulate --out "$name" --seed 1000 --calibration-captures "$total" --no-scenes "${spec[@]}" "$@" \
    >/dev/null 2>&1
  local flagged=0 named=0 specific=0 unexplained=0
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
    # The words the patterns below judge: a moved camera's fitted motion and
    # every named camera's place on the rig left out.
    out=$(echo "$out" | sed -E "s/: turned [0-9.]+ deg, shifted [0-9.]+ mm//g; s/ \[module [0-9]+'s (left|right) camera\]//g")
    [ $rc -eq 1 ] && flagged=$((flagged + 1))
    if [ -n "$expect" ] && echo "$out" | grep -qE "^verdict: recalibrate \(($expect)\)$"; then named=$((named + 1)); fi
    if [ -n "$exact" ] && echo "$out" | grep -qE "^verdict: recalibrate \(($exact)\)$"; then specific=$((specific + 1)); fi
    if echo "$out" | grep -q "^verdict: .*changed: neither a new pose nor a new lens"; then unexplained=$((unexplained + 1)); fi
    [ $rc -eq 2 ] && echo "$name night $n: bad input" >&2
  done
  echo "$name: flagged $flagged/$nights, named $named/$nights, specific $specific/$nights, unexplained $unexplained/$nights"
  if [ -z "$expect" ]; then
    [ "$flagged" -eq 0 ] || ok=0
  else
    [ "$flagged" -ge "$need" ] && [ "$named" -ge "$need_named" ] || ok=0
  fi
}
either='\(either explains its corners\)[^;]*'  # ERE: and both fits' sizes
for kind in "${kinds[@]}"; do
  case $kind in
    unmoved) run_kind unmoved "" "" ;;
    camera)
      run_kind camera "camera 2 moved( or its lens changed $either)?" "camera 2 moved" --bump-camera 2 --bump-rotation-deg 0.05 ;;
    module)  # the two modules' closure tells neither which one changed nor a motion from a lens drift: never exact
      run_kind module "module 0 and module 1 disagree: one moved or a lens changed" "" \
        --bump-module 1 --bump-translation-mm 0.1 ;;
    module:*)  # three or more modules: the shifted one is in every failing pair, and named alone
      m=${kind#module:}
      run_kind "module_$m" "module $m moved or a lens changed" "" --bump-module "$m" --bump-translation-mm 0.1 ;;
    focal:*)
      p=${kind#focal:}
      run_kind "focal_$p" "camera 2('s lens changed: [^;]*| moved or its lens changed $either)" "camera 2's lens changed: [^;]*" \
        --bump-camera 2 --bump-focal-percent "$p" ;;
    principal:*)
      d=${kind#principal:}
      run_kind "principal_${d/,/_}" "camera 1('s lens changed: [^;]*| moved or its lens changed $either)" \
        "camera 1's lens changed: [^;]*" --bump-camera 1 --bump-principal-point-px "${d%,*}" "${d#*,}" ;;
    *) echo "unknown kind $kind" >&2; exit 2 ;;
  esac
done
echo "$( [ $ok -eq 1 ] && echo PASS || echo FAIL ): unmoved 0 alarms required; bumps need >= $need/$nights flagged, >= $need_named/$nights named"
[ $ok -eq 1 ]
