#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# splinewalk path and profile, end to end on the default scene:
# - `path orbit|fly` write paths that `profile` reads back;
# - `profile` writes profile.csv with the documented columns and one row per frame, all numbers;
#   profile.json agrees with the CSV (its median recomputed here); other_ms = frame_ms - stages;
# - converged: on the median frame the stages add up to frame_ms within 5 % (other <= 5 %);
#   walkthrough: no frame waits for the pool (pool_waits 0 and vis_hierarchy_ms 0.0000: both
#   count where a frame's threads block on the pool, in both modes, so the checks can fail; seen
#   failing with a planted walkthrough wait for one face's build in gpu/stage_hierarchy.c
#   request_walkthrough: pool_waits and vis_hierarchy_ms both fail); converged: no fallback draws;
# - frametime.svg and report.html are well-formed XML; 3 frames captured, nothing left staged;
# - bad path files: the malformed corpus (tests/malformed) holds them; here a failed run leaves an
#   existing output directory as it was, a subnormal is read, `path` refuses to write inf keys.
# usage: test_profile.sh SPLINEWALK DATA_DIR WORKDIR SOURCE_DIR
set -u
sw=$1 data=$2 work=$3 src=$4
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
pass() { echo "ok:   $*"; }
for tool in xmllint jq awk; do
  command -v $tool >/dev/null || { echo "FAIL: $tool not installed (scripts/install-deps.sh)"; exit 1; }
done

columns="frame,t_s,frame_ms,wait_visibility_ms,prepare_ms,trim_ms,draw_ms,readback_ms,write_ms,other_ms,vis_ms,vis_hierarchy_ms,vis_tessellate_ms,vis_join_ms,patches,patches_trimmed,patches_culled,faces_drawn,faces_culled,hierarchy_nodes,refine_rounds,triangles,border_triangles,border_loops_kept,border_loops_made,border_quads_away,trim_textures,trim_texels,trim_reused,trim_exact,atlas_pages,fallback_draws,pool_waits,gpu_ms,static_drawn,static_faces,static_triangles,static_requests,proxies_drawn,proxy_instances,proxy_triangles,bound_exceeded,bound_excess_px,budget_coarsened,occlusion_tests,nodes_occluded,faces_occluded,resident_triangles,grid_hits,grid_misses,upload_bytes,pool_other_ms,pool_hierarchy_ms,pool_hierarchy_wait_ms,pool_refine_ms,pool_static_cluster_ms,pool_static_build_ms,pool_static_retire_ms,pool_static_proxy_ms,pool_compile_ms,pool_frame_stage_ms,pool_other_tasks,pool_hierarchy_tasks,pool_hierarchy_wait_tasks,pool_refine_tasks,pool_static_cluster_tasks,pool_static_build_tasks,pool_static_retire_tasks,pool_static_proxy_tasks,pool_compile_tasks,pool_frame_stage_tasks,pool_queued,pool_inject_peak,resident_bytes,captured"
# col NAME: NAME's field number in profile.csv (the stages lie between frame_ms and other_ms)
col() { echo "$columns" | tr , '\n' | grep -nx "$1" | cut -d: -f1; }

# ---- help and usage ---------------------------------------------------------------------------
"$sw" --help | grep -q '^  profile' || fail "splinewalk --help does not list profile"
"$sw" --help | grep -q '^  path' || fail "splinewalk --help does not list path"
"$sw" profile --help >help.txt || fail "profile --help exit status"
for opt in --path --out --frames --size --error --converged --sequential --threads --eval; do
  grep -q -- "$opt" help.txt || fail "profile --help does not mention $opt"
