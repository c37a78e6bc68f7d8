#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# `splinewalk check-osd` on the sample models with uniform bicubic regions and on generated nets:
# every one reports regions > 0 and a difference to OpenSubdiv within 1e-10 (the command's exit
# status), and a deliberately tiny tolerance makes it fail (the check can fail).
# usage: test_check_osd.sh SPLINEWALK DATA_DIR
set -u
sw=$1 data=$2
out=$("$sw" check-osd "$data/occ/terrain.brep" "$data/occ/MAT.brep" "$data/occ/shell1.brep" \
      --generated 5 2>/dev/null) || { echo "FAIL: check-osd exit status"; echo "$out"; exit 1; }
echo "$out"
lines=$(echo "$out" | grep -c "regions on")
[ "$lines" -eq 4 ] || { echo "FAIL: expected 4 report lines, got $lines"; exit 1; }
if echo "$out" | grep -q ": 0 regions"; then echo "FAIL: a report with 0 regions"; exit 1; fi
"$sw" check-osd --generated 1 --tolerance 1e-30 >/dev/null 2>&1 &&
  { echo "FAIL: a 1e-30 tolerance passed: the comparison cannot fail"; exit 1; }
"$sw" check-osd --samples 0 >/dev/null 2>&1; [ $? -eq 2 ] || { echo "FAIL: --samples 0 accepted"; exit 1; }
echo "ok"
