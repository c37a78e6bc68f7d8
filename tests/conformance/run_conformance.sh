#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The conformance harness: OCCT's sample models against an independent reference, the way users
# bring them (their own files, other units, IGES from other systems).
#   run_conformance.sh TEST_IMAGES SCALED_IGES DATA WORK quick|quick-exact|full [FILE...]
# Each case is one model in one variant at one view, run by tests/images' test_images on the
# hierarchy path (converged, default ε_img 0.5 px, default LODs) at 640x480: splinewalk's frame
# against OCCT's BRepMesh at a deflection of 0.1 px at the view's nearest depth (tests/support),
# silhouette and depth edges within 1 px both ways, crack pixels 0 where the B-rep is closed
# (test_images says what it asserts), and no piece drawn over its error bound (the frame's
# bound_exceeded is 0: converged frames keep ε_img everywhere; a case over it fails with the
# count). Planted: items whose grid the segment limit caps drawn capped instead of halved
# (stage_tessellate_hierarchy.c MAX_GRID_SPLITS 0) → Pump_Nut's mid views fail (3 each); the
# side of a trim loop its fat border covers probed 1e-3 of the longest edge off the loop
# (stage_trim.c) → screw and bottle at diagonal 0.01 fail (the ribbons of thin faces drawn
# outside them: max 2.24 and 1.41 px); a fat border's inner point not kept in its loop's (u, v)
# box (crack_fill.c box_exit) → Bottom at diagonal 10 fails (a sample on a degenerate edge stepped
# 3e8 in u, onto the surface extrapolated: a spike of 276 px); knot spans of 1e-8 of the trim box
# taken as a face's cell (stage_tessellate.c SLIVER_FRACTION 1e-9) → hammer at diagonal 0.01
# fails (14 borders capped: bound exceeded), and widened by the capped count it ran out of memory;
# faces converted at the file's size (face_occt.cpp import_scale_exp returning 0) → Exhaust at
# diagonal 0.01 fails (OCCT's 1e-7 tolerances: trims off by up to 74 px in the close view); a fat
# border's end nearer than the near plane left there (crack_fill.c quad_ends_clipped) →
# quick-exact fails on MODERN_Refrigerator_1's mid view (1 crack pixel).
# Variants: the file itself; an IGES copy at its own size
# (IGESControl_Writer: trims become B-spline pcurves); BREP copies uniformly scaled to bounding
# diagonals of 0.01, 10 and 10,000 (a unit conversion: scaled_iges). Views: whole, mid, close.
#  - full: every .brep under DATA/occ and .step under DATA/step (or the FILEs given), every
#    variant and view (`make conformance`: about 40 minutes on 2 cores), or those named in
#    CONF_VARIANTS (say "orig iges") and CONF_VIEWS (say "mid,close");
#  - quick: a subset that must pass in `make test` (under 5 minutes);
#  - quick-exact: views drawn with exact trim edges (test_images --exact-edges, as the CLI draws)
#    that must pass in `make test`, MODERN_Refrigerator_1's mid view among them (a fat border
#    tapered to nothing at the near plane there: one crack pixel). CONF_FLAGS adds test_images
#    options to any mode.
# A file without faces (wires only) is reported as skipped; a case whose reference or frame
# takes over 180 s as "timeout", a view whose camera shows no reference face or no edge (a mid
# view filled by one smooth surface) as "empty", a view whose reference the triangle budget
# capped at a deflection over 0.5 px as "coarse" (all failures: nothing was checked). Prints one line per case and
# a summary; exit 1 if any case failed. What it catches: any model, unit or exporter on which
# the guarantee does not hold (found so far: see docs/conformance.md).
set -u
test_images=$1 scaled=$2 data=$3 work=$4 mode=$5
shift 5
mkdir -p "$work/out" && cd "$work" || exit 1
export EGL_PLATFORM=surfaceless
# The reference's triangle budget, as the registered image tests (tests/images/CMakeLists.txt):
# BRepMesh took 120-300 s for test_images' default of 1.5 M (Ball's close view), over the limit.
export SW_IMAGES_MAX_TRIANGLES=${SW_IMAGES_MAX_TRIANGLES:-300000}
pass=0 failed=0 skipped=0
flags=${CONF_FLAGS:-}
[ "$mode" = quick-exact ] && flags="$flags --exact-edges"
: >cases.txt

