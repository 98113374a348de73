#!/usr/bin/env bash
# Scaling of one femto run over MPI ranks on this machine (docs/PERFORMANCE.md, "MPI"): the same
# command as 1 process x 1 thread, 1 process x 2 threads and 2 ranks x 1 thread, interleaved,
# REPS times each; prints median wall-clock and CPU seconds (ratios: speed-up in wall clock, CPU
# time relative to 1x1) and checks the outputs are identical.
# Usage: bench/mpi_scaling.sh [FEMTO] [REPS]   (run from the source root; writes /tmp/femto-mpi-scaling)
set -eu
femto=${1:-build/femto} reps=${2:-3}
work=/tmp/femto-mpi-scaling
rm -rf "$work" && mkdir -p "$work"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_rmaps_base_oversubscribe=1 OMPI_MCA_btl_vader_single_copy_mechanism=none
echo "CPU: $(lscpu | sed -n 's/^Model name: *//p'), $(nproc) cores; load $(cut -d' ' -f1-3 /proc/loadavg)"
# "wall cpu": wall-clock and CPU seconds (user + system, all threads and ranks: the ranks are
# children of mpiexec on one machine). On a busy machine CPU time is the fair measure of work.
seconds() { /usr/bin/time -f "%e %U %S" -o "$work/time" "$@" > /dev/null 2>&1; awk '{print $1, $2 + $3}' "$work/time"; }
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
run() {  # NAME ARGS...
  local name=$1 && shift
  local wa=() wb=() wc=() ca=() cb=() cc=() t
  for ((i = 0; i < reps; ++i)); do
    t=($(seconds "$femto" "$@" --threads 1 --out "$work/$name-1x1")) && wa+=("${t[0]}") && ca+=("${t[1]}")
    t=($(seconds "$femto" "$@" --threads 2 --out "$work/$name-1x2")) && wb+=("${t[0]}") && cb+=("${t[1]}")
    t=($(seconds mpiexec -n 2 "$femto" "$@" --threads 1 --out "$work/$name-2x1")) && wc+=("${t[0]}") && cc+=("${t[1]}")
  done
  local same=identical
  for f in transient.npy fluence.npy moments.csv; do
    [ -f "$work/$name-1x1/$f" ] || continue
    cmp -s "$work/$name-1x1/$f" "$work/$name-2x1/$f" || same=DIFFERENT
  done
  local a b c
  a=$(median "${wa[@]}") b=$(median "${wb[@]}") c=$(median "${wc[@]}")
  printf '%-10s wall: 1x1 %6.2f s, 1x2 %6.2f s (%.2fx), 2 ranks x 1 %6.2f s (%.2fx);' \
    "$name" "$a" "$b" "$(echo "$a / $b" | bc -l)" "$c" "$(echo "$a / $c" | bc -l)"
  a=$(median "${ca[@]}") b=$(median "${cb[@]}") c=$(median "${cc[@]}")
  printf ' CPU: %6.2f s, %6.2f s (%.2fx), %6.2f s (%.2fx); outputs %s\n' \
    "$a" "$b" "$(echo "$b / $a" | bc -l)" "$c" "$(echo "$c / $a" | bc -l)" "$same"
}
run path render --integrator path --spp 16 --frames none --no-previews
run hybrid render --spp 4 --frames none --no-previews
run tissue tissue data/scenes/cube60.json --photons 100000
run diffusion diffusion --photons 200000
