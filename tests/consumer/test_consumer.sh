#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The consumer test: install splinewalk to a temporary prefix, build
# samples/embed_headless.c (and samples/embed_custom_shader.c, run once per build: the immediate
# API with a host shading function) against the installed package through find_package and through
# pkg-config (a copy of the sample, so nothing but the installed headers can be seen), run both
# headlessly, and compare their frames with `splinewalk render` of the same scene and camera:
# at most 0.1 % of pixels may differ. Negative controls prove the comparison sees a different
# camera (another preset, and the same camera with a 1 % narrower field of view).
# With SW_CONSUMER_FROM=debs the package comes from the Debian packages `cpack` builds (unpacked
# into a scratch root) instead of `cmake --install`, and their dependency fields are checked.
# usage: test_consumer.sh BUILD_DIR SOURCE_DIR PNG_DIFF DATA_DIR WORK_DIR [SANITIZE]
set -euo pipefail
build=$1 src=$2 png_diff=$3 data=$4 work=$5 sanitize=${6:-}
export EGL_PLATFORM=surfaceless

fail() { echo "FAIL: $*" >&2; exit 1; }
step() { echo "== $*"; }

rm -rf "$work"
mkdir -p "$work"
prefix=$work/prefix
flags=(-Wall -Wextra -Wpedantic -Werror -std=c11)
if [ -n "$sanitize" ]; then
  # An instrumented library needs an instrumented program (the sanitizer runtime comes first).
  flags+=("-fsanitize=$sanitize" -fno-omit-frame-pointer)
fi

if [ "${SW_CONSUMER_FROM:-install}" = debs ]; then
  # The Debian packages instead of `cmake --install`: built by cpack from the same build, unpacked
  # into a scratch root (no dpkg database touched), used from its /usr.
  step "build the Debian packages and unpack them into $work/root"
  (cd "$build" && cpack -B "$work/debs" >/dev/null) || fail "cpack failed"
  runtime=$(ls "$work"/debs/libsplinewalk[0-9]*_*.deb) dev=$(ls "$work"/debs/libsplinewalk-dev_*.deb)
  tools=$(ls "$work"/debs/splinewalk-tools_*.deb)
  modules=()
  for m in import image lodbuild; do
    modules+=("$(ls "$work"/debs/libsplinewalk-"$m"[0-9]*_*.deb)") || fail "no package of the $m module"
  done
  for deb in "$runtime" "$dev" "$tools" "${modules[@]}"; do
    dpkg-deb -x "$deb" "$work/root"
    echo "$(dpkg-deb -f "$deb" Package): $(dpkg-deb -f "$deb" Depends | cut -c1-160)"
  done
  version=$(dpkg-deb -f "$runtime" Version)
  for deb in "$dev" "${modules[@]}"; do
    dpkg-deb -f "$deb" Depends | grep -q "$(dpkg-deb -f "$runtime" Package) (= $version)" ||
      fail "$(dpkg-deb -f "$deb" Package) does not depend on its library's exact version"
  done
  for lib in libc6 libegl1 libopengl0; do
    dpkg-deb -f "$runtime" Depends | grep -q -w "$lib" || fail "the library's package does not depend on $lib"
  done
  # the core's package: libc, EGL and OpenGL only (dpkg-shlibdeps reads them off the binary)
  extra=$(dpkg-deb -f "$runtime" Depends | tr ',' '\n' | sed 's/^ *//; s/ .*//' |
          grep -v -x -E 'libc6|libegl1|libopengl0' || true)
  [ -z "$extra" ] || fail "the core's package depends on more than libc, EGL and OpenGL: $extra"
  dpkg-deb -c "$runtime" | awk '{print $6}' | grep -q -x './usr/lib/libsplinewalk.so' &&
    fail "the unversioned link name is in the runtime package, not in -dev"
  prefix=$work/root/usr
else
  step "install to $prefix"
  cmake --install "$build" --prefix "$prefix" >/dev/null
fi
for f in lib/libsplinewalk.so include/splinewalk/splinewalk.h include/splinewalk/sw_result.h \
         lib/cmake/splinewalk/splinewalkConfig.cmake lib/cmake/splinewalk/splinewalkConfigVersion.cmake \
         lib/pkgconfig/splinewalk.pc bin/splinewalk; do
  [ -e "$prefix/$f" ] || fail "$f not installed"
done
for m in import image lodbuild; do
  for f in lib/libsplinewalk_$m.so lib/pkgconfig/splinewalk-$m.pc; do
    [ -e "$prefix/$f" ] || fail "$f not installed"
  done
done
[ -e "$prefix/include/splinewalk/sw_import.h" ] && [ -e "$prefix/include/splinewalk/sw_image.h" ] &&
  [ -e "$prefix/include/splinewalk/sw_lod_build.h" ] || fail "a module's header is not installed"

