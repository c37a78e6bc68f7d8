#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The project's license is stated: LICENSE exists at the source root, and every library source
# file (*.c *.h *.cpp *.hpp *.glsl under threads/ scenegraph/ lod/ gpu/ runtime/) names its license
# with an SPDX-License-Identifier line among its first 3 lines. Lists every offending file.
# In a git checkout the files are git's (tracked, plus untracked ones not ignored); elsewhere find's.
# usage: test_license.sh SOURCE_DIR
set -u
root=${1:?usage: test_license.sh SOURCE_DIR}
cd "$root" || { echo "FAIL: no source directory $root"; exit 1; }
dirs="threads scenegraph lod gpu runtime"

has_spdx() { head -n 3 -- "$1" | grep -q 'SPDX-License-Identifier:'; }

# The check can fail: a file without the line is caught, one with it passes.
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
printf '/* a header */\n#pragma once\n\n/* SPDX-License-Identifier: MIT */\n' >"$tmp/late.h"
printf '/* SPDX-License-Identifier: MIT */\n#pragma once\n' >"$tmp/good.h"
if has_spdx "$tmp/late.h" || ! has_spdx "$tmp/good.h"; then
  echo "FAIL: the SPDX check itself is broken"; exit 1
fi

fail=0
if [ ! -f LICENSE ]; then echo "FAIL: LICENSE missing at $root"; fail=1; fi

if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  list=$(git ls-files --cached --others --exclude-standard -- $dirs)
else
  list=$(find $dirs -type f | sort)
fi
checked=0 missing=0
while IFS= read -r f; do
  case "$f" in *.c|*.h|*.cpp|*.hpp|*.glsl) ;; *) continue ;; esac
  [ -f "$f" ] || continue   # deleted in the work tree, not yet committed
  checked=$((checked + 1))
  if ! has_spdx "$f"; then
    [ "$missing" -eq 0 ] && echo "FAIL: no SPDX-License-Identifier line in the first 3 lines of:"
    echo "  $f"
    missing=$((missing + 1))
  fi
done <<<"$list"

if [ "$checked" -eq 0 ]; then echo "FAIL: no library source file found under $dirs"; exit 1; fi
if [ "$missing" -gt 0 ]; then echo "$missing of $checked library source files lack the line"; fail=1; fi
[ "$fail" -eq 0 ] && echo "ok: LICENSE present, $checked library source files carry an SPDX line"
exit "$fail"
