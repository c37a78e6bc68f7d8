#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# End-to-end tests of the splinewalk CLI: truthful --help, import/info/render on a real model, and
# bad input (every case: a clear error naming the file and the problem, exit status 1, no crash).
# usage: test_cli.sh SPLINEWALK MAKE_BAD_SWS DATA_DIR WORKDIR
set -u
sw=$1 make_bad=$2 data=$3 work=$4
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
pass() { echo "ok:   $*"; }

# expect_error NAME ID FILE -- CMD...: exit status 1, stderr names FILE and the result ID, no crash.
expect_error() {
  local name=$1 id=$2 file=$3; shift 4
  "$@" >out.txt 2>err.txt; local rc=$?
  if [ $rc -ne 1 ]; then fail "$name: exit status $rc, expected 1"; cat err.txt; return; fi
  grep -q -- "$id" err.txt || { fail "$name: stderr lacks $id"; cat err.txt; return; }
  grep -qF -- "$file" err.txt || { fail "$name: stderr does not name $file"; cat err.txt; return; }
  pass "$name: $(head -c 200 err.txt)"
}

# --help: exit 0, and the options each command takes are all described.
"$sw" --help | grep -q render || fail "splinewalk --help lists no render"
for c in import info render demo; do
  "$sw" $c --help >help.txt || fail "$c --help exit status"
done
"$sw" render --help >help.txt
for opt in -o --size --view --camera --error --eval iso front top right bezier exact; do
  grep -q -- "$opt" help.txt || fail "render --help does not mention $opt"
done
"$sw" info --help | grep -q -- --json || fail "info --help does not mention --json"
"$sw" nosuchcommand >/dev/null 2>&1; [ $? -eq 2 ] || fail "unknown command: exit status not 2"
"$sw" render only-a-scene.sws >/dev/null 2>&1; [ $? -eq 2 ] || fail "render without -o: not a usage error"
"$sw" render x.sws -o y.png --size 0x5 >/dev/null 2>&1; [ $? -eq 2 ] || fail "--size 0x5 accepted"
"$sw" render x.sws -o y.png --camera 1,2,3 >/dev/null 2>&1; [ $? -eq 2 ] || fail "short --camera accepted"
"$sw" render x.sws -o y.png --error nan >/dev/null 2>&1; [ $? -eq 2 ] || fail "--error nan accepted"
pass "help texts and usage errors"

# A real model through import, info and render.
model=$data/occ/Motor-c.brep
"$sw" import "$model" -o motor.sws >import.txt 2>&1 || { fail "import Motor-c"; cat import.txt; }
"$sw" info motor.sws --json >info_sws.json || fail "info motor.sws"
"$sw" info "$model" --json >info_brep.json || fail "info Motor-c.brep"
grep -q '"faces": 223' info_sws.json || fail "info: Motor-c should have 223 faces: $(cat info_sws.json)"
grep -q '"meshes": 0, "mesh_triangles": 0' info_sws.json || fail "info: Motor-c has no meshes: $(cat info_sws.json)"
a=$(sed 's/"file": "[^"]*", //; s/"memory_bytes": [0-9]*//' info_sws.json)
b=$(sed 's/"file": "[^"]*", //; s/"memory_bytes": [0-9]*//' info_brep.json)
[ "$a" = "$b" ] || fail "info of the .sws differs from info of its source: $a vs $b"
"$sw" render motor.sws -o motor.png --size 320x240 --view front >render.txt 2>&1 ||
  { fail "render motor.sws"; cat render.txt; }
trimmed=$(sed -n 's/.*trimmed by trim textures \([0-9]*\).*/\1/p' render.txt)
[ -n "$trimmed" ] && [ "$trimmed" -gt 0 ] || fail "render: no trim-textured patches: $(cat render.txt)"
[ -s motor.png ] || fail "render wrote no image"
"$sw" render "$model" -o motor.exr --size 160x120 >/dev/null 2>&1 || fail "render to EXR"
"$sw" render motor.sws -o exact.png --size 320x240 --eval exact >exact.txt 2>&1 || fail "render --eval exact"
exact=$(sed -n 's/.*, \([0-9]*\) by the exact path.*/\1/p' exact.txt)
[ -n "$exact" ] && [ "$exact" -gt 0 ] || fail "--eval exact drew no patch by the exact path: $(cat exact.txt)"
"$sw" render motor.sws -o x.png --eval fast >/dev/null 2>&1; [ $? -eq 2 ] || fail "--eval fast accepted"
[ -s motor.exr ] || fail "no EXR written"
pass "import / info / render on Motor-c.brep ($trimmed trim-textured patches)"