# run_case FILE NAME VIEWS: one test_images run, one line per view in cases.txt.
run_case() {
  local file=$1 name=$2 views=$3 log rc
  log=$name.log
  # shellcheck disable=SC2086 # flags: words
  timeout 180 "$test_images" --hierarchy $flags out 640x480 "$views" "$file" >"$log" 2>&1
  rc=$?
  if grep -q "no face could be imported" "$log"; then
    echo "SKIP    $name: no faces" | tee -a cases.txt
    skipped=$((skipped + 1))
    return
  fi
  if [ $rc -eq 124 ]; then
    echo "TIMEOUT $name $views: over 180 s" | tee -a cases.txt
    failed=$((failed + 1))
    return
  fi
  # test_images prints per view: "<out>/<stem> <view>:", two "<= 1 px" lines, FAIL: when it fails
  awk -v name="$name" '
    /^out\/[^ ]+ [a-z]+:/ { if (view != "") report(); view = $2; sub(":", "", view); lines = ""; bad = 0; over = ""; refpx = 0 }
    /splinewalk: .*bound exceeded/ { over = $NF }
    /reference: deflection/ { match($0, /\([0-9.]+ px at/); refpx = substr($0, RSTART + 1, RLENGTH - 7) + 0 }
    /<= 1 px:/ { match($0, /[0-9.]+ %/); pct = substr($0, RSTART, RLENGTH - 2)
                 match($0, /max [0-9.]+ px/); mx = substr($0, RSTART + 4, RLENGTH - 7)
                 lines = lines sprintf(" %s%% max %s px", pct, mx) }
    /FAIL:/ { if (bad == 0) bad = 1 } # a view that tests nothing fails too: it stays EMPTY
    /no face of the reference in view|the view tests nothing/ { bad = 2 }
    function report() {
      if (over != "" && over + 0 > 0 && bad == 0) bad = 1 # converged: the bound is kept everywhere
      if (bad != 2 && lines != "" && refpx > 0.5) { # the triangle budget coarsened the reference
        printf "COARSE  %s %s: nothing checked (the reference capped at %.2f px)%s\n", name, view, refpx,
               over == "" ? "" : sprintf("; bound exceeded %s", over)
        return }
      printf "%s %s %s:%s%s\n", bad == 2 || lines == "" ? "EMPTY  " : bad ? "FAIL   " : "ok     ",
             name, view, bad == 2 || lines == "" ? " nothing checked (no reference face or edge in view)" : lines,
             over == "" ? "" : sprintf("; bound exceeded %s", over) }
    END { if (view != "") report() }' "$log" | tee -a cases.txt
  [ $rc -eq 0 ] || grep -q "^\(ok\|FAIL\|EMPTY\|COARSE\) .*$name " cases.txt ||
    echo "FAIL    $name: exit $rc, $(tail -n 1 "$log")" | tee -a cases.txt
}

# variants FILE LIST: the copies named in LIST (orig, iges, d0.01, d10, d10000) of FILE.
variant_file() {
  local file=$1 v=$2 stem out
  stem=$(basename "${file%.*}")
  case $v in
    orig) echo "$file"; return ;;
    iges) out=$stem.igs; "$scaled" "$file" "$out" 0 >/dev/null 2>&1 || return 1 ;;
    d*) out=$stem-$v.brep; "$scaled" "$file" "$out" "${v#d}" >/dev/null 2>&1 || return 1 ;;
  esac
  echo "$out"
}

one_model() {
  local file=$1 variants=$2 views=$3 v f
  for v in $variants; do
    if ! f=$(variant_file "$file" "$v"); then
      echo "FAIL    $(basename "$file") $v: the copy could not be written" | tee -a cases.txt
      continue
    fi
    run_case "$f" "$(basename "${file%.*}")-$v" "$views"
  done
}

if [ "$mode" = quick ]; then
  # views that hold today (docs/conformance.md lists the ones that do not)
  one_model "$data/step/screw.step" "orig d0.01 d10000" whole
  one_model "$data/occ/bottle.brep" "iges" whole
  one_model "$data/occ/bottle.brep" "d0.01" whole
  one_model "$data/occ/Bottom.brep" "d10" whole
  one_model "$data/occ/hammer.brep" "d0.01" whole,close
  one_model "$data/occ/MODERN_Exhaust_1.brep" "d0.01" close
  one_model "$data/occ/Pump_Nut.brep" "orig d10" whole,mid
  one_model "$data/occ/Motor-c.brep" "orig" whole
  one_model "$data/occ/shell1.brep" "d10000" whole
elif [ "$mode" = quick-exact ]; then
  # views that hold today with exact edges (docs/curves.md: Motor-c's whole view does not)
  one_model "$data/occ/MODERN_Refrigerator_1.brep" "orig" mid
  one_model "$data/occ/Pump_Nut.brep" "orig" whole,mid,close
  one_model "$data/occ/Motor-c.brep" "orig" close
  one_model "$data/occ/CrankArm.brep" "orig" close
  one_model "$data/step/screw.step" "orig" whole
else
  files=("$@")
  [ ${#files[@]} -gt 0 ] || files=("$data"/occ/*.brep "$data"/step/*.step)
  for f in "${files[@]}"; do
    one_model "$f" "${CONF_VARIANTS:-orig iges d0.01 d10 d10000}" "${CONF_VIEWS:-whole,mid,close}"
  done
fi
pass=$(grep -c '^ok' cases.txt)
failed=$((failed + $(grep -c '^FAIL' cases.txt)))
skipped=$(grep -c '^SKIP' cases.txt)
timeouts=$(grep -c '^TIMEOUT' cases.txt)
empty=$(grep -c '^EMPTY' cases.txt)
coarse=$(grep -c '^COARSE' cases.txt)
failed=$((failed + empty + coarse))
echo "conformance ($mode): $pass views ok, $((failed - timeouts - empty - coarse)) failed, $timeouts timed out, $empty checked nothing, $coarse with a reference too coarse, $skipped files without faces"
exit $((failed > 0))