done
"$sw" path --help | grep -q -- --seconds || fail "path --help does not mention --seconds"
"$sw" path spiral x.sws -o p.path >/dev/null 2>&1; [ $? -eq 2 ] || fail "path spiral: not a usage error"
"$sw" profile x.sws --path p.path >/dev/null 2>&1; [ $? -eq 2 ] || fail "profile without --out: not a usage error"
"$sw" profile x.sws --path p.path --out o --sequential --threads 2 >/dev/null 2>&1
[ $? -eq 2 ] || fail "--sequential with --threads: not a usage error"
for c in ${columns//,/ }; do
  grep -q "\`$c\`" "$src/docs/camera-path.md" || fail "column $c is not documented in docs/camera-path.md"
done
pass "help texts, usage errors, documented columns"

# ---- paths on the default scene -----------------------------------------------------------------
"$sw" demo -o demo --data "$data" --size 64x48 >demo.txt 2>&1 || { fail "demo"; cat demo.txt; exit 1; }
scene=demo/default.sws
surfaces=$("$sw" info $scene | awk '$1 == "surfaces" { print $2 }')
[ "$surfaces" -gt 0 ] 2>/dev/null || fail "splinewalk info: no surface count"
"$sw" path orbit $scene -o orbit.path --frames 40 --seconds 8 >path.txt 2>&1 || { fail "path orbit"; cat path.txt; }
"$sw" path fly $scene -o fly.path --frames 8 >>path.txt 2>&1 || { fail "path fly"; cat path.txt; }
"$sw" path walk $scene -o walk.path --eye-height 0.5 >>path.txt 2>&1 || { fail "path walk"; cat path.txt; }
[ "$(grep -c '^key ' walk.path)" -eq 9 ] || fail "walk.path: expected 9 keys"
head -1 orbit.path | grep -qx 'splinewalk-path 1' || fail "orbit.path header: $(head -1 orbit.path)"
grep -qx closed orbit.path || fail "orbit.path is not closed"
grep -qx 'frames 40' orbit.path || fail "orbit.path does not suggest 40 frames"
[ "$(grep -c '^key ' orbit.path)" -eq 17 ] || fail "orbit.path: expected 16 keys + the closing one"
ls orbit.path.tmp-* >/dev/null 2>&1 && fail "path left a temporary file"
pass "path orbit / fly / walk"

# ---- checks on one run's files ------------------------------------------------------------------
# check_run DIR N: columns, N numeric rows, other = frame - stages, JSON = CSV, XML, captures.
check_run() {
  local dir=$1 n=$2
  [ "$(head -1 "$dir/profile.csv")" = "$columns" ] || fail "$dir: CSV header: $(head -1 "$dir/profile.csv")"
  [ "$(($(wc -l <"$dir/profile.csv") - 1))" -eq "$n" ] || fail "$dir: CSV rows $(($(wc -l <"$dir/profile.csv") - 1)), expected $n"
  # border_triangles: some in every run (every face drawn gets its fat borders), never more than
  # the triangles they are counted in (a field left unset or counted apart fails here)
  awk -F, -v n="$(echo "$columns" | tr , "\n" | wc -l)" -v n_other="$(col other_ms)" -v n_tri="$(col triangles)" \
      -v n_border="$(col border_triangles)" 'NR > 1 {
      if ($n_border > $n_tri) { print "row " NR ": " $n_border " border triangles of " $n_tri; bad = 1 }
      borders += $n_border
      if (NF != n) { print "row " NR ": " NF " fields"; bad = 1 }
      for (i = 1; i <= NF; i++) if ($i !~ /^-?[0-9]+(\.[0-9]+)?$/) { print "row " NR " field " i ": " $i; bad = 1 }
      if ($1 != NR - 2) { print "row " NR ": frame " $1; bad = 1 }
      stages = 0; for (i = 4; i < n_other; i++) stages += $i
      if (($3 - stages - $n_other) > 0.002 || ($3 - stages - $n_other) < -0.002) { print "row " NR ": other " $n_other " != " $3 - stages; bad = 1 }
      if (NR > 2 && $2 <= prev_t) { print "row " NR ": t_s not increasing"; bad = 1 }
      prev_t = $2
    } END { if (!(borders > 0)) { print "no fat-border triangles in any frame"; bad = 1 }
            exit bad }' "$dir/profile.csv" >awk.txt || { fail "$dir: CSV rows"; head -5 awk.txt; }
  jq -e ".frame_count == $n and (.frames | length) == $n" "$dir/profile.json" >/dev/null ||
    fail "$dir: profile.json is not valid JSON or has not $n frames"
  local med_csv med_json
  med_csv=$(tail -n +2 "$dir/profile.csv" | cut -d, -f3 | sort -g |
            awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }')
  med_json=$(jq '.summary.frame_ms.median' "$dir/profile.json")
  awk -v a="$med_csv" -v b="$med_json" 'BEGIN { exit !(a - b < 0.001 && b - a < 0.001) }' ||
    fail "$dir: JSON median frame_ms $med_json, CSV gives $med_csv"
  for s in wait_visibility trim draw readback write other vis vis_hierarchy vis_tessellate pool_hierarchy pool_refine; do
    jq -e ".summary.${s}_ms | has(\"median\") and has(\"p90\") and has(\"p99\") and has(\"max\")" \
      "$dir/profile.json" >/dev/null || fail "$dir: summary lacks ${s}_ms"
  done
  xmllint --noout "$dir/frametime.svg" 2>xml.txt || { fail "$dir: frametime.svg not well-formed"; cat xml.txt; }
  xmllint --noout "$dir/report.html" 2>xml.txt || { fail "$dir: report.html not well-formed"; cat xml.txt; }
  grep -q '<svg' "$dir/report.html" || fail "$dir: report.html holds no SVG"
  local caps
  caps=$(awk -F, 'NR > 1 && $NF == 1 { printf "%s ", $1 }' "$dir/profile.csv")
  [ "$caps" = "0 $((n / 2)) $((n - 1)) " ] || fail "$dir: captured frames '$caps'"
  for f in $caps; do
    local png
    png=$(printf 'frame-%04d.png' "$f")
    [ -s "$dir/$png" ] || fail "$dir: $png missing"
    grep -q "$png" "$dir/report.html" || fail "$dir: report.html does not show $png"
  done
  [ "$(ls "$dir"/*.png | wc -l)" -eq 3 ] || fail "$dir: more PNGs than captures"
  ls -a "$dir" | grep -q '^\.profile-' && fail "$dir: staging directory left behind"
  check_pool "$dir"
}

