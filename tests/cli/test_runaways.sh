#!/usr/bin/env bash
# Runaways replayed through the CLI, each with a time limit, each ending with a
# valid image or a clear refusal.
#  quick (make test, ~20 s):
#   - a real part written as IGES (IGESControl_Writer's trimmed surfaces) and uniformly scaled to
#     bounding diagonals of 0.01 and 10,000 as a unit conversion does it: `render` must finish
#     within 60 s each (the import within 180 s) and draw the part (a non-constant image; both scales alike within 6 % of
#     the pixels, since the view is fitted to the box). Catches: trim flattening at a tolerance
#     below the rounding of the scaled loops (scenegraph/trim.c's floor), which spun for minutes.
#   - `--error 1e-9` and a `--camera` with fovy 1e-9 degrees: refused at once, when the command
#     line is read (usage error, exit 2), naming the floor (they spun, or grew memory at ~600 MB/s).
#     Catches a floor removed from the one camera check (runtime/src/camera.c
#     sw_rt_camera_problem) or from the CLI's --error parser: the render then runs into this
#     script's 20 s limit. The API's own refusal of both is test_api_compose's.
#  floors (make test, ~10 s): the floors that must render, on Motor-c at 640x480: ε_img 0.05 px and fovy 0.5 degrees
#   (the iso camera at the distance that fits the part at that fovy): each within 300 s, an image
#   that is not empty; their time and peak RSS are printed (/usr/bin/time when present).
# usage: test_runaways.sh SPLINEWALK SCALED_IGES SW_PNG_DIFF DATA_DIR WORKDIR quick|floors
set -u
sw=$1 scaled=$2 pngdiff=$3 data=$4 work=$5 mode=$6
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
export EGL_PLATFORM=surfaceless
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
pass() { echo "ok:   $*"; }

# timed LIMIT_S LOG -- CMD...: runs CMD with a time limit, stdout+stderr to LOG; prints the wall
# time and peak RSS; returns CMD's exit status (124: ran past the limit).
timed() {
  local limit=$1 log=$2; shift 3
  local t0 rc
  t0=$(date +%s%N)
  if [ -x /usr/bin/time ]; then
    /usr/bin/time -f "peak RSS %M KB" -o time.txt timeout "$limit" "$@" >"$log" 2>&1; rc=$?
  else
    timeout "$limit" "$@" >"$log" 2>&1; rc=$?; echo "peak RSS ?" >time.txt
  fi
  local ms=$((($(date +%s%N) - t0) / 1000000))
  printf '  %d.%03d s, %s: %s\n' $((ms / 1000)) $((ms % 1000)) "$(tail -1 time.txt)" "$*"
  return $rc
}

not_empty() { # PNG: not one constant colour
  oiiotool --stats "$1" 2>/dev/null | grep -q "Constant: No"
}

if [ "$mode" = quick ]; then
  part=$data/occ/Pump_Nut.brep
  for d in 0.01 10000; do
    "$scaled" "$part" "nut-$d.igs" "$d" >/dev/null || { fail "scaled_iges $d"; continue; }
    # the import bounds a hang only: the 10,000 copy takes ~5 s in release and ~60 s under ASan
    # on a loaded 2-core machine (OCCT projecting its pcurves at 1e-7 absolute), once past 60
    timed 180 import-$d.log -- "$sw" import "nut-$d.igs" -o "nut-$d.sws" ||
      { fail "import of the part scaled to $d"; cat import-$d.log; continue; }
    timed 60 render-$d.log -- "$sw" render "nut-$d.sws" -o "nut-$d.png" --size 320x240
    rc=$?
    if [ $rc -ne 0 ]; then fail "render of the part scaled to $d: exit status $rc"; tail -3 render-$d.log
    elif ! not_empty "nut-$d.png"; then fail "render of the part scaled to $d: empty image"
    else pass "IGES part scaled to diagonal $d rendered"; fi
  done
  if [ -f nut-0.01.png ] && [ -f nut-10000.png ]; then
    "$pngdiff" nut-0.01.png nut-10000.png 6 || fail "the two scales draw different images"
  fi

  # The floors: refused at once, with the reason.
  "$sw" import "$data/occ/Pump_Nut.brep" -o nut.sws >/dev/null 2>&1 || fail "import Pump_Nut"
  timed 20 err.log -- "$sw" render nut.sws -o e.png --size 160x120 --error 1e-9
  rc=$?
  if [ $rc -eq 2 ] && grep -q "at least 0.01" err.log; then
    pass "--error 1e-9 refused: $(grep -m1 "bad value" err.log | head -c 200)"
  else fail "--error 1e-9: exit status $rc"; tail -3 err.log; fi
  timed 20 fovy.log -- "$sw" render nut.sws -o f.png --size 160x120 --camera 200,200,200,0,0,0,0,0,1,1e-9
  rc=$?
  if [ $rc -eq 2 ] && grep -q "180)" fovy.log; then
    pass "fovy 1e-9 refused: $(grep -m1 "bad value" fovy.log | head -c 200)"
  else fail "fovy 1e-9: exit status $rc"; tail -3 fovy.log; fi
else
  model=$data/occ/Motor-c.brep
  "$sw" import "$model" -o motor.sws >/dev/null 2>&1 || fail "import Motor-c"
  timed 300 e005.log -- "$sw" render motor.sws -o e005.png --size 640x480 --error 0.05
  rc=$?
  if [ $rc -eq 0 ] && not_empty e005.png; then pass "Motor-c at ε_img 0.05 px"
  else fail "Motor-c at ε_img 0.05 px: exit status $rc"; tail -3 e005.log; fi
  # fovy 0.5°, from the iso direction at the distance that fits the part (sw_camera_fit's rule,
  # diagonal / (2 tan(fovy / 2)) x 1.1: 126 diagonals away, a telephoto view)
  c=$("$sw" info motor.sws --json | python3 -c '
import json, math, sys
b = json.load(sys.stdin)["bbox"]
c = [(b[i] + b[i + 3]) / 2 for i in range(3)]
d = sum((b[i + 3] - b[i]) ** 2 for i in range(3)) ** 0.5 / (2 * math.tan(math.radians(0.25))) * 1.1
e = [c[i] + d / 3 ** 0.5 for i in range(3)]
print(",".join("%.9g" % v for v in e + c + [0, 0, 1, 0.5]))')
  timed 300 f05.log -- "$sw" render motor.sws -o f05.png --size 640x480 --camera "$c"
  rc=$?
  if [ $rc -eq 0 ] && not_empty f05.png; then pass "Motor-c at fovy 0.5 degrees ($c)"
  else fail "Motor-c at fovy 0.5 degrees: exit status $rc"; tail -3 f05.log; fi
fi

echo "$failures failure(s)"
[ "$failures" -eq 0 ]
