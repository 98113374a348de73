#!/usr/bin/env bash
# femto's cube60 benchmark against the established tissue Monte Carlo codes on the same machine,
# interleaved round by round (docs/PERFORMANCE.md, "Against MMC and MCX-CL on the same host").
# The other codes are not part of femto: build them yourself (commands below) and pass their
# binaries. Each round runs femto-bench-tissue (1 and 2 threads) on the scene as shipped (with
# its face images and four detectors) and with --fluence-only (the classic tally the other codes
# compute here: the fluence volume and the absorbed fraction), then MMC and MCX-CL with 1 and
# 2 threads, all on 1e6 photons, and prints photons/ms as each program reports it (MMC and
# MCX-CL: their "speed" line, which leaves out setup, kernel compilation and output).
#
#   apt-get install pocl-opencl-icd ocl-icd-opencl-dev opencl-c-headers        # both use OpenCL
#   git clone https://github.com/fangq/mmc && (cd mmc/src && make ssemath)      # CPU, SSE+OpenMP
#   git clone https://github.com/fangq/mcxcl && (cd mcxcl/src && make)         # OpenCL on POCL
#   bench/reference/run.sh build/femto-bench-tissue mmc/bin/mmc mcxcl/bin/mcxcl [ROUNDS]
#
# Run from the source root. Pass "-" for a program to leave out.
set -eu
femto=$1 mmc=$2 mcxcl=$3 rounds=${4:-3}
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cp "$here/mmc_cube60.json" "$here/mcxcl_cube60.json" "$work/"
echo "CPU: $(lscpu | sed -n 's/^Model name: *//p'), $(nproc) cores; load $(cut -d' ' -f1-3 /proc/loadavg)"
strip() { sed 's/\x1b\[[0-9;]*m//g'; }
for r in $(seq "$rounds"); do
  # femto: the bench's 1- and 2-thread rows (photons/ms wall clock, the absorbed fraction).
  if [ "$femto" != - ]; then
    for tally in all fluence; do
      "$femto" "$root/data/scenes/cube60.json" 1e6 $([ $tally = fluence ] && echo --fluence-only) \
        > "$work/femto" 2>&1
      # Also its tracing-only rate (no allocation, reductions or results), the nearer match to
      # the other codes' "speed", which leaves out their setup and output.
      awk -v r="$r" -v k="$tally" 'NF == 9 && $1 ~ /^[12]$/ {t = $5; sub(/\(/, "", t)
        printf "round %s femto  threads %s  %7.1f photons/ms  absorbed %s  (tracing only %s; tallies: %s)\n", r, $1, $2, $9, t, k}' "$work/femto"
    done
  fi
  for t in 1 2; do
    if [ "$mmc" != - ]; then
      (cd "$work" && OMP_NUM_THREADS=$t "$mmc" -f mmc_cube60.json -c sse -M G -n 1e6 -b 0 -O F -F bin \
          -D T -s mmc_out > mmc.log 2>&1)
      printf "round %s mmc    threads %s  %7.1f photons/ms  absorbed %s\n" "$r" "$t" \
        "$(strip < "$work/mmc.log" | sed -n 's/.*speed[^0-9]*\([0-9.]*\) photon\/ms.*/\1/p' | head -1)" \
        "$(strip < "$work/mmc.log" | sed -n 's/.*absorbed: *\([0-9.]*%\).*/\1/p' | head -1)"
    fi
    if [ "$mcxcl" != - ]; then
      (cd "$work" && POCL_MAX_PTHREAD_COUNT=$t "$mcxcl" -f mcxcl_cube60.json -n 1e6 -b 0 -O F -F mc2 \
          -G 1 -A 1 -s mcxcl_out > mcxcl.log 2>&1)
      printf "round %s mcxcl  threads %s  %7.1f photons/ms  absorbed %s\n" "$r" "$t" \
        "$(strip < "$work/mcxcl.log" | sed -n 's/.*speed[^0-9]*\([0-9.]*\) photon\/ms.*/\1/p' | head -1)" \
        "$(strip < "$work/mcxcl.log" | sed -n 's/.*absorbed: *\([0-9.]*%\).*/\1/p' | head -1)"
    fi
  done
done
