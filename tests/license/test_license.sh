#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The project's license is stated: LICENSE exists at the source root, and every library source
# file (*.c *.h *.cpp *.hpp *.glsl under threads/ scenegraph/ lod/ gpu/ runtime/ modules/) names its license
# with an SPDX-License-Identifier line among its first 3 lines. Lists every offending file.
# In a git checkout the files are git's (tracked, plus untracked ones not ignored); elsewhere find's.
# usage: test_license.sh SOURCE_DIR
set -u
root=${1:?usage: test_license.sh SOURCE_DIR}
cd "$root" || { echo "FAIL: no source directory $root"; exit 1; }
dirs="threads scenegraph lod gpu runtime modules"

# Prints the files among its arguments that lack the line in their first 3 lines (one awk for
# all of them; an empty file has no first line, so it is caught apart).
missing_spdx() {
  local f
  for f in "$@"; do [ -s "$f" ] || echo "$f"; done
  awk 'FNR == 1 { if (NR > 1 && !ok) print prev; ok = 0; prev = FILENAME }
       FNR <= 3 && /SPDX-License-Identifier:/ { ok = 1 }
       END { if (NR > 0 && !ok) print prev }' "$@"
}

# The check can fail: a file with the line too late and an empty one are caught, good ones pass.
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
printf '/* a header */\n#pragma once\n\n/* SPDX-License-Identifier: MIT */\n' >"$tmp/late.h"
printf '/* SPDX-License-Identifier: MIT */\n#pragma once\n' >"$tmp/good.h"
printf '#!/bin/sh\n# SPDX-License-Identifier: MIT\n' >"$tmp/good.sh"
: >"$tmp/empty.c"
self=$(missing_spdx "$tmp/good.h" "$tmp/late.h" "$tmp/empty.c" "$tmp/good.sh" | sort | tr '\n' ' ')
if [ "$self" != "$tmp/empty.c $tmp/late.h " ]; then
  echo "FAIL: the SPDX check itself is broken (flagged: $self)"; exit 1
fi

fail=0
if [ ! -f LICENSE ]; then echo "FAIL: LICENSE missing at $root"; fail=1; fi

if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  list=$(git ls-files --cached --others --exclude-standard -- $dirs)
else
  list=$(find $dirs -type f | sort)
fi
files=()
while IFS= read -r f; do
  case "$f" in *.c|*.h|*.cpp|*.hpp|*.glsl) ;; *) continue ;; esac
  [ -f "$f" ] && files+=("$f")   # skip files deleted in the work tree, not yet committed
done <<<"$list"
checked=${#files[@]}
if [ "$checked" -eq 0 ]; then echo "FAIL: no library source file found under $dirs"; exit 1; fi

bad=$(missing_spdx "${files[@]}" | sort)
if [ -n "$bad" ]; then
  echo "FAIL: no SPDX-License-Identifier line in the first 3 lines of:"
  echo "$bad" | sed 's/^/  /'
  echo "$(echo "$bad" | wc -l) of $checked library source files lack the line"
  fail=1
fi
[ "$fail" -eq 0 ] && echo "ok: LICENSE present, $checked library source files carry an SPDX line"
exit "$fail"