# The EXR's content (a non-empty file passed before, a blank or wrong image too): its
# RGB must be the PNG render of the same view to within one level (the EXR holds RGBA8 / 255 in
# half); its Z must cover exactly the pixels the PNG shows the part on (finite there, +inf on the
# white background; <= 0.5 % of them may disagree, at antialiased edges), at least 5 % of the
# image; and every finite Z must lie within the depth range of the part's bounding box seen by
# the iso preset (centre at diag / (2 tan 20 deg) x 1.1, +- diag / 2), as info --json gives it.
# Caught when planted: rows written bottom-up (modules/image/image_oiio.cpp write_exr), a Z channel of 0.
"$sw" render "$model" -o motor_exr_ref.png --size 160x120 >/dev/null 2>&1 || fail "render PNG beside the EXR"
if oiiotool --dumpdata motor.exr >exr.txt && oiiotool --dumpdata motor_exr_ref.png >png.txt; then
  exr_check=$(python3 - info_brep.json exr.txt png.txt <<'PY'
import json, math, sys
def pixels(path):  # oiiotool --dumpdata: "Pixel (x, y): v0 v1 ..." per pixel, row by row (8-bit
    # files add "(f0 f1 ...)", the values / 255)
    return [[float(v) for v in line.split(":")[1].split("(")[0].split()]
            for line in open(path) if line.lstrip().startswith("Pixel (")]
exr, png = pixels(sys.argv[2]), pixels(sys.argv[3])
n = len(png)
if n == 0 or len(exr) != n or any(len(p) != 5 for p in exr):
    print("%d EXR pixels (RGBA + Z each expected), %d PNG pixels" % (len(exr), n)); sys.exit(1)
color = max(abs(round(255 * e[k]) - p[k]) for e, p in zip(exr, png) for k in range(3))
covered = [math.isfinite(e[4]) for e in exr]
white = [p[:3] == [255, 255, 255] for p in png]
disagree = sum(c == w for c, w in zip(covered, white))
b = json.load(open(sys.argv[1]))["bbox"]
diag = math.dist(b[:3], b[3:])
d = diag / (2 * math.tan(math.radians(20))) * 1.1
zs = [e[4] for e in exr if math.isfinite(e[4])]
out = [z for z in zs if not d - diag / 2 <= z <= d + diag / 2]
ok = color <= 1 and len(zs) >= 0.05 * n and disagree <= 0.005 * n and not out
print("RGB max difference %d level(s); Z covers %d of %d pixels, %d disagree with the PNG's part; "
      "Z in [%.4g, %.4g], the box's range [%.4g, %.4g]%s" % (color, len(zs), n, disagree,
      min(zs) if zs else 0, max(zs) if zs else 0, d - diag / 2, d + diag / 2, "" if ok else " BAD"))
sys.exit(0 if ok else 1)
PY
  ) && pass "EXR content: $exr_check" || fail "EXR content: $exr_check"
else
  fail "EXR content: oiiotool could not read the EXR or the PNG"
fi

# OCCT's IGES reader prints to stdout by default: `info --json` must still print one JSON line.
"$sw" info --json "$data/iges/bearing.iges" >iges.json 2>/dev/null || fail "info bearing.iges"
[ "$(head -c 1 iges.json)" = "{" ] && [ "$(wc -l <iges.json)" -eq 1 ] ||
  fail "info --json of an IGES file is not one JSON line: $(head -c 300 iges.json)"
pass "info --json of an IGES file is clean"