# check_pool DIR: the pool columns. Every task the renderer submits names its kind (no "other");
# the first frame, which sees the scene first, ran hierarchy builds for some time (with one
# worker: the first frame after the static LODs' clustering); each face's
# hierarchy is built once (builds <= surfaces); the pool's threads (the workers, plus the frame's
# thread while a converged frame waits) cannot have spent more than (workers + 1) x the run's wall
# time in tasks — in walkthrough mode, where only the workers run tasks and a running task's time
# counts in the frames it spans and the counters are read inside the frame's window, not even in
# any one frame (workers x frame_ms, plus 1 ms for the clocks); the visibility thread's requests went through the injection
# queue in the first frame (peak > 0).
check_pool() {
  local dir=$1 workers wall first
  [ "$(column "$dir" pool_other_tasks | sort -u)" = 0 ] || fail "$dir: pool tasks of no kind"
  workers=$(jq .worker_threads "$dir/profile.json") wall=$(jq .wall_s "$dir/profile.json")
  # With one worker, the static LODs' clustering (one task, submitted as the scene is first seen)
  # may take that worker before the first frame's hierarchy requests arrive (which comes first is
  # the threads' race); the builds then start in the frame where the clustering ended, or, when it
  # ended at that frame's close, in the next.
  first=0
  if [ "$workers" = 1 ]; then
    first=$(paste -d' ' <(column "$dir" pool_static_cluster_tasks) \
                        <(column "$dir" pool_static_cluster_ms) |
            awk '$1 > 0 { print NR - 1; exit } $2 == 0 { print NR - 1; exit }')
  fi
  local last=$first
  [ "$first" -gt 0 ] || [ "$workers" != 1 ] || last=1
  [ "$first" -gt 0 ] && last=$((first + 1))
  column "$dir" pool_hierarchy_tasks | sed -n "$((first + 1)),$((last + 1))p" |
    awk '{ n += $1 } END { exit !(n > 0) }' ||
    fail "$dir: no hierarchy build in the first frame (frames $first..$last)"
  column "$dir" pool_hierarchy_ms | sed -n "$((first + 1)),$((last + 1))p" |
    awk '{ t += $1 } END { exit !(t > 0) }' ||
    fail "$dir: no hierarchy build time in the first frame (frames $first..$last)"
  column "$dir" pool_hierarchy_tasks | awk -v s="$surfaces" '{ n += $1 } END { exit !(n >= 1 && n <= s) }' ||
    fail "$dir: $(column "$dir" pool_hierarchy_tasks | awk '{ n += $1 } END { print n }') hierarchy builds for $surfaces surfaces"
  awk -F, -v w="$workers" -v wall="$wall" '
    NR == 1 { for (i = 1; i <= NF; i++) pool[i] = ($i ~ /^pool_.*_ms$/); next }
    { for (i = 1; i <= NF; i++) if (pool[i]) ms += $i }
    END { printf "pool %.1f ms in a %.1f ms run on %d workers\n", ms, 1e3 * wall, w
          exit !(ms > 0 && ms <= (w + 1) * 1e3 * wall * 1.01 + 1) }' "$dir/profile.csv" >pool.txt ||
    fail "$dir: pool time out of bounds: $(cat pool.txt)"
  if [ "$(jq -r .mode "$dir/profile.json")" = walkthrough ]; then
    awk -F, -v w="$workers" '
      NR == 1 { for (i = 1; i <= NF; i++) pool[i] = ($i ~ /^pool_.*_ms$/); next }
      { ms = 0; for (i = 1; i <= NF; i++) if (pool[i]) ms += $i
        if (ms > w * ($3 + 1)) { printf "frame %d: pool %.2f ms in a %.2f ms frame\n", $1, ms, $3; bad = 1 } }
      END { exit bad }' "$dir/profile.csv" >frames.txt || fail "$dir: pool time above workers x frame: $(head -3 frames.txt)"
  fi
  column "$dir" pool_inject_peak | head -1 | awk '{ exit !($1 > 0) }' ||
    fail "$dir: the first frame's requests did not show in pool_inject_peak"
}

