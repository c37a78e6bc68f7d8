#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The malformed corpus: every file a user could feed splinewalk broken, each refused with its own
# error id, exit status 1, the file named, within 30 s, nothing written, no crash (run under ASan
# and UBSan in CI). What it catches: a reader that accepts a broken file (exit 0), crashes (exit
# >= 128), hangs (the 30 s limit), or reports the wrong class of error (the id).
#   test_malformed.sh SPLINEWALK MAKE_BAD_SWS DATA WORK
# - files/ (committed, listed in manifest.txt with their ids): camera paths (read by `profile`
#   before its scene), T-spline .tsm files, small STEP / IGES / BREP texts, text named .sws;
# - made here from a real scene (DATA/occ/Pump_Nut.brep imported): .sws files corrupted in their
#   header, section table, layout, checksums and geometry (make_bad_sws), and cut at 0, 10, 63,
#   100 bytes, half and one byte short; real BREP and STEP files cut in half;
# - inputs that are not regular files: a directory, a FIFO (must not block) and a device named
#   .sws.
set -u
sw=$1 make_bad=$2 data=$3 work=$4
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
failures=0 checked=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# check FILE ID: the command reading FILE fails as described above.
check() {
  local file=$1 id=$2 out="out-$checked" rc
  checked=$((checked + 1))
  if [[ $file == *.path ]]; then
    timeout 30 "$sw" profile no-scene.sws --path "$file" --out "$out" >o.txt 2>e.txt; rc=$?
  else
    timeout 30 "$sw" info "$file" >o.txt 2>e.txt; rc=$?
  fi
  local name=${file##*/}
  if [ $rc -ne 1 ]; then fail "$name: exit status $rc, expected 1: $(head -c 300 e.txt)"; return; fi
  grep -q -- "($id)" e.txt || { fail "$name: expected $id: $(head -c 300 e.txt)"; return; }
  grep -qF -- "$name" e.txt || fail "$name: the message does not name the file: $(head -c 300 e.txt)"
  [ ! -e "$out" ] || fail "$name: output written"
}

# ---- the committed corpus --------------------------------------------------------------------
while read -r name id _; do
  [[ -z $name || $name == \#* ]] && continue
  check "$here/files/$name" "$id"
done <"$here/manifest.txt"

# ---- .sws files corrupted from a real scene ---------------------------------------------------
"$sw" import "$data/occ/Pump_Nut.brep" -o nut.sws >/dev/null 2>&1 || { fail "import Pump_Nut"; exit 1; }
while read -r corruption id; do
  "$make_bad" nut.sws "sws-$corruption.sws" "$corruption" || { fail "make_bad_sws $corruption"; continue; }
  check "sws-$corruption.sws" "$id"
done <<'LIST'
version-2 SW_ERR_VERSION
bad-magic SW_ERR_FORMAT
flags SW_ERR_FORMAT
reserved SW_ERR_FORMAT
section-count-7 SW_ERR_FORMAT
section-count-13 SW_ERR_FORMAT
table-misaligned SW_ERR_FORMAT
table-in-header SW_ERR_FORMAT
entry-size-48 SW_ERR_FORMAT
size-field-long SW_ERR_TRUNCATED
size-field-short SW_ERR_FORMAT
section-overlap SW_ERR_FORMAT
section-past-end SW_ERR_FORMAT
section-misaligned SW_ERR_FORMAT
count-mismatch SW_ERR_FORMAT
duplicate-id SW_ERR_FORMAT
padding SW_ERR_FORMAT
trailing SW_ERR_FORMAT
decreasing-knots SW_ERR_INVALID_GEOMETRY
nan-weight SW_ERR_INVALID_GEOMETRY
loop-index SW_ERR_FORMAT
header-crc SW_ERR_CHECKSUM
section-crc SW_ERR_CHECKSUM
LIST
size=$(stat -c %s nut.sws)
for n in 0 10 63 100 $((size / 2)) $((size - 1)); do
  head -c "$n" nut.sws >"sws-cut-$n.sws"
  check "sws-cut-$n.sws" SW_ERR_TRUNCATED
done

# ---- real CAD files cut in half -----------------------------------------------------------------
head -c "$(($(stat -c %s "$data/occ/Pump_Nut.brep") / 2))" "$data/occ/Pump_Nut.brep" >cut-nut.brep
check cut-nut.brep SW_ERR_FORMAT # OCCT's BREP reader does not tell a cut file from a bad one
step=$(ls "$data"/step/*.stp "$data"/step/*.step 2>/dev/null | head -1)
head -c "$(($(stat -c %s "$step") / 2))" "$step" >cut-step.step
check cut-step.step SW_ERR_FORMAT # nor its STEP reader ("unexpected end of file" in its log)

# ---- not regular files ------------------------------------------------------------------------
mkdir dir.sws && check dir.sws SW_ERR_NOT_REGULAR_FILE
mkfifo fifo.sws && check fifo.sws SW_ERR_NOT_REGULAR_FILE
ln -s /dev/zero zero.sws && check zero.sws SW_ERR_NOT_REGULAR_FILE

[ $failures -eq 0 ] && echo "ok: $checked malformed inputs refused, each with its id" ||
  echo "$failures of $checked failed"
exit $((failures > 0))