# A T-spline sample: its rational bicubic Bézier patches through the same pipeline.
tsm=$(dirname "$0")/../../samples/tsplines/t_junctions.tsm
"$sw" info "$tsm" --json >tsm.json || fail "info t_junctions.tsm"
grep -q '"tspline": 32' tsm.json || fail "t_junctions.tsm should give 32 T-spline patches: $(cat tsm.json)"
"$sw" render "$tsm" -o tsm.png --size 160x120 >/dev/null 2>&1 || fail "render t_junctions.tsm"
pass "T-spline sample through info and render"

# Bad input.
size=$(stat -c %s motor.sws)
expect_error "missing file" SW_ERR_NOT_FOUND no-such.sws -- "$sw" info no-such.sws
expect_error "missing STEP" SW_ERR_NOT_FOUND no-such.step -- "$sw" import no-such.step -o x.sws
head -c 3000 /dev/urandom | base64 >garbage.step
expect_error "garbage STEP" SW_ERR_FORMAT garbage.step -- "$sw" import garbage.step -o g.sws
[ ! -e g.sws ] || fail "garbage STEP left an output file"
echo "not a scene" >plain.txt
expect_error "unknown extension" SW_ERR_UNSUPPORTED plain.txt -- "$sw" info plain.txt
head -c 40 motor.sws >header-cut.sws
expect_error "truncated inside the header" SW_ERR_TRUNCATED header-cut.sws -- "$sw" info header-cut.sws
head -c $((size / 2)) motor.sws >half.sws
expect_error "truncated .sws" SW_ERR_TRUNCATED half.sws -- "$sw" render half.sws -o h.png
[ ! -e h.png ] || fail "render of a truncated scene wrote an image"
head -c $((size - 8)) motor.sws >short.sws
expect_error ".sws shorter than its section table says" SW_ERR_TRUNCATED short.sws -- "$sw" info short.sws
cp motor.sws flipped.sws
printf '\xff' | dd of=flipped.sws bs=1 seek=$((size - 1000)) conv=notrunc status=none
expect_error "wrong checksum" SW_ERR_CHECKSUM flipped.sws -- "$sw" info flipped.sws
"$make_bad" motor.sws knots.sws decreasing-knots || fail "make_bad_sws decreasing-knots"
expect_error "decreasing knots" SW_ERR_INVALID_GEOMETRY knots.sws -- "$sw" render knots.sws -o k.png
"$make_bad" motor.sws nan.sws nan-weight || fail "make_bad_sws nan-weight"
expect_error "NaN weight" SW_ERR_INVALID_GEOMETRY nan.sws -- "$sw" info nan.sws

# A failed import must not touch an existing output.
cp motor.sws keep.sws && sum=$(cksum <keep.sws)
"$sw" import garbage.step -o keep.sws >/dev/null 2>&1
[ "$(cksum <keep.sws)" = "$sum" ] || fail "failed import changed the existing output"
ls keep.sws.tmp* >/dev/null 2>&1 && fail "failed import left a temporary file"
mkdir -p ro && chmod 555 ro
if [ "$(id -u)" -ne 0 ]; then
  expect_error "unwritable output" SW_ERR_IO ro/x.sws -- "$sw" import "$model" -o ro/x.sws
fi
expect_error "output in a missing directory" SW_ERR_NOT_FOUND nodir/x.sws -- "$sw" import "$model" -o nodir/x.sws

# generate grid: instances sharing one model's geometry; bad input is a usage error (2) or a
# named failure (1), and nothing is written by a failed run.
"$sw" --help | grep -q generate || fail "splinewalk --help lists no generate"
"$sw" generate --help >help.txt || fail "generate --help exit status"
for opt in grid --model --count -o --spacing --dims 10000000; do
  grep -q -- "$opt" help.txt || fail "generate --help does not mention $opt"
done
for bad in "--count -5" "--count 0" "--count 10000001" "--count 99999999999" "--count 12abc" \
           "--count 1e3" "--spacing -1" "--spacing nan" "--spacing 0" "--dims 4"; do
  "$sw" generate grid --model motor.sws $bad -o bad.sws >/dev/null 2>err.txt
  rc=$?
  [ $rc -eq 2 ] || fail "generate $bad: exit status $rc, expected 2"
  grep -q -- "${bad%% *}" err.txt || fail "generate $bad: stderr does not name ${bad%% *}"
