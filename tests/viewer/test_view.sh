#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# tests/viewer: `splinewalk view` as a user meets it.
#  1. No display: exit 1 with a message that points to `splinewalk profile` (before any import).
#  2. Bad arguments: --screenshot without --script is a usage error (2); a missing script file
#     is named in the error (1).
#  3. Under xvfb-run: the window opens, 60 frames of a scripted orbit are drawn in walkthrough mode
#     (0 pool waits: counted wherever the frame blocks on the pool — before, only on
#     the converged branch, so 0 held by construction; seen failing with a planted walkthrough
#     wait for one face's build, "pool waits 1"), the last view is drawn converged (--settle),
#     the window's back buffer is saved through OpenImageIO, and the viewer closes cleanly
#     (exit 0). The screenshot must match `splinewalk render --camera` of the camera it printed
#     (<= 0.1 % of pixels differ): what the window shows is the renderer's frame, presented into
#     the window's framebuffer. These runs are without static LODs (--no-static-lod; render draws
#     none without a LOD cache); 5. has them, as the viewer draws by default.
#     The frame-time, wireframe and trim-atlas overlays change the frame, each only as it should.
#  4. samples/embed_minimal (a GLFW host of the public API) draws 30 frames into its window and
#     exits 0.
#  5. Static LODs (the default) and LOD colouring (--lod-colors, keys T and C) on STATIC_MODEL: the
#     settled screenshot equals `render --static-lod --lod-colors` of its camera, and differs from
#     the plain render (the colours show which representation drew each surface); with
#     --no-static-lod it equals the plain render.
# usage: test_view.sh SPLINEWALK PNG_DIFF MODEL WORKDIR EMBED_MINIMAL STATIC_MODEL
set -euo pipefail
sw=$1 diff=$2 model=$3 work=$4 embed=$5 static_model=$6
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*"; exit 1; }

set +e
out=$(env -u DISPLAY -u WAYLAND_DISPLAY "$sw" view "$model" 2>&1); rc=$?
set -e
[ $rc -eq 1 ] || fail "no display: exit $rc, expected 1"
grep -q "splinewalk profile" <<<"$out" || fail "no display: message does not point to profile: $out"
grep -q "% convert" <<<"$out" && fail "no display: the scene was imported before the display check"
echo "ok: no display -> exit 1, points to splinewalk profile"

set +e
"$sw" view "$model" --screenshot "$work/x.png" >/dev/null 2>&1; rc=$?
[ $rc -eq 2 ] || fail "--screenshot without --script: exit $rc, expected 2"
out=$(xvfb-run -a -s "-screen 0 1280x1024x24" "$sw" view "$model" --script "$work/missing.path" 2>&1); rc=$?
set -e
[ $rc -eq 1 ] || fail "missing script: exit $rc, expected 1"
grep -q "missing.path" <<<"$out" || fail "missing script not named: $out"
echo "ok: bad arguments -> 2, missing script -> 1 naming it"

"$sw" path orbit "$model" -o "$work/orbit.path" >/dev/null 2>&1
xvfb-run -a -s "-screen 0 1280x1024x24" "$sw" view "$model" --size 640x360 --no-static-lod \
  --script "$work/orbit.path" --frames 60 --settle --screenshot "$work/shot.png" \
  >"$work/view.out" 2>"$work/view.err" || { cat "$work/view.err"; fail "view exited $?"; }
cat "$work/view.out"
grep -q "^script: 60 frames" "$work/view.out" || fail "not 60 frames"
grep -q "pool waits 0," "$work/view.out" || fail "walkthrough frames waited for the pool"
[ -s "$work/shot.png" ] || fail "no screenshot"
cam=$(sed -n 's/^screenshot camera //p' "$work/view.out")
[ -n "$cam" ] || fail "no camera printed"
"$sw" render "$model" -o "$work/render.png" --size 640x360 --camera "$cam" >/dev/null 2>&1
"$diff" "$work/shot.png" "$work/render.png" 0.1 || fail "screenshot differs from render"
# Negative control: the comparison sees a different view.
"$sw" render "$model" -o "$work/other.png" --size 640x360 --view front >/dev/null 2>&1
if "$diff" "$work/shot.png" "$work/other.png" 0.1 >/dev/null; then
  fail "control: the front view compared equal to the screenshot"