# settled DIR: a run along the closed orbit comes round to where it started: in its last 4
# frames every face in view has its hierarchy, so nothing is built or refined any more. (The
# frame's own tessellation chunks go through the pool's injection queue every frame, and a helper
# that found every chunk taken may still be queued at the frame's end: queue and injection
# figures no longer tell a settled run.)
settled() {
  for c in pool_hierarchy_tasks pool_refine_tasks; do
    [ "$(column "$1" $c | tail -4 | sort -u)" = 0 ] ||
      fail "$1: $c not 0 in the last 4 frames: $(column "$1" $c | tail -4 | tr '\n' ' ')"
  done
}

# column VALUE of DIR: every row's value of a column, one a line.
column() { awk -F, -v c="$2" 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == c) k = i; next } { print $k }' "$1/profile.csv"; }

# stages_add_up DIR ROW: on the ROW-th fastest frame (the median), the submitting thread's stages
# add up to frame_ms within 5 % (other <= 5 %).
stages_add_up() {
  tail -n +2 "$1/profile.csv" | sort -t, -k3 -g | sed -n "$2p" | awk -F, -v o="$(col other_ms)" '{
    stages = 0; for (i = 4; i < o; i++) stages += $i
    printf "median frame %d: frame %.3f ms, stages %.3f ms, other %.3f ms (%.2f %%)\n", $1, $3, stages, $o, 100 * $o / $3
    exit !($3 > 0 && stages >= 0.95 * $3 && stages <= 1.05 * $3 && $o <= 0.05 * $3) }'
}

# ---- walkthrough (the default mode), threaded: the visibility thread prepares the next frame ----
# Without occlusion culling here and in the converged run: `settled` assumes one revolution draws
# every face the next one does, and a frame resting from occlusion culling draws faces that
# frames before it hid (their hierarchies are built then; the fly-through below has it on).
"$sw" profile $scene --path orbit.path --size 320x240 --out walk --no-occlusion >walk.txt 2>walk.err ||
  { fail "profile (walkthrough)"; cat walk.txt walk.err; }
