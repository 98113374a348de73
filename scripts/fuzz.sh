#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ (clang, ASan, UBSan) in build-asan, the build of
# `scripts/quickstart.sh sanitize` (so after it nothing is compiled again), replays their seeds
# and the fixed crash inputs of fuzz/regressions, then fuzzes each target for a fixed time.
# Fails on any crash, hang (an input running longer than FEMTO_FUZZ_TIMEOUT seconds), memory
# blow-up (RSS above 2.5 GB) or sanitizer report; the input that caused it is kept in
# build-asan/fuzz/artifacts/TARGET/ (docs/RELIABILITY.md, "Fuzzing").
#   scripts/fuzz.sh                 # 30 s per target
#   scripts/fuzz.sh 3600            # an hour per target
#   FEMTO_FUZZ_TARGETS=vdb scripts/fuzz.sh 600
# Environment: FEMTO_FUZZ_BUILD_DIR (build-asan), FEMTO_FUZZ_TARGETS ("scene vdb flags"),
# FEMTO_FUZZ_TIMEOUT (10), FEMTO_JOBS (nproc), FEMTO_FUZZ_RUNS (stop each target after this many
# inputs instead of the time budget).
set -euo pipefail

seconds="${1:-30}"
case "$seconds" in
  ''|*[!0-9]*) echo "usage: $0 [SECONDS_PER_TARGET]" >&2; exit 2 ;;
esac
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${FEMTO_FUZZ_BUILD_DIR:-$root/build-asan}"
targets="${FEMTO_FUZZ_TARGETS:-scene vdb flags}"
timeout="${FEMTO_FUZZ_TIMEOUT:-10}"
jobs="${FEMTO_JOBS:-$(nproc 2>/dev/null || echo 2)}"

"$root/scripts/quickstart.sh" deps  # cmake, the libraries, clang and its runtimes when missing

# The configuration of `scripts/quickstart.sh sanitize` (keep the two the same).
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
      -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1" -DFEMTO_SANITIZE=ON -DFEMTO_FUZZ=ON -DFEMTO_UNITY=ON \
      -DFEMTO_BUILD_BENCH=OFF >/dev/null
cmake --build "$build" -j "$jobs" --target femto-fuzz

# A corrupt .vdb may ask OpenVDB for any amount of memory. Allocations above 2 GiB fail (new
# throws std::bad_alloc, as on a machine without that memory) instead of ASan aborting: femto
# must turn that into bad input. Memory actually used is bounded by -rss_limit_mb.
export ASAN_OPTIONS="allocator_may_return_null=1:max_allocation_size_mb=2048:detect_leaks=1:check_initialization_order=1:strict_string_checks=1"
export LSAN_OPTIONS="suppressions=$root/sanitizer/lsan-suppressions.txt"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
for s in /usr/lib/llvm-14/bin/llvm-symbolizer "$(command -v llvm-symbolizer || true)"; do
  if [ -n "$s" ] && [ -x "$s" ]; then export ASAN_SYMBOLIZER_PATH="$s"; break; fi
done

seeds_of() {
  case "$1" in
    scene) echo "$root/data/scenes $root/fuzz/seeds/scene" ;;
    vdb) echo "$build/fuzz/seeds/vdb" ;;
    flags) echo "$root/fuzz/seeds/flags" ;;
  esac
}

status=0
summary=()
for t in $targets; do
  bin="$build/fuzz/femto-fuzz-$t"
  [ -x "$bin" ] || { echo "fuzz.sh: unknown target '$t'" >&2; exit 2; }
  corpus="$build/fuzz/corpus/$t"
  artifacts="$build/fuzz/artifacts/$t"
  log="$build/fuzz/$t.log"
  mkdir -p "$corpus" "$artifacts"
  dict=()
  [ -f "$root/fuzz/$t.dict" ] && dict=(-dict="$root/fuzz/$t.dict")
  # shellcheck disable=SC2046
  seeds=($(seeds_of "$t"))

  echo "== femto-fuzz-$t: replaying the seeds and fuzz/regressions/$t"
  if ! "$bin" -runs=0 -timeout="$timeout" -rss_limit_mb=2560 "${seeds[@]}" "$root/fuzz/regressions/$t" \
       >"$log.replay" 2>&1; then
    tail -n 60 "$log.replay"
    echo "fuzz.sh: $t: a seed or regression input fails (log: $log.replay)" >&2
    status=1
    summary+=("$t: FAILED on the seeds or regression inputs")
    continue
  fi

  budget=(-max_total_time="$seconds")
  [ -n "${FEMTO_FUZZ_RUNS:-}" ] && budget=(-runs="$FEMTO_FUZZ_RUNS")
  echo "== femto-fuzz-$t: fuzzing (${budget[*]}, -timeout=$timeout)"
  start=$(date +%s)
  set +e
  "$bin" "${budget[@]}" -timeout="$timeout" -rss_limit_mb=2560 -print_final_stats=1 \
         -artifact_prefix="$artifacts/" "${dict[@]}" "$corpus" "${seeds[@]}" >"$log" 2>&1
  rc=$?
  set -e
  elapsed=$(( $(date +%s) - start ))
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1 || true)
  cov=$(grep -E '^#[0-9]+' "$log" | tail -n 1 | sed -n 's/.*\(cov: [0-9]*\).*/\1/p' || true)
  if [ "$rc" -ne 0 ]; then
    grep -E -A 40 'ERROR: |runtime error|SUMMARY|deadly signal|Test unit written' "$log" | head -n 80 || tail -n 60 "$log"
    echo "fuzz.sh: $t: FAILED (exit $rc); log $log, inputs in $artifacts" >&2
    status=1
    summary+=("$t: FAILED after ${execs:-?} inputs in ${elapsed} s")
  else
    summary+=("$t: ${execs:-?} inputs in ${elapsed} s, ${cov:-cov ?}, no findings")
  fi
done

echo "== fuzz summary"
printf '  %s\n' "${summary[@]}"
exit "$status"