done
"$sw" generate grid --model motor.sws -o bad.sws >/dev/null 2>&1; [ $? -eq 2 ] || fail "generate without --count accepted"
"$sw" generate grid --count 4 -o bad.sws >/dev/null 2>&1; [ $? -eq 2 ] || fail "generate without --model accepted"
"$sw" generate grid --model motor.sws --count 4 >/dev/null 2>&1; [ $? -eq 2 ] || fail "generate without -o accepted"
"$sw" generate cube --model motor.sws --count 4 -o bad.sws >/dev/null 2>&1; [ $? -eq 2 ] || fail "generate cube accepted"
[ ! -e bad.sws ] || fail "a generate usage error wrote its output"
expect_error "generate: missing model" SW_ERR_NOT_FOUND no-such.step -- \
  "$sw" generate grid --model no-such.step --count 4 -o bad.sws
expect_error "generate: model not a scene" SW_ERR_UNSUPPORTED plain.txt -- \
  "$sw" generate grid --model plain.txt --count 4 -o bad.sws
expect_error "generate: truncated model" SW_ERR_TRUNCATED half.sws -- \
  "$sw" generate grid --model half.sws --count 4 -o bad.sws
expect_error "generate: output in a missing directory" SW_ERR_NOT_FOUND nodir/grid.sws -- \
  "$sw" generate grid --model motor.sws --count 4 -o nodir/grid.sws
# 10^7 Motor-c instances are 2.23e9 face occurrences: over what the BVH holds, refused up front.
expect_error "generate: too many occurrences" SW_ERR_LIMIT "2^31 - 1" -- \
  "$sw" generate grid --model motor.sws --count 10000000 -o bad.sws
[ ! -e bad.sws ] && ! ls bad.sws.tmp* >/dev/null 2>&1 || fail "a failed generate left a file"
cp motor.sws keep.sws && sum=$(cksum <keep.sws)
"$sw" generate grid --model no-such.step --count 4 -o keep.sws >/dev/null 2>&1
"$sw" generate grid --model motor.sws --count 10000000 -o keep.sws >/dev/null 2>&1
[ "$(cksum <keep.sws)" = "$sum" ] || fail "a failed generate changed the existing output"
# A grid of 8 Motor-c instances from its .sws: 223 faces stored once, drawn 8 times.
"$sw" generate grid --model motor.sws --count 8 -o grid.sws >gen.txt 2>&1 || { fail "generate grid"; cat gen.txt; }
grep -q "2x2x2 grid" gen.txt || fail "8 instances should be a 2x2x2 grid: $(cat gen.txt)"
"$sw" info grid.sws --json >grid.json || fail "info grid.sws"
grep -q '"faces": 223,' grid.json && grep -q '"instances": 8,' grid.json &&
  grep -q '"face_occurrences": 1784,' grid.json || fail "grid.sws: $(cat grid.json)"
"$sw" generate grid --model "$model" --count 10 --dims 2 --spacing 500 -o flat.sws >gen.txt 2>&1 ||
  { fail "generate grid --dims 2"; cat gen.txt; }
grep -q "4x3x1 grid (spacing 500, 500, 500)" gen.txt || fail "10 instances in 2D: $(cat gen.txt)"
"$sw" render grid.sws -o grid.png --size 160x120 --eval bezier >render.txt 2>&1 ||
  { fail "render grid.sws"; cat render.txt; }
[ -s grid.png ] || fail "render of grid.sws wrote no image"
# One instance at the first cell (no translation) draws exactly the model: same bytes.
"$sw" generate grid --model motor.sws --count 1 -o one.sws >/dev/null 2>&1 || fail "generate --count 1"
"$sw" render motor.sws -o model1.png --size 160x120 --eval bezier >/dev/null 2>&1 &&
  "$sw" render one.sws -o one.png --size 160x120 --eval bezier >/dev/null 2>&1 ||
  fail "render of the model or its 1-instance grid"