check_run walk 40
[ "$(column walk pool_waits | sort -u)" = 0 ] || fail "walkthrough: a frame waited for the pool"
[ "$(column walk vis_hierarchy_ms | sort -u)" = 0.0000 ] || fail "walkthrough: hierarchy waits on the visibility thread"
[ "$(column walk pool_hierarchy_wait_tasks | sort -u)" = 0 ] || fail "walkthrough: a pool task waited for a build"
settled walk
# pixels are read back only for the frames written (3 captures), not for every frame: the
# median of the others' readback_ms is a clock read's (it was 0.05 ms at 320x240 reading back)
paste -d, <(column walk captured) <(column walk readback_ms) | awk -F, '$1 == 0 { print $2 }' |
  sort -g | awk '{ v[NR] = $1 } END { exit !(NR > 0 && v[int((NR + 1) / 2)] < 0.01) }' ||
  fail "walkthrough: frames not written are read back: $(column walk readback_ms | tr '\n' ' ')"
pass "walkthrough pool: $(cat pool.txt); queue peak $(column walk pool_inject_peak | head -1) in frame 0, 0 at the end"
column walk vis_ms | awk '!($1 > 0) { bad = 1 } END { exit bad }' || fail "threaded: a frame without visibility-thread time"
stages_add_up walk 20 >median.txt || fail "threaded: the submitting thread's stages do not add up: $(cat median.txt)"
pass "threaded: $(cat median.txt)"
jq -e '.mode == "walkthrough" and .lp_num_threads == "2"' walk/profile.json >/dev/null ||
  fail "walkthrough: run description in profile.json"
grep -q 'frames in' walk.err || fail "no final progress line on a non-terminal stderr"
# static LODs by default: the scene has no LOD cache, so its levels are asked of the pool, and said
paste -d, <(column walk static_requests) <(column walk static_drawn) |
  awk -F, '{ n += $1 + $2 } END { exit !(n > 0) }' || fail "walkthrough: static LODs not on by default"
grep -q 'static LODs: .* has no LOD cache' walk.err || fail "walkthrough: the missing LOD cache not said"
pass "walkthrough: 40 frames, $(sed -n 's/^frame *\([0-9.]*\).*/\1/p' walk.txt) ms median"

# ---- converged: the stages account for the frame ------------------------------------------------
# Without static LODs here and in the sequential run: a converged frame waits for every level it
# needs, which under the sanitizers takes minutes; the walkthrough above draws them (the default).
"$sw" profile $scene --path orbit.path --frames 40 --size 320x240 --out conv --converged \
  --no-occlusion --no-static-lod >conv.txt 2>&1 || { fail "profile --converged"; cat conv.txt; }
check_run conv 40
[ "$(column conv fallback_draws | sort -u)" = 0 ] || fail "converged: fallback draws"
column conv pool_hierarchy_wait_tasks | awk '{ n += $1 } END { exit !(n > 0) }' ||
  fail "converged: no pool task waited for a hierarchy build"
# the wait counters are alive where waits happen (the walkthrough's 0 above means something)
column conv pool_waits | awk '{ n += $1 } END { exit !(n > 0) }' ||
  fail "converged: no frame counted a pool wait"
column conv vis_hierarchy_ms | awk '{ t += $1 } END { exit !(t > 0) }' ||
  fail "converged: no hierarchy wait timed"
settled conv
pass "converged pool: $(cat pool.txt)"
stages_add_up conv 20 >median.txt || fail "converged: stages do not add up on the median frame: $(cat median.txt)"
pass "converged: $(cat median.txt)"

# ---- sequential and the fly-through -------------------------------------------------------------
"$sw" profile $scene --path orbit.path --frames 6 --size 160x120 --out seq --sequential --no-occlusion \
  --no-static-lod >seq.txt 2>&1 ||
  { fail "profile --sequential"; cat seq.txt; }
check_run seq 6
[ "$(column seq occlusion_tests | sort -u)" = 0 ] || fail "--no-occlusion: occlusion tests counted"
# One pipeline: sw_renderer_draw prepares on the visibility thread too (vis_ms), and a sequential
# frame waits for all of it before it is drawn (nothing overlaps: wait_visibility_ms covers
# vis_ms, less the clock reads' spacing).
paste -d, <(column seq vis_ms) <(column seq wait_visibility_ms) |
  awk -F, '!($1 > 0) || $2 < $1 - 0.05 { bad = 1 } END { exit bad }' ||
  fail "--sequential: not prepared on the visibility thread and waited for: $(paste -d, <(column seq vis_ms) <(column seq wait_visibility_ms) | tr '\n' ' ')"
