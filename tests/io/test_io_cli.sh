#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The project's one writer and its guarded inputs through the CLI. Each
# check names the fault it catches:
# - `import -o /dev/null` succeeds and /dev/null stays a character device (a writer that renames
#   a temporary over any non-directory turns it into a regular file when run as root);
# - `path -o -` prints the path on standard output, `path -o FIFO` feeds a reader (a writer that
#   cannot write a stream);
# - `import -o LINK` writes the file the link names and leaves the link (a writer that replaces
#   the link);
# - `import -o DIR` is SW_ERR_NOT_REGULAR_FILE naming DIR;
# - a dead writer's NAME.tmp-PID is gone after the next write (temporaries that pile up);
# - `info FIFO` returns at once with SW_ERR_NOT_REGULAR_FILE (an open() that blocks for ever),
#   `import DIR.step` says "is a directory" (was "file not found"), `render -o frame` says the
#   name has no extension (was "unsupported image type '.'");
# - a writer killed (SIGKILL, SIGTERM; strace injects them at its fsync and its rename) leaves the
#   old file as it was, and no temporary outlives the next run (skipped without strace/ptrace).
# usage: test_io_cli.sh SPLINEWALK DATA_DIR WORKDIR
set -u
sw=$1 data=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
pass() { echo "ok:   $*"; }

# expect_error NAME ID TEXT -- CMD...: exit status 1 within 10 s, stderr holds ID and TEXT.
expect_error() {
  local name=$1 id=$2 text=$3; shift 4
  timeout 10 "$@" >out.txt 2>err.txt; local rc=$?
  if [ $rc -ne 1 ]; then fail "$name: exit status $rc, expected 1"; cat err.txt; return; fi
  grep -q -- "$id" err.txt || { fail "$name: stderr lacks $id"; cat err.txt; return; }
  grep -qF -- "$text" err.txt || { fail "$name: stderr lacks '$text'"; cat err.txt; return; }
  pass "$name: $(head -c 200 err.txt)"
}

model=$data/occ/wedge_ok.brep
"$sw" import "$model" -o m.sws >import.txt 2>&1 || { fail "import Motor-c"; cat import.txt; exit 1; }

# ---- targets ----------------------------------------------------------------------------------
"$sw" import "$model" -o /dev/null >out.txt 2>&1 || { fail "import -o /dev/null"; cat out.txt; }
[ -c /dev/null ] || fail "/dev/null is no longer a character device"
"$sw" path orbit m.sws -o - >stdout.path 2>stderr.txt || fail "path -o -"
head -1 stdout.path | grep -qx 'splinewalk-path 1' || fail "path -o -: no path on stdout"
grep -q 'orbit of m.sws' stderr.txt || fail "path -o -: the summary is not on stderr"
mkfifo fifo.path
cat fifo.path >from-fifo.path &
reader=$!
timeout 10 "$sw" path orbit m.sws -o fifo.path >/dev/null 2>&1 || fail "path -o FIFO"
wait $reader
cmp -s from-fifo.path stdout.path || fail "path -o FIFO: the reader got other bytes than -o -"
[ -p fifo.path ] || fail "the FIFO was replaced"
pass "/dev/null, - and a FIFO written in place"

# a link to real.sws, and a temporary of real.sws left by a writer that died
echo old >real.sws
ln -s real.sws link.sws
(exit 0) & dead=$!; wait $dead
echo partial >real.sws.tmp-$dead
"$sw" import "$model" -o link.sws >out.txt 2>&1 || { fail "import -o link.sws"; cat out.txt; }
[ -L link.sws ] || fail "import -o link.sws replaced the link"
cmp -s real.sws m.sws || fail "import -o link.sws did not write the file the link names"
[ -e real.sws.tmp-$dead ] && fail "a dead writer's real.sws.tmp-$dead was left"
ls ./*.tmp-* >/dev/null 2>&1 && fail "temporaries left: $(ls ./*.tmp-*)"
mkdir out.sws
expect_error "import -o DIR" SW_ERR_NOT_REGULAR_FILE "out.sws: is a directory" -- \
  "$sw" import "$model" -o out.sws
expect_error "import -o NODIR/x.sws" SW_ERR_NOT_FOUND "does not exist" -- \
  "$sw" import "$model" -o no-such-dir/x.sws
pass "a symbolic link written through, a directory refused, a stale temporary removed"

# ---- killed writers: strace delivers the signal at the writer's fsync or rename -----------------
# (catches: a kill that leaves a partial target, or a temporary that no later run removes)
if strace -f -o /dev/null true 2>/dev/null; then
  cp m.sws keep.sws
  cp stdout.path keep.path
  (strace -f -o /dev/null -e trace=fsync -e inject=fsync:signal=KILL:when=1 \
    "$sw" import "$model" -o keep.sws) >/dev/null 2>&1
  cmp -s keep.sws m.sws || fail "kill -9 at the fsync of import: keep.sws changed"
  (strace -f -o /dev/null -e trace=fsync -e inject=fsync:signal=TERM:when=1 \
    "$sw" path fly m.sws -o keep.path) >/dev/null 2>&1
  cmp -s keep.path stdout.path || fail "SIGTERM at the fsync of path: keep.path changed"
  (strace -f -o /dev/null -e trace=rename -e inject=rename:signal=KILL \
    "$sw" path fly m.sws -o keep.path) >/dev/null 2>&1
  cmp -s keep.path stdout.path || fail "kill -9 at the rename of path: keep.path changed"
  ls keep.path.tmp-* >/dev/null 2>&1 || echo "note: kill -9 at the rename left no temporary"
  "$sw" path orbit m.sws -o keep.path >/dev/null 2>&1 || fail "path after a killed one"
  ls ./*.tmp-* >/dev/null 2>&1 && fail "a killed writer's temporary outlived the next run: $(ls ./*.tmp-*)"
  pass "killed writers (SIGKILL, SIGTERM at fsync and rename): old files kept, temporaries gone"
else
  echo "skip: killed writers (strace missing or ptrace not permitted)"
fi

# ---- inputs -----------------------------------------------------------------------------------
mkfifo fifo.sws
expect_error "info FIFO" SW_ERR_NOT_REGULAR_FILE "FIFO" -- "$sw" info fifo.sws
mkdir dir.step
expect_error "import DIR.step" SW_ERR_NOT_REGULAR_FILE "is a directory" -- \
  "$sw" import dir.step -o x.sws
ln -s /dev/zero zero.sws
expect_error "info /dev/zero as .sws" SW_ERR_NOT_REGULAR_FILE "character device" -- \
  "$sw" info zero.sws
expect_error "render -o frame" SW_ERR_UNSUPPORTED "no extension" -- \
  "$sw" render m.sws -o frame --size 32x24
[ -e x.sws ] && fail "a refused import created its output"

[ $failures -eq 0 ] && echo "all passed" || echo "$failures FAILED"
exit $((failures != 0))