cmp -s model1.png one.png || fail "a 1-instance grid renders differently from its model"
pass "generate grid: usage errors, failures, a 2x2x2 grid of Motor-c, a 1-instance grid = the model"

# generate building: exactly N surfaces, deterministic, rendered, its BREP read back; bad input is
# a usage error (2) or a named failure (1) and leaves nothing behind.
"$sw" generate --help >help.txt
for opt in building --surfaces --seed --brep --data 10000000 occt-misc; do
  grep -q -- "$opt" help.txt || fail "generate --help does not mention $opt"
done
for bad in "--surfaces -5" "--surfaces 0" "--surfaces 99" "--surfaces 10000001" \
           "--surfaces 99999999999" "--surfaces 1e3" "--surfaces abc" "--seed -1" "--seed x"; do
  "$sw" generate building $bad -o bad.sws >/dev/null 2>err.txt
  rc=$?
  [ $rc -eq 2 ] || fail "generate building $bad: exit status $rc, expected 2"
  grep -q -- "${bad%% *}" err.txt || fail "generate building $bad: stderr does not name ${bad%% *}"
done
"$sw" generate building --surfaces 1000 >/dev/null 2>&1; [ $? -eq 2 ] || fail "generate building without -o accepted"
"$sw" generate building -o bad.sws >/dev/null 2>&1; [ $? -eq 2 ] || fail "generate building without --surfaces accepted"
"$sw" generate building --surfaces 1000 --model motor.sws -o bad.sws >/dev/null 2>&1; [ $? -eq 2 ] ||
  fail "generate building --model accepted"
expect_error "generate building: missing sample data" SW_ERR_NOT_FOUND no-such-dir/occ/MODERN_Chair_1.brep -- \
  "$sw" generate building --surfaces 1000 --data no-such-dir -o bad.sws --brep bad.brep
expect_error "generate building: output in a missing directory" SW_ERR_NOT_FOUND nodir/b.sws -- \
  "$sw" generate building --surfaces 1000 -o nodir/b.sws --brep b-nodir.brep
expect_error "generate building: BREP in a missing directory" SW_ERR_NOT_FOUND nodir/b.brep -- \
  "$sw" generate building --surfaces 1000 -o b-nodir.sws --brep nodir/b.brep
if [ "$(id -u)" -ne 0 ]; then
  expect_error "generate building: unwritable output" SW_ERR_IO ro/b.sws -- \
    "$sw" generate building --surfaces 1000 -o ro/b.sws
fi
for f in bad.sws bad.brep b-nodir.brep b-nodir.sws; do
  [ ! -e $f ] && ! ls $f.tmp* >/dev/null 2>&1 || fail "a failed generate building left $f"
done
"$sw" generate building --surfaces 1000 --seed 3 -o b1.sws --brep b1.brep >gen.txt 2>&1 ||
  { fail "generate building"; cat gen.txt; }
"$sw" generate building --surfaces 1000 --seed 3 -o b2.sws >/dev/null 2>&1 || fail "generate building again"
cmp -s b1.sws b2.sws || fail "generate building: one seed, two different files"
"$sw" info b1.sws --json >b1.json || fail "info b1.sws"
grep -q '"face_occurrences": 1000,' b1.json || fail "building of 1000 surfaces: $(cat b1.json)"
faces=$(sed -n 's/.*"faces": \([0-9]*\),.*/\1/p' b1.json)
[ -n "$faces" ] && [ "$faces" -ge 100 ] || fail "building: $faces unique faces of 1000"
"$sw" info b1.brep --json >b1brep.json 2>/dev/null || fail "info b1.brep"
grep -q "\"faces\": $faces," b1brep.json && grep -q '"face_occurrences": 1000,' b1brep.json ||
  fail "the BREP read back differs: $(cat b1brep.json) vs $faces faces, 1000 occurrences"