fi
echo "ok: 60 scripted frames, settled screenshot equals splinewalk render of its camera"

# The frame-time overlay (the viewer's own GL drawing over the presented frame): the same run with
# --overlay differs from the render, but only in the overlay's corner (at most 20 % of the pixels:
# a 360 x 120 box of 640 x 360 is 18.75 %).
xvfb-run -a -s "-screen 0 1280x1024x24" "$sw" view "$model" --size 640x360 --no-static-lod \
  --script "$work/orbit.path" --frames 10 --settle --overlay --screenshot "$work/overlay.png" \
  >"$work/overlay.out" 2>"$work/overlay.err" || { cat "$work/overlay.err"; fail "view --overlay"; }
cam=$(sed -n 's/^screenshot camera //p' "$work/overlay.out")
"$sw" render "$model" -o "$work/render10.png" --size 640x360 --camera "$cam" >/dev/null 2>&1
if "$diff" "$work/overlay.png" "$work/render10.png" 0.1 >/dev/null; then
  fail "--overlay: no overlay drawn"
fi
"$diff" "$work/overlay.png" "$work/render10.png" 20 || fail "--overlay changed more than its corner"
echo "ok: the overlay is drawn over the frame, in its corner only"

# Wireframe: the same settled view drawn as lines differs from the shaded render in over 1 % of
# the pixels (the surfaces' interiors turn to background between the lines).
xvfb-run -a -s "-screen 0 1280x1024x24" "$sw" view "$model" --size 640x360 --no-static-lod \
  --script "$work/orbit.path" --frames 10 --settle --wireframe --screenshot "$work/wire.png" \
  >"$work/wire.out" 2>"$work/wire.err" || { cat "$work/wire.err"; fail "view --wireframe"; }
if "$diff" "$work/wire.png" "$work/render10.png" 1 >/dev/null; then
  fail "--wireframe: the frame looks shaded"
fi
echo "ok: --wireframe draws lines"

# The trim-atlas overlay: one page of the atlas in the upper right corner (a 180 x 180 box of
# 640 x 360: 14 % of the pixels); the frame outside it is the render's. Motor-c has trimmed faces,
# so the page is not empty: the overlay changes more than 1 % of the pixels.
xvfb-run -a -s "-screen 0 1280x1024x24" "$sw" view "$model" --size 640x360 --no-static-lod \
  --script "$work/orbit.path" --frames 10 --settle --atlas-overlay --screenshot "$work/atlas.png" \
  >"$work/atlas.out" 2>"$work/atlas.err" || { cat "$work/atlas.err"; fail "view --atlas-overlay"; }
if "$diff" "$work/atlas.png" "$work/render10.png" 1 >/dev/null; then
  fail "--atlas-overlay: no atlas page drawn"
fi
"$diff" "$work/atlas.png" "$work/render10.png" 15 || fail "--atlas-overlay changed more than its corner"
echo "ok: the trim-atlas overlay shows a page in its corner only"

"$sw" import "$model" -o "$work/model.sws" >/dev/null 2>&1
xvfb-run -a -s "-screen 0 1280x1024x24" "$embed" "$work/model.sws" 30 >"$work/embed.out" 2>&1 ||
  { cat "$work/embed.out"; fail "embed_minimal"; }
grep -q "^embed_minimal: 30 frames" "$work/embed.out" || fail "embed_minimal: $(cat "$work/embed.out")"
echo "ok: $(cat "$work/embed.out")"

"$sw" path orbit "$static_model" -o "$work/static.path" >/dev/null 2>&1
xvfb-run -a -s "-screen 0 1280x1024x24" "$sw" view "$static_model" --size 640x360 \
  --script "$work/static.path" --frames 10 --settle --lod-colors \
  --screenshot "$work/lod.png" >"$work/lod.out" 2>"$work/lod.err" ||
  { cat "$work/lod.err"; fail "view --lod-colors (static LODs by default)"; }
