#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The bundle (scripts/bundle) against the full build, with the bundle moved elsewhere and run in
# a scrubbed environment (env -i: no LD_LIBRARY_PATH, no EGL_PLATFORM, nothing of the build's):
# - size under 32 MiB; highest GLIBC_ symbol of its programs and libraries <= 2.36;
# - every library its programs load resolves inside the moved bundle or to the system's libc,
#   libm, EGL/OpenGL dispatch or C++ runtime (an absolute RPATH to the build tree, or a library
#   left out, fails here);
# - the default scene rendered by the bundle (Mesa's surfaceless platform, then the EGL device
#   platform as on NVIDIA) is byte for byte the full build's frame, so 0 pixels differ;
# - `demo` renders the default scene the bundle ships: its four views are the full build's;
# - `generate building` from the bundle's .sws parts is byte for byte the full build's from
#   OCCT's files; build-lod (CGAL, OpenMesh from the bundle's lib/) and profile run;
# - a program compiled against the bundle's headers and core library draws a node scene.
# usage: test_bundle.sh BUNDLE FULL_BUILD WORKDIR SOURCE_DIR
set -euo pipefail
bundle=$(cd "$1" && pwd)
full=$(cd "$2" && pwd)
work=$3
src=$(cd "$4" && pwd)
rm -rf "$work" && mkdir -p "$work"
work=$(cd "$work" && pwd)
fail() { echo "FAIL: $*" >&2; exit 1; }
system_libs='^(linux-vdso\.so\.1|ld-linux-x86-64\.so\.2|libc\.so\.6|libm\.so\.6|libpthread\.so\.0|libdl\.so\.2|librt\.so\.1|libEGL\.so\.1|libOpenGL\.so\.0|libGLdispatch\.so\.0|libstdc\+\+\.so\.6|libgcc_s\.so\.1)$'

# Moved: nothing may point back at where it was built.
cp -a "$bundle" "$work/moved"
b=$work/moved
scrubbed() { (cd "$work" && env -i PATH=/usr/bin:/bin HOME="$work" "$@"); }

bytes=$(du -sb "$b" | cut -f1)
[ "$bytes" -lt $((32 * 1024 * 1024)) ] || fail "bundle is $bytes bytes"
echo "size: $bytes bytes"

glibc=$(for f in "$b"/bin/splinewalk "$b"/lib/*.so*; do [ -L "$f" ] || objdump -T "$f"; done |
        grep -o 'GLIBC_[0-9.]*' | sed 's/GLIBC_//' | sort -uV | tail -1)
[ "$(printf '%s\n2.36\n' "$glibc" | sort -V | tail -1)" = 2.36 ] || fail "GLIBC_$glibc > 2.36"
echo "highest GLIBC_: $glibc"

for elf in "$b"/bin/splinewalk "$b"/lib/*.so*; do
  [ -L "$elf" ] && continue
  while read -r name arrow path rest; do
    [ "$arrow" = "=>" ] || { path=$name; name=$(basename "$name"); }
    [ "$path" = "not" ] && fail "$elf: $name not found"
    [[ $name =~ $system_libs ]] && continue
    path=$(realpath -m "$path")
    case "$path" in
      "$b"/lib/*) ;;
      *) fail "$elf: $name resolves to $path, outside the bundle and not a system library" ;;
    esac
  done < <(scrubbed ldd "$elf" | sed 's/^[[:space:]]*//; s/ (0x[0-9a-f]*)$//')
done
echo "libraries: inside the bundle or the system's"

# The default scene: the bundle's frames against the full build's.
scene=$b/share/splinewalk/default.sws
"$full/bin/splinewalk" render "$scene" -o "$work/full.png" --view iso >/dev/null
scrubbed "$b/bin/splinewalk" render "$scene" -o "$work/bundle.png" --view iso >/dev/null
cmp "$work/full.png" "$work/bundle.png" || fail "the bundle's frame differs from the full build's"
scrubbed SW_EGL_PLATFORM=device "$b/bin/splinewalk" render "$scene" -o "$work/device.png" \
    --view iso | grep -q "EGL device platform" || fail "not drawn through the EGL device platform"
cmp "$work/full.png" "$work/device.png" || fail "the EGL device platform's frame differs"
echo "default scene: the bundle's frames (surfaceless, device) = the full build's"

# `demo`: the bundle renders the copy it ships; its four views = the full build's `make demo`.
"$full/bin/splinewalk" demo -o "$work/demo_full" --size 320x180 >/dev/null 2>&1 ||
  fail "the full build's demo"
scrubbed "$b/bin/splinewalk" demo -o "$work/demo_bundle" --size 320x180 >/dev/null ||
  fail "the bundle's demo"
for view in iso front top inside; do
  cmp "$work/demo_full/$view.png" "$work/demo_bundle/$view.png" || fail "demo's $view view differs"
done
echo "demo: the bundle's four views = the full build's"

# generate from the shipped parts = generate from OCCT's files.
"$full/bin/splinewalk" generate building --surfaces 10000 -o "$work/full_b.sws" >/dev/null
scrubbed "$b/bin/splinewalk" generate building --surfaces 10000 -o "$work/bundle_b.sws" >/dev/null
cmp "$work/full_b.sws" "$work/bundle_b.sws" || fail "generated buildings differ"
scrubbed "$b/bin/splinewalk" generate building --surfaces 400 -o "$work/small.sws" >/dev/null
scrubbed "$b/bin/splinewalk" build-lod "$work/small.sws" 2>/dev/null | tail -1 |
  grep -q "LOD cache [0-9.]* MiB" || fail "build-lod in the bundle"
scrubbed "$b/bin/splinewalk" info "$work/small.sws" | grep -q "LOD cache" ||
  fail "no LOD cache after build-lod"
scrubbed "$b/bin/splinewalk" path orbit "$scene" -o "$work/orbit.path" >/dev/null
scrubbed "$b/bin/splinewalk" profile "$scene" --path "$work/orbit.path" --out "$work/profile" \
    --frames 6 --size 320x180 >/dev/null
[ "$(($(wc -l <"$work/profile/profile.csv") - 1))" = 6 ] || fail "profile: not 6 frames"
echo "generate (= the full build's), build-lod, path, profile: run"

# Embedding the bundle's core.
cc -std=c11 -O1 "$src/samples/embed_nodes.c" -I"$b/include" -L"$b/lib" -lsplinewalk \
   -Wl,-rpath,"$b/lib" -lm -o "$work/embed_nodes"
scrubbed "$work/embed_nodes" >/dev/null || fail "embed_nodes against the bundle"
[ -s "$work/embed_nodes.png" ] || fail "embed_nodes wrote no frame"
echo "embed_nodes built against the bundle: drew its frame"
echo "PASS"