"$sw" render b1.sws -o b1.png --size 320x240 >render.txt 2>&1 || { fail "render b1.sws"; cat render.txt; }
drawn=$(sed -n 's/.*faces drawn \([0-9]*\),.*/\1/p' render.txt)
tris=$(sed -n 's/.*; \([0-9]*\) triangles;.*/\1/p' render.txt)
[ -n "$drawn" ] && [ "$drawn" -gt 0 ] && [ -n "$tris" ] && [ "$tris" -gt 0 ] ||
  fail "render of the building drew nothing: $(cat render.txt)"
# a blank 320x240 PNG compresses to a few hundred bytes; the building's image does not
[ "$(stat -c %s b1.png 2>/dev/null || echo 0)" -gt 4000 ] || fail "render of the building: blank image"
pass "generate building: usage errors, failures, 1000 surfaces ($faces unique) twice the same, rendered ($drawn faces, $tris triangles), BREP read back"

# generate vehicle: the same options and guarantees, cars instead of rooms.
"$sw" generate vehicle -o bad.sws >/dev/null 2>&1; [ $? -eq 2 ] || fail "generate vehicle without --surfaces accepted"
"$sw" generate vehicle --surfaces 20000000 -o bad.sws >/dev/null 2>&1; [ $? -eq 2 ] || fail "generate vehicle --surfaces 2e7 accepted"
expect_error "generate vehicle: missing sample data" SW_ERR_NOT_FOUND no-such-dir/occ/Motor-c.brep -- \
  "$sw" generate vehicle --surfaces 1000 --data no-such-dir -o bad.sws
[ ! -e bad.sws ] || fail "a failed generate vehicle left bad.sws"
"$sw" generate vehicle --surfaces 1000 -o v1.sws --brep v1.brep >gen.txt 2>&1 || { fail "generate vehicle"; cat gen.txt; }
"$sw" info v1.sws --json >v1.json || fail "info v1.sws"
grep -q '"face_occurrences": 1000,' v1.json || fail "vehicle of 1000 surfaces: $(cat v1.json)"
vfaces=$(sed -n 's/.*"faces": \([0-9]*\),.*/\1/p' v1.json)
"$sw" info v1.brep --json 2>/dev/null | grep -q "\"faces\": $vfaces,.*\"face_occurrences\": 1000," ||
  fail "the vehicle BREP read back differs from $vfaces faces, 1000 occurrences"
"$sw" render v1.sws -o v1.png --size 320x240 >render.txt 2>&1 || { fail "render v1.sws"; cat render.txt; }
[ "$(stat -c %s v1.png 2>/dev/null || echo 0)" -gt 4000 ] || fail "render of the vehicles: blank image"
pass "generate vehicle: usage errors, missing data, 1000 surfaces ($vfaces unique), BREP read back, rendered"

# info and the static LOD cache of a .sws: "none" before build-lod; after it, per level the
# triangles build-lod itself reported stored (catches: info reading the section wrongly, or not at
# all); and a level finer than a frame draws not stored (catches: every level written whole)
"$sw" import "$data/occ/Pump_Nut.brep" -o nut.sws >/dev/null 2>&1 || fail "import Pump_Nut"
"$sw" info nut.sws | grep -q "^  LOD cache       none" || fail "info: a scene without LODs not said"
"$sw" info nut.sws --json | grep -q '"lod_cache": null}' || fail "info --json: no lod_cache null"
"$sw" build-lod nut.sws >lods.txt 2>&1 || { fail "build-lod nut.sws"; cat lods.txt; }
built=$(awk '$1 ~ /^[0-9]$/ && $4 == "%" { printf "%s:%s ", $1, $NF }' lods.txt)
shown=$("$sw" info nut.sws | awk '$1 == "level" { printf "%s:%s ", $2, $5 }')
[ -n "$built" ] && [ "$built" = "$shown" ] || fail "info's LOD levels '$shown', build-lod's '$built'"
awk '$1 == "0" && $4 == "%" { ok = $2 > 0 && $NF < $2 } END { exit !ok }' lods.txt ||
  fail "build-lod stored all of level 0 (it is never drawn)"
"$sw" info nut.sws | grep -q "^    level 0 .*not stored: too fine to draw" ||
  fail "info: levels not stored not said"
