#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs the Debian 12 packages splinewalk builds, tests and demos with (PLATFORM.md).
# As root: installs what is missing. Otherwise: prints the one apt-get line to run and fails.
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libglfw3-dev libosd-dev libopenmesh-dev libopenimageio-dev openimageio-tools
  libstb-dev  # the core's PNG writer (stb_image_write.h, compiled in)
  libegl-dev libgl-dev libopengl-dev libgles-dev libegl-mesa0 libgl1-mesa-dri libgbm-dev
  libglu1-mesa-dev
  libocct-data-exchange-dev libocct-modeling-algorithms-dev libocct-modeling-data-dev
  libocct-foundation-dev libtbb-dev occt-misc libcgal-dev
  xvfb xauth libcmocka-dev
  libxml2-utils jq  # tests/profile: xmllint checks the SVG and HTML, jq the JSON
  strace  # tests/io: kills a writer at its fsync and rename (signal injection)
  libgeos-dev  # bench/triangulate: GEOS's polygon CDT against CGAL's (docs/licensing.md)
  libfreetype-dev fonts-dejavu-core  # the text module: label glyphs (DejaVu Sans by default)
)
if [ "${SW_WITH_CLANG:-0}" = 1 ]; then
  packages+=(clang libclang-rt-14-dev)
fi

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [ "$status" = "install ok installed" ] || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

line="apt-get update && apt-get install -y --no-install-recommends ${missing[*]}"
if [ "$(id -u)" -ne 0 ]; then
  echo "splinewalk: missing Debian packages. Run as root:" >&2
  echo "  $line" >&2
  exit 1
fi
echo "splinewalk: installing ${#missing[@]} Debian package(s): ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
apt-get update -q
apt-get install -y -q --no-install-recommends "${missing[@]}"