cam=$(sed -n 's/^screenshot camera //p' "$work/lod.out")
"$sw" render "$static_model" -o "$work/lod_render.png" --size 640x360 --camera "$cam" \
  --static-lod --lod-colors >/dev/null 2>&1
"$diff" "$work/lod.png" "$work/lod_render.png" 0.1 || fail "--static-lod --lod-colors differs from render"
"$sw" render "$static_model" -o "$work/plain.png" --size 640x360 --camera "$cam" >/dev/null 2>&1
if "$diff" "$work/lod.png" "$work/plain.png" 1 >/dev/null; then
  fail "--lod-colors: the frame shows no LOD colours"
fi
echo "ok: static LODs by default with --lod-colors equal render --static-lod of its camera, coloured by representation"

# --no-static-lod: the viewer draws every face by the per-frame path, as render without a LOD cache
xvfb-run -a -s "-screen 0 1280x1024x24" "$sw" view "$static_model" --size 640x360 \
  --script "$work/static.path" --frames 10 --settle --no-static-lod --lod-colors \
  --screenshot "$work/nolod.png" >"$work/nolod.out" 2>"$work/nolod.err" ||
  { cat "$work/nolod.err"; fail "view --no-static-lod"; }
cam=$(sed -n 's/^screenshot camera //p' "$work/nolod.out")
"$sw" render "$static_model" -o "$work/nolod_render.png" --size 640x360 --camera "$cam" \
  --lod-colors >/dev/null 2>&1
"$diff" "$work/nolod.png" "$work/nolod_render.png" 0.1 || fail "--no-static-lod differs from render"
echo "ok: --no-static-lod equals render of its camera without static LODs"

# One pipeline for the viewer and `profile`: the same scripted path, converged, recorded by
# `view --profile` and by `profile`, gives the same columns and, frame by frame, the same
# counters (faces, patches, hierarchy nodes, triangles, fat borders and the samples kept for them,
# trim textures and those kept, occlusion tests...). Times differ, and so do the pool's own
# columns and the pool waits (when a build ends is the scheduler's). A viewer that set up its frames
# differently (planted: occlusion culling off in view's frame) fails here on occlusion_tests.
"$sw" profile "$model" --path "$work/orbit.path" --frames 12 --size 320x180 --converged \
  --no-static-lod --out "$work/prof" >"$work/prof.out" 2>&1 || { cat "$work/prof.out"; fail "profile"; }
xvfb-run -a -s "-screen 0 1280x1024x24" "$sw" view "$model" --size 320x180 --no-static-lod \
  --script "$work/orbit.path" --frames 12 --converged --profile "$work/vprof" \
  >"$work/vprof.out" 2>"$work/vprof.err" || { cat "$work/vprof.err"; fail "view --profile"; }
grep -q "^wrote $work/vprof/profile.csv" "$work/vprof.out" || fail "view --profile: $(cat "$work/vprof.out")"
for f in profile.json frametime.svg report.html; do
  [ -s "$work/vprof/$f" ] || fail "view --profile: no $f"
done
[ "$(head -1 "$work/prof/profile.csv")" = "$(head -1 "$work/vprof/profile.csv")" ] ||
  fail "view --profile: other columns than profile's"
counters() {
  awk -F, 'NR == 1 { for (i = 1; i <= NF; i++)
                       if ($i !~ /(_ms|_s|^pool_.*|^resident_bytes|^captured)$/) keep[i] = 1 }
           { line = ""; for (i = 1; i <= NF; i++) if (i in keep) line = line $i ","; print line }' "$1"
}
counters "$work/prof/profile.csv" >"$work/prof_counts.csv"
counters "$work/vprof/profile.csv" >"$work/view_counts.csv"
[ "$(wc -l <"$work/view_counts.csv")" -eq 13 ] || fail "view --profile: not 12 frames"
diff "$work/prof_counts.csv" "$work/view_counts.csv" >"$work/counts.diff" ||
  { cat "$work/counts.diff"; fail "view --profile: counters differ from profile's on the same path"; }
echo "ok: view --profile and profile on the same path: the same columns, $(head -1 "$work/view_counts.csv" | tr , '\n' | grep -c .) counters equal on 12 frames"