"$sw" info nut.sws --json | python3 -c 'import json, sys; c = json.load(sys.stdin)["lod_cache"]; sys.exit(not (c["chains"] > 0 and len(c["levels"]) == 5))' ||
  fail "info --json: lod_cache"
pass "info: the LOD cache (none; then levels $shown as build-lod built them)"

# the settings it was built with; a damaged LODS section is said, not a failure of info (catches:
# settings not stored or misread; info refusing the whole scene for its cache)
"$sw" info nut.sws | grep -q "built with    δ 0.002 x each super-surface's diagonal, 4 simplified levels aiming at ε 2 δ x 4^k, ε certified" ||
  fail "info: the LOD cache's settings"
python3 - nut.sws bad_lods.sws <<'PY' || fail "a damaged copy of nut.sws"
import sys
b = bytearray(open(sys.argv[1], 'rb').read())
at = b.find(b'SWLODS\0\0')
b[at + 200] ^= 0x40  # inside the first chain: the section's checksum no longer holds
open(sys.argv[2], 'wb').write(b)
PY
"$sw" info bad_lods.sws >bad_lods.txt 2>&1 || fail "info refused a scene for its damaged LOD cache"
grep -q "^  LOD cache       unusable (SW_ERR_CHECKSUM" bad_lods.txt || fail "info: a damaged LOD cache not said"
"$sw" info bad_lods.sws --json | grep -q '"lod_cache": {"unusable": "SW_ERR_CHECKSUM"}' ||
  fail "info --json: a damaged LOD cache"
pass "info: the LOD cache's settings; a damaged cache said, the scene described"

# outlines placed into a scene (`splinewalk outline`, docs/outlines.md): info counts them, a frame
# draws them; a mistake names FILE:LINE:COLUMN and writes nothing (catches: the SHAPES section not
# written or read, the command not registered, an error without its position, a file written
# anyway)
cat >plan.txt <<'TXT'
# a floor plan on the floor and a sign above it
outline name room color 0.8 0.1 0.1
  M -0.02 -0.02 h 0.04 v 0.03 h -0.04 Z
  M 0 0.005 m -0.005 0 a 0.005 0.005 0 1 0 0.01 0 a 0.005 0.005 0 1 0 -0.01 0 Z
end
outline name sign color 0.1 0.1 0.9 origin 0 0.03 0.01 x-axis 1 0 0 y-axis 0 0 1
  M -0.01 0 L 0.01 0 L 0 0.015 Z
end
label "Nut \\ \"M8\"" size 20 screen align middle origin 0 0 0.03 color 0.9 0.9 0.1
TXT
"$sw" outline plan.txt --into nut.sws -o planned.sws >outline.txt 2>&1 || { fail "outline"; cat outline.txt; }
grep -q "2 outlines (3 loops), 1 labels -> planned.sws" outline.txt || { fail "outline: summary"; cat outline.txt; }
"$sw" info planned.sws | grep -q "^  outlines        3; drawn 3" || fail "info: outlines not counted"
"$sw" render planned.sws -o planned.png --size 320x240 >render_ol.txt 2>&1 || { fail "render planned.sws"; cat render_ol.txt; }
grep -q "outlines: 3 drawn" render_ol.txt || { fail "render: outlines not drawn"; cat render_ol.txt; }
printf 'outline\n  M 0 0 L 1 0 L 1 1\n  L 2\nend\n' >bad_plan.txt
rm -f bad.sws
expect_error "outline: a missing number" "bad_plan.txt:3:6:" bad_plan.txt -- "$sw" outline bad_plan.txt -o bad.sws
[ ! -e bad.sws ] || fail "outline: a file written after a mistake"
printf 'label "no font" font "/no/such/font.ttf"\n' >bad_font.txt
expect_error "outline: a label's missing font" SW_ERR_NOT_FOUND /no/such/font.ttf -- "$sw" outline bad_font.txt -o bad.sws
pass "outline: outlines and a label placed into a scene, counted, drawn; a mistake at its line and column"

echo "$failures failure(s)"
[ $failures -eq 0 ]
