#!/usr/bin/env bash
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

echo "$failures failure(s)"
[ $failures -eq 0 ]