stages_add_up seq 3 >median.txt || fail "--sequential: stages do not add up: $(cat median.txt)"
echo "      sequential: $(cat median.txt)"
jq -e '.worker_threads == 1 and .sequential == true and .mode == "converged"' seq/profile.json \
  >/dev/null || fail "--sequential: not one worker, converged: $(jq -c '[.worker_threads, .sequential, .mode]' seq/profile.json)"
"$sw" profile $scene --path fly.path --size 160x120 --out fly --threads 1 >fly.txt 2>&1 ||
  { fail "profile along fly.path"; cat fly.txt; }
check_run fly 8
jq -e '.worker_threads == 1' fly/profile.json >/dev/null || fail "--threads 1 not passed through"
# Occlusion culling is on by default: boxes are tested against the occlusion map in the first
# frame, and a frame goes without it only after a culled frame that hid nothing (its rest).
paste -d, <(column fly occlusion_tests) <(column fly nodes_occluded) <(column fly faces_occluded) |
  awk -F, 'NR == 1 && !($1 > 0) { bad = 1 } $1 > 0 && $2 + $3 == 0 { idle = 1 } !($1 > 0) && !idle { bad = 1 }
           END { exit bad }' ||
  fail "occlusion culling: a frame without tests before any that hid nothing: $(column fly occlusion_tests | tr '\n' ' ')"
pass "sequential and fly-through runs (occlusion culling on)"

# ---- bad path files -----------------------------------------------------------------------------
key2='key 1  0 10 0  0 0 0  0 0 1  40'
# Every bad path file (30 of them, each with its error id) is in the malformed corpus
# (tests/malformed: refused by `profile` with FILE:LINE, exit 1, nothing written).
# An existing output directory is left as it was.
mkdir -p keep && echo old >keep/marker
printf 'splinewalk-path 1\nkey 0 1\n' >cut.path
"$sw" profile $scene --path cut.path --out keep >/dev/null 2>&1; [ $? -eq 1 ] || fail "cut.path accepted"
[ "$(ls -A keep)" = marker ] || fail "a failed run changed its output directory: $(ls -A keep)"
"$sw" profile $scene --path no-such.path --out nothing >/dev/null 2>err.txt; [ $? -eq 1 ] &&
  grep -q SW_ERR_NOT_FOUND err.txt || fail "missing path file: $(cat err.txt)"
# A subnormal coordinate is a (tiny) finite number, read as such.
printf 'splinewalk-path 1\nkey 0  10 1e-310 0  0 0 0  0 0 1  40\n%s\n' "$key2" >tiny.path
"$sw" profile $scene --path tiny.path --frames 2 --size 32x24 --out tiny >tiny.txt 2>&1 ||
  { fail "a subnormal coordinate refused"; cat tiny.txt; }
# `path` never writes a key it would refuse to read: 1e308 s overflows the key times.
"$sw" path orbit $scene -o inf.path --seconds 1e308 >inf.txt 2>&1; rc=$?
[ $rc -eq 1 ] && grep -q "inf.path (not written):.*'inf'" inf.txt && [ ! -e inf.path ] ||
  fail "path orbit --seconds 1e308: exit $rc, $(cat inf.txt), $(ls inf.path* 2>&1)"
# An --error below SW_ERROR_MIN_PX is refused before the output folder is made.
"$sw" profile $scene --path orbit.path --error 0.001 --out tiny_error >/dev/null 2>err.txt; rc=$?
[ $rc -eq 2 ] && [ ! -e tiny_error ] || fail "--error 0.001: exit $rc, $(cat err.txt)"
pass "bad runs: the output directory kept, a subnormal read, inf keys and --error 0.001 refused"

[ $failures -eq 0 ] && echo "all profile tests passed" || echo "$failures failure(s)"
exit $((failures > 0))