step "the core is lean: libc, pthreads, EGL and OpenGL; no OCCT, OIIO, CGAL, OpenMesh or C++"
core=$prefix/lib/libsplinewalk.so
deps=$(ldd "$core")
echo "$deps"
if [ -z "$sanitize" ]; then # the sanitizers' runtimes bring libstdc++ and libgcc_s with them
  [ "$(echo "$deps" | wc -l)" -le 12 ] || fail "ldd of the core lists more than 12 lines"
  if grep -i -E 'TK[A-Z]|OpenImageIO|opencv|CGAL|gmp|OpenMesh|osd|stdc\+\+' <<<"$deps"; then
    fail "the core loads a library that belongs to a module"
  fi
fi
# no C++ symbol (mangled _Z...) and no third-party name, defined or needed
if nm -D "$core" | grep -E ' _Z|OpenImageIO|TopoDS|Standard_|CGAL|OpenMesh|OpenSubdiv'; then
  fail "the core holds or needs a module's symbols"
fi
echo "core: $(stat -L -c %s "$core") bytes"
for m in import image lodbuild; do
  lib=$prefix/lib/libsplinewalk_$m.so
  echo "module $m: $(stat -L -c %s "$lib") bytes, ldd $(ldd "$lib" | wc -l) lines"
  entry=$(nm -D --defined-only "$lib" | awk '$2 == "T" {print $3}')
  [ "$entry" = "sw_${m/lodbuild/lod_build}_install" ] || fail "libsplinewalk_$m exports '$entry'"
done

step "the library exports exactly the functions the installed headers declare"
# public: version SPLINEWALK_<major>; the modules' ABI: SPLINEWALK_PRIVATE_<version>
exported=$(nm -D --defined-only "$core" | awk '$2 ~ /^[TDBRVW]$/ {print $3}' |
           grep -v -E '^(_edata|_end|__bss_start)$' | grep -v '@@SPLINEWALK_PRIVATE_' |
           sed 's/@@SPLINEWALK_[0-9]*$//' | sort)
