#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# bench_peers and bench_scaling on tiny buildings, a few frames: exit status 0, truthful --help,
# usage errors exit 2, and CSVs with every column, one field per column and finite positive
# figures where a figure must be positive; GLU's and OCCT's last frames cover the same pixels
# (within 5 %: both within eps_img of the surfaces), the SVG is closed and holds its four lines.
# make_assembly (when given): copies that share their part's geometry, which import turns into
# instances of one prototype each (a copy by value would import as as many surfaces as faces).
# usage: test_bench_quick.sh SPLINEWALK BENCH_PEERS BENCH_SCALING WORKDIR [MAKE_ASSEMBLY]
set -u
sw=$1 peers=$2 scaling=$3 work=$4 assembly=${5:-}
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
pass() { echo "ok:   $*"; }

# check_csv FILE ROWS COLUMN... : the header names every COLUMN, every row has as many fields as
# the header, there are ROWS rows, and each named column holds a finite number > 0.
check_csv() {
  local file=$1 rows=$2; shift 2
  [ -s "$file" ] || { fail "$file missing or empty"; return; }
  awk -F, -v rows="$rows" -v cols="$*" '
    NR == 1 { n = NF; for (i = 1; i <= NF; i++) at[$i] = i
              k = split(cols, want, " ")
              for (j = 1; j <= k; j++) if (!(want[j] in at)) { print "no column " want[j]; bad = 1 }
              next }
    { if (NF != n) { print "row " NR - 1 ": " NF " fields, header has " n; bad = 1 }
      for (j = 1; j <= k; j++) { v = $(at[want[j]])
        if (v !~ /^[0-9]+(\.[0-9]+)?([eE][-+]?[0-9]+)?$/ || v + 0 <= 0) {
          print "row " NR - 1 " " want[j] " = \"" v "\": not a finite number > 0"; bad = 1 } } }
    END { if (NR - 1 != rows) { print NR - 1 " rows, expected " rows; bad = 1 }; exit bad }
  ' "$file" || { fail "$file"; return; }
  pass "$file: $rows rows, columns $*"
}

"$sw" generate building --surfaces 100 -o tiny.sws --brep tiny.brep >gen.txt 2>&1 \
  || { cat gen.txt; fail "splinewalk generate"; exit 1; }

# --help tells what each option is; a bad option is a usage error (2), not a run.
"$peers" --help >help.txt || fail "bench_peers --help exit status"
for opt in --peers --frames --warmup --passes --size --error --path --brep --csv glu occt \
  splinewalk glFinish VmHWM; do
  grep -q -- "$opt" help.txt || fail "bench_peers --help does not mention $opt"
done
"$peers" --frames 1 tiny.sws >/dev/null 2>&1; [ $? -eq 2 ] || fail "bench_peers --frames 1: not 2"
"$peers" --peers gl tiny.sws >/dev/null 2>&1; [ $? -eq 2 ] || fail "bench_peers --peers gl: not 2"
"$scaling" --help >help.txt || fail "bench_scaling --help exit status"
for opt in --min --max --frames --size --error --fly --dir --splinewalk --csv --svg --cold \
  --target --vehicle; do
  grep -q -- "$opt" help.txt || fail "bench_scaling --help does not mention $opt"
done
"$scaling" --min 10 >/dev/null 2>&1; [ $? -eq 2 ] || fail "bench_scaling --min 10: not 2"

# bench_peers: three peers, each in its own process.
# (without static LODs: their builds, waited for by the converged warm-up, take minutes under the
# sanitizers; bench/lod and the profile test draw them)
if "$peers" tiny.sws --frames 4 --size 160x120 --no-static-lods --csv peers.csv >peers.txt 2>&1; then
  pass "bench_peers ran: $(grep -c '^  [a-z]* *|' peers.txt) table rows"
else
  cat peers.txt; fail "bench_peers exit status"
fi
check_csv peers.csv 3 width height error_px frames ok median_ms p99_ms first_frame_ms \
  peak_rss_bytes triangles_per_frame ratio_median ratio_p99 ratio_first_frame ratio_peak_rss \
  ratio_triangles face_occurrences
awk -F, 'NR > 1 { p[$2] = NR } END { exit !("splinewalk" in p && "glu" in p && "occt" in p) }' \
  peers.csv || fail "peers.csv lacks a peer"
awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) at[$i] = i; next }
  { c[$(at["peer"])] = $(at["covered_px"]) }
  END { d = c["glu"] - c["occt"]; if (d < 0) d = -d; m = c["glu"] > c["occt"] ? c["glu"] : c["occt"]
        printf "glu %d px, occt %d px\n", c["glu"], c["occt"]; exit !(m > 0 && d <= 0.05 * m) }' \
  peers.csv && pass "GLU and OCCT cover the same pixels" || fail "GLU and OCCT cover different pixels"

# bench_scaling: two sizes, CSV and SVG.
if "$scaling" --min 100 --max 1000 --frames 3 --size 160x120 --dir scenes --csv scaling.csv \
  --svg scaling.svg >scaling.txt 2>&1; then
  pass "bench_scaling ran"
else
  cat scaling.txt; fail "bench_scaling exit status"
fi
check_csv scaling.csv 2 surfaces face_occurrences scene_bytes frames median_ms p99_ms \
  first_frame_ms peak_rss_bytes triangles_per_frame
awk -F, 'NR == 2 { a = $3 } NR == 3 { b = $3 } END { exit !(b > a) }' scaling.csv \
  && pass "scene bytes grow with the surfaces" || fail "scene bytes do not grow with the surfaces"
"$scaling" --fly --min 100 --max 100 --frames 3 --size 160x120 --dir scenes --csv fly.csv \
  >fly.txt 2>&1 || { cat fly.txt; fail "bench_scaling --fly exit status"; }
grep -q "fly-through" fly.txt || fail "bench_scaling --fly does not say it flies"
check_csv fly.csv 1 surfaces median_ms p99_ms first_frame_ms peak_rss_bytes triangles_per_frame
# a cold start of a car park: no warm-up, static LODs built as needed; with a target no frame
# misses, the first 10 frames settle (catches a settle time never measured or not printed)
"$scaling" --vehicle --cold --target 1e9 --min 100 --max 100 --frames 12 --size 160x120 \
  --dir scenes --csv cold.csv >cold.txt 2>&1 || { cat cold.txt; fail "bench_scaling --cold exit status"; }
[ -f scenes/vehicle-100.sws ] && grep -q "generated vehicles" cold.txt ||
  fail "bench_scaling --vehicle did not draw a car park"
grep -q "settled: 10 frames' median <= 1e+09 ms" cold.txt || { cat cold.txt; fail "--cold: not settled"; }
check_csv cold.csv 1 surfaces median_ms first_frame_ms settle_ms
awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) at[$i] = i; next }
  { exit !($(at["settle_ms"]) >= $(at["first_frame_ms"])) }' cold.csv ||
  fail "--cold: settled before the first frame"
[ "$(grep -c '<polyline' scaling.svg)" -eq 4 ] && tail -n 1 scaling.svg | grep -q '</svg>' \
  && pass "scaling.svg: 4 lines, closed" || fail "scaling.svg malformed"

# make_assembly: Pump_Nut (25 faces) and screw.step (10) taken in turn until 300 faces: 9 rounds,
# 18 copies, 315 faces drawn from 35 prototype surfaces.
occ=/usr/share/opencascade/data
if [ -n "$assembly" ] && [ -f $occ/occ/Pump_Nut.brep ] && [ -f $occ/step/screw.step ]; then
  "$assembly" --help | grep -q -- "--faces" || fail "make_assembly --help does not mention --faces"
  "$assembly" --faces 0 -o x.brep $occ/occ/Pump_Nut.brep >/dev/null 2>&1
  [ $? -eq 2 ] || fail "make_assembly --faces 0: not 2"
  if "$assembly" $occ/occ/Pump_Nut.brep $occ/step/screw.step --faces 300 -o asm.brep >asm.txt 2>&1 \
    && "$sw" import asm.brep -o asm.sws >imp.txt 2>&1 && "$sw" info asm.sws >info.txt 2>&1; then
    grep -q "18 copies of 2 parts, 315 faces" asm.txt || { cat asm.txt; fail "make_assembly's count"; }
    grep -Eq "^ +surfaces +35 " info.txt && grep -q "instances 18, surfaces drawn 315" info.txt \
      && pass "make_assembly: 18 instances of 2 parts, 315 faces from 35 surfaces" \
      || { cat info.txt; fail "make_assembly's copies are not instances of shared parts"; }
  else
    cat asm.txt imp.txt; fail "make_assembly, import or info exit status"
  fi
fi

[ $failures -eq 0 ] && echo "all passed" || echo "$failures failed"
[ $failures -eq 0 ]
