#!/usr/bin/env bash
# Runs femto as one process and as 2 MPI ranks (1 thread each) and checks that every output file
# is byte-identical (render.json/summary.json: everything but the command, date, threads and
# timing). Also: a rank that fails alone ends the job with its message and exit code, and
# leaves no output folder (docs/mpi.md).
# Catches: a split that changes the sums' order (tiles, light chunks, photon passes, tissue
# chunks, diffusion batches), counters counted twice or lost, a rank writing outputs, a failing
# rank that hangs the job or exits 0, options and commands that cannot run across ranks accepted.
# Usage: compare_ranks.sh FEMTO MPIEXEC SOURCE_DIR WORK_DIR CASE
set -u
femto=$1 mpiexec=$2 src=$3 work=$4 case=$5
# CI runs as root in a container: allow root, more ranks than cores, no kernel single copy.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_rmaps_base_oversubscribe=1 OMPI_MCA_btl_vader_single_copy_mechanism=none
mpi2() { "$mpiexec" -n 2 "$@"; }
fail() { echo "FAIL: $*"; exit 1; }
dir="$work/$case"
rm -rf "$dir" && mkdir -p "$dir" && cd "$dir" || exit 1

# Runs the arguments both ways and compares the output folders.
compare() {
  "$femto" "$@" --threads 2 --out one --quiet || fail "single process: $*"
  mpi2 "$femto" "$@" --threads 1 --out two --quiet || fail "2 ranks: $*"
  local n=0
  while IFS= read -r f; do
    n=$((n + 1))
    [ -f "two/$f" ] || fail "2 ranks did not write $f"
    case "$f" in
      render.json | summary.json)
        python3 - "one/$f" "two/$f" <<'PY' || fail "$f: results differ (beyond the run's command, date, threads and timing)"
import json, sys
run_keys = {"command", "date_utc", "timing", "threads", "threads_requested", "mpi_ranks", "memory",
            "memory_bytes_estimate", "seconds", "photons_per_second", "trace_seconds"}
def strip(v):
    if isinstance(v, dict):
        return {k: strip(x) for k, x in v.items() if k not in run_keys}
    if isinstance(v, list):
        return [strip(x) for x in v]
    return v
a, b = (strip(json.load(open(p))) for p in sys.argv[1:3])
if a != b:
    for k in sorted(set(a) | set(b)):
        if a.get(k) != b.get(k):
            print("differs:", k, str(a.get(k))[:300], "|", str(b.get(k))[:300])
    sys.exit(1)
PY
        ;;
      *) cmp -s "one/$f" "two/$f" || fail "$f differs between 1 process and 2 ranks" ;;
    esac
  done < <(cd one && find . -type f | sed 's|^\./||' | sort)
  [ "$n" -gt 2 ] || fail "too few outputs ($n)"
  [ "$(cd one && find . -type f | wc -l)" = "$(cd two && find . -type f | wc -l)" ] ||
    fail "different sets of files"
  echo "ok: $* ($n files identical)"
}

# Small copies of the example scenes (edited keys checked): the default scene at 100 x 72 pixels
# (bands of 16 rows, the last ones partial) and 48 bins; cube60 with 10 gates.
small() {  # FILE FROM [OLD NEW]...: literal replacements
  python3 - "$@" <<'PY' || fail "$2 changed: a key to edit is missing"
import sys
out, src, edits = sys.argv[1], sys.argv[2], sys.argv[3:]
text = open(src).read()
for old, new in zip(edits[::2], edits[1::2]):
    if old not in text:
        sys.exit(1)
    text = text.replace(old, new)
open(out, "w").write(text)
PY
}
scene=small.json
small $scene "$src/data/scenes/default.json" '"resolution": [256, 192]' '"resolution": [100, 72]' \
  '"bin_width": 25, "bins": 128' '"bin_width": 67, "bins": 48'
case "$case" in
  path) compare render $scene --integrator path --spp 3 ;;
  kernel) compare render $scene --integrator path --spp 4 --reconstruction kernel --first-pass-spp 2 ;;
  light) compare render $scene --integrator light --light-paths 150000 ;;
  photons) compare render $scene --integrator photons --spp 3 --photons 20000 ;;
  beams) compare render $scene --integrator beams --spp 2 --photons 1000 ;;
  hybrid) compare render $scene --integrator hybrid --spp 2 --photons 2000 ;;
  tissue)
    small cube.json "$src/data/scenes/cube60.json" '"bin_width": 100, "bins": 50' '"bin_width": 500, "bins": 10'
    compare tissue cube.json --photons 5000
    # Standard errors on: the fluence is reduced after every batch.
    rm -rf one two
    small cube_err.json cube.json '"stderr": false' '"stderr": true'
    compare tissue cube_err.json --photons 5000 ;;
  diffusion) compare diffusion --photons 30000 ;;
  rank-fails)
    # Rank 1 alone cannot read its scene (as when a file is missing on one node).
    mpi2 sh -c 'if [ "$OMPI_COMM_WORLD_RANK" = 1 ]; then s=missing.json; else s=""; fi;
                exec "$0" render $s --spp 1 --out out' "$femto" > log 2>&1
    code=$?
    cat log
    [ "$code" = 2 ] || fail "exit code $code, expected 2"
    grep -q "femto: error on rank 1 of 2: .*missing.json" log || fail "rank 1's message not shown"
    [ ! -e out ] || fail "an output folder was written"
    echo "ok: rank failure ends the job with code 2"
    # What does not run across ranks is refused (exit 2, a message, nothing written).
    mpi2 "$femto" render $scene --spp 1 --checkpoint --out out > log 2>&1
    code=$?
    [ "$code" = 2 ] || fail "--checkpoint under mpirun: exit code $code, expected 2"
    grep -q -- "--checkpoint: not available under mpirun" log || { cat log; fail "no --checkpoint message"; }
    [ ! -e out ] || fail "--checkpoint under mpirun wrote an output folder"
    mpi2 "$femto" info $scene > log 2>&1
    code=$?
    [ "$code" = 2 ] || fail "femto info under mpirun: exit code $code, expected 2"
    grep -q "femto info does not run across MPI ranks" log || { cat log; fail "no message for info"; }
    echo "ok: --checkpoint and femto info are refused under mpirun" ;;
  *) fail "unknown case $case" ;;
esac