declared=$(grep -h -o -E '^SW_API [^(]*\(' "$prefix"/include/splinewalk/*.h |
           sed -E 's/.*[ *]([A-Za-z_0-9]+)\($/\1/' | sort)
[ -n "$declared" ] || fail "no SW_API declarations found"
diff <(echo "$exported") <(echo "$declared") || fail "exported symbols differ from the public API"
echo "$(echo "$exported" | wc -l) functions"
private=$(nm -D --defined-only "$core" | awk '$3 ~ /@@SPLINEWALK_PRIVATE_/ {print $3}' | sed 's/@@.*//')
if grep -v -E '^sw_|^sw__' <<<"$private"; then fail "a private export outside the sw_ names"; fi
if grep -x -F -f <(echo "$declared") <<<"$private"; then fail "a public function is also private"; fi
echo "$(echo "$private" | wc -l) functions for the modules (SPLINEWALK_PRIVATE)"

cp "$src/samples/embed_headless.c" "$work/embed_headless.c"
cp "$src/samples/embed_custom_shader.c" "$work/embed_custom_shader.c"

step "build through find_package(splinewalk)"
cmake -S "$src/tests/consumer/find_package" -B "$work/cmake-build" -DCMAKE_PREFIX_PATH="$prefix" \
      -DSW_SAMPLE="$work/embed_headless.c" -DSW_SAMPLE_GL="$work/embed_custom_shader.c" \
      -DCMAKE_BUILD_TYPE=Release \
      -DCMAKE_C_FLAGS="${flags[*]}" >/dev/null
cmake --build "$work/cmake-build" >/dev/null
bin_cmake=$work/cmake-build/embed_headless

step "build through pkg-config"
export PKG_CONFIG_LIBDIR=$prefix/lib/pkgconfig   # this prefix only, never a system copy
libdir=$(pkg-config --variable=libdir splinewalk)
# shellcheck disable=SC2046  # pkg-config's output is a list of words
cc "${flags[@]}" "$work/embed_headless.c" $(pkg-config --cflags --libs splinewalk splinewalk-import) \
   -Wl,-rpath,"$libdir" -o "$work/embed_pc"
bin_pc=$work/embed_pc

step "build samples/embed_minimal.c (a GLFW host) through pkg-config"
cp "$src/samples/embed_minimal.c" "$work/embed_minimal.c"
# shellcheck disable=SC2046
cc "${flags[@]}" "$work/embed_minimal.c" $(pkg-config --cflags --libs splinewalk) \
   $(env -u PKG_CONFIG_LIBDIR pkg-config --cflags --libs glfw3) -lm -Wl,-rpath,"$libdir" \
   -o "$work/embed_minimal" || fail "embed_minimal does not build against the installed package"

step "build samples/embed_custom_shader.c (an EGL host with its own shading) through pkg-config"
# shellcheck disable=SC2046
cc "${flags[@]}" "$work/embed_custom_shader.c" $(pkg-config --cflags --libs splinewalk) \
   $(env -u PKG_CONFIG_LIBDIR pkg-config --cflags --libs egl opengl) -lm -Wl,-rpath,"$libdir" \
   -o "$work/embed_custom_shader" || fail "embed_custom_shader does not build against the installed package"
"$work/embed_custom_shader" "$work/custom_shader.png" > "$work/custom_shader.log" ||
  fail "embed_custom_shader: $(cat "$work/custom_shader.log")"
[ -s "$work/custom_shader.png" ] || fail "embed_custom_shader wrote no PNG"
"$work/cmake-build/embed_custom_shader" "$work/custom_shader_cmake.png" > "$work/custom_shader_cmake.log" ||
  fail "embed_custom_shader (find_package build): $(cat "$work/custom_shader_cmake.log")"
"$png_diff" "$work/custom_shader.png" "$work/custom_shader_cmake.png" 0.1 ||
  fail "the two builds of embed_custom_shader draw different frames"

for b in "$bin_cmake" "$bin_pc"; do
  deps=$(ldd "$b")
  grep -q "libsplinewalk.so.0 => $prefix/" <<<"$deps" ||
    fail "$b does not load the installed libsplinewalk: $(grep splinewalk <<<"$deps")"
done

step "help and usage"
help=$("$bin_pc" --help)
grep -q "usage: embed_headless" <<<"$help" || fail "--help"
set +e
"$bin_pc" --size 0x7 >/dev/null 2>&1; rc_usage=$?
"$bin_pc" "$work/missing.sws" -o "$work/x.png" >/dev/null 2>&1; rc_missing=$?
set -e
[ $rc_usage -eq 2 ] || fail "bad --size: exit $rc_usage, expected 2"
[ $rc_missing -eq 1 ] || fail "missing scene: exit $rc_missing, expected 1"

cli=$prefix/bin/splinewalk
size=640x480
step "Motor-c: both builds against splinewalk render --view iso at $size"
"$cli" import "$data/occ/Motor-c.brep" -o "$work/motor.sws" >/dev/null 2>&1
"$bin_cmake" "$work/motor.sws" -o "$work/motor_cmake.png" --size $size > "$work/motor_cmake.log"
"$bin_pc" "$work/motor.sws" -o "$work/motor_pc.png" --size $size > "$work/motor_pc.log"
"$cli" render "$work/motor.sws" -o "$work/motor_ref.png" --size $size --view iso >/dev/null
"$png_diff" "$work/motor_ref.png" "$work/motor_cmake.png" 0.1 || fail "find_package build differs"
"$png_diff" "$work/motor_ref.png" "$work/motor_pc.png" 0.1 || fail "pkg-config build differs"

step "the EGL device platform (EGL_EXT_device_enumeration, what NVIDIA offers without a display) on Mesa's software device"
grep -q "EGL surfaceless platform" "$work/motor_pc.log" || fail "the default run did not use the surfaceless platform"
SW_EGL_PLATFORM=device "$bin_pc" "$work/motor.sws" -o "$work/motor_device.png" --size $size \
  > "$work/motor_device.log" || fail "no frame through the EGL device platform"
grep "^GL:" "$work/motor_device.log"
grep -q "EGL device platform" "$work/motor_device.log" || fail "SW_EGL_PLATFORM=device was not used"
"$png_diff" "$work/motor_pc.png" "$work/motor_device.png" 0 || fail "the device platform draws another frame"

step "negative controls: another camera must be seen as different"
expect_different() {
  set +e
  "$png_diff" "$1" "$2" 0.1; local rc=$?
  set -e
  [ $rc -eq 1 ] || fail "$2 was not reported as different (exit $rc)"
}
"$cli" render "$work/motor.sws" -o "$work/motor_front.png" --size $size --view front >/dev/null
expect_different "$work/motor_cmake.png" "$work/motor_front.png"
# The sample prints its camera in --camera syntax: the same eye, target and up with a field of
# view 1 % narrower (40° -> 39.6°) zooms the frame by 1 %.
camera=$(sed -n 's/^camera: //p' "$work/motor_cmake.log")
[ -n "$camera" ] || fail "the sample printed no camera"
"$cli" render "$work/motor.sws" -o "$work/motor_same_camera.png" --size $size --camera "$camera" >/dev/null
"$png_diff" "$work/motor_ref.png" "$work/motor_same_camera.png" 0.1 || fail "printed camera differs"
zoomed=$(echo "$camera" | awk -F, -v OFS=, '{$10 = $10 * 0.99; print}')
"$cli" render "$work/motor.sws" -o "$work/motor_zoom.png" --size $size --camera "$zoomed" >/dev/null
expect_different "$work/motor_cmake.png" "$work/motor_zoom.png"

size=640x360
step "the built-in default scene (no SCENE argument) against render of demo's default.sws at $size"
"$cli" demo -o "$work/demo" --size $size >/dev/null 2>&1
"$bin_pc" -o "$work/default_pc.png" --size $size > "$work/default_pc.log" 2>/dev/null
"$cli" render "$work/demo/default.sws" -o "$work/default_ref.png" --size $size --view iso >/dev/null
"$png_diff" "$work/default_ref.png" "$work/default_pc.png" 0.1 || fail "default scene differs"
echo "PASS"
