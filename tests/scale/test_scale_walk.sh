#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# scale_walk_1e5 (large-model readiness; label heavy): a generated 10^5-surface building
# is loaded and walked by a walkthrough profile run along a fly-through, and
# - generate, path and profile exit 0; the building has 10^5 surfaces drawn;
# - profile.csv has the documented header and one numeric row per frame, frame indices in order;
#   profile.json holds the same number of frames;
# - every frame draws faces and triangles (a walk that loads nothing or draws nothing fails);
# - no frame waits for the worker pool (walkthrough mode). pool_waits counts wherever
#   the frame's threads block on the pool (before, only the converged branch counted,
#   so 0 held by construction); seen failing with a planted walkthrough wait for one face's
#   build (gpu/stage_hierarchy.c request_walkthrough): frames 9, 11, 12, 14, 16 "1 pool waits";
# - the peak resident set of the profile process stays under MAX_RSS_MIB (from the measured peak,
#   with margin: see tests/scale/CMakeLists.txt).
# usage: test_scale_walk.sh SPLINEWALK PEAK_RSS DATA_DIR WORKDIR SOURCE_DIR FRAMES MAX_RSS_MIB
set -u
sw=$1 peak=$2 data=$3 work=$4 src=$5 frames=$6 max_mib=$7
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
pass() { echo "ok:   $*"; }
command -v jq >/dev/null || { echo "FAIL: jq not installed (scripts/install-deps.sh)"; exit 1; }

# The documented columns, read from docs/camera-path.md's table (one `name` per row), so that the
# check follows the documentation rather than a copy of the header.
columns=$(sed -n '/^| `frame` |/,/^$/p' "$src/docs/camera-path.md" |
          sed -n 's/^| `\([a-z_0-9]*\)` |.*/\1/p' | paste -sd, -)
[ -n "$columns" ] || { echo "FAIL: no column table in docs/camera-path.md"; exit 1; }

t0=$(date +%s.%N)
"$sw" generate building --surfaces 100000 --data "$data" -o b1e5.sws >gen.txt 2>&1 ||
  { fail "generate building --surfaces 100000"; cat gen.txt; exit 1; }
t1=$(date +%s.%N)
grep -q "building of 100000 surfaces" gen.txt || fail "generate: $(cat gen.txt)"
"$sw" info b1e5.sws >info.txt 2>&1 || fail "info"
grep -Eq "surfaces drawn 100000$" info.txt || fail "info does not draw 100000 surfaces: $(grep drawn info.txt)"
"$sw" path fly b1e5.sws -o fly.path --frames "$frames" >path.txt 2>&1 || { fail "path fly"; cat path.txt; }
pass "generated $(stat -c %s b1e5.sws) bytes in $(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.1f", b - a }') s; path fly"

"$peak" rss.txt "$sw" profile b1e5.sws --path fly.path --frames "$frames" --size 1280x720 \
  --out prof >prof.txt 2>&1
rc=$?
cat prof.txt
[ $rc -eq 0 ] || { fail "profile exit status $rc"; exit 1; }

csv=prof/profile.csv
[ "$(head -1 $csv)" = "$columns" ] || fail "CSV header: $(head -1 $csv)"
rows=$(($(wc -l <$csv) - 1))
[ "$rows" -eq "$frames" ] || fail "CSV rows $rows, expected $frames"
col() { echo "$columns" | tr , '\n' | grep -nx "$1" | cut -d: -f1; }
c_tri=$(col triangles) c_faces=$(col faces_drawn) c_waits=$(col pool_waits) c_frame=$(col frame)
n_cols=$(echo "$columns" | tr , '\n' | wc -l)
awk -F, -v n="$n_cols" -v ct="$c_tri" -v cf="$c_faces" -v cw="$c_waits" -v c0="$c_frame" 'NR > 1 {
    if (NF != n) { print "row " NR ": " NF " fields"; bad = 1 }
    for (i = 1; i <= NF; i++) if ($i !~ /^-?[0-9]+(\.[0-9]+)?$/) { print "row " NR " field " i ": " $i; bad = 1 }
    if ($c0 != NR - 2) { print "row " NR ": frame " $c0; bad = 1 }
    if (!($ct > 0) || !($cf > 0)) { print "frame " $c0 ": " $ct " triangles, " $cf " faces"; bad = 1 }
    if ($cw != 0) { print "frame " $c0 ": " $cw " pool waits"; bad = 1 }
  } END { exit bad }' $csv >awk.txt || { fail "CSV rows"; head -20 awk.txt; }
jq -e ".frame_count == $frames and (.frames | length) == $frames" prof/profile.json >/dev/null ||
  fail "profile.json is not valid JSON or has not $frames frames"
pass "$rows frames, every one with triangles and faces drawn, 0 pool waits"

kib=$(sed -n 's/^peak_rss_kib \([0-9]*\)$/\1/p' rss.txt)
[ -n "$kib" ] || fail "no peak RSS: $(cat rss.txt)"
mib=$((${kib:-0} / 1024))
echo "peak RSS of the profile run: $mib MiB (bound $max_mib MiB)"
[ "$mib" -gt 0 ] && [ "$mib" -lt "$max_mib" ] || fail "peak RSS $mib MiB not under $max_mib MiB"

[ $failures -eq 0 ] && echo "scale_walk: all checks passed" || echo "scale_walk: $failures failure(s)"
[ $failures -eq 0 ]
