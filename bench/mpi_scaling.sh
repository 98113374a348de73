#!/usr/bin/env bash
# Scaling of one femto run over MPI ranks on this machine (docs/PERFORMANCE.md, "MPI"): the same
# command as 1 process x 1 thread, 1 process x 2 threads and 2 ranks x 1 thread, interleaved,
# REPS times each; prints the median wall-clock seconds and checks the outputs are identical.
# Usage: bench/mpi_scaling.sh [FEMTO] [REPS]   (run from the source root; writes /tmp/femto-mpi-scaling)
set -eu
femto=${1:-build/femto} reps=${2:-3}
work=/tmp/femto-mpi-scaling
rm -rf "$work" && mkdir -p "$work"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_rmaps_base_oversubscribe=1 OMPI_MCA_btl_vader_single_copy_mechanism=none
echo "CPU: $(lscpu | sed -n 's/^Model name: *//p'), $(nproc) cores; load $(cut -d' ' -f1-3 /proc/loadavg)"
seconds() { local t0 t1; t0=$(date +%s.%N); "$@" > /dev/null 2>&1; t1=$(date +%s.%N); echo "$t1 - $t0" | bc; }
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
run() {  # NAME ARGS...
  local name=$1 && shift
  local a=() b=() c=()
  for ((i = 0; i < reps; ++i)); do
    a+=("$(seconds "$femto" "$@" --threads 1 --out "$work/$name-1x1")")
    b+=("$(seconds "$femto" "$@" --threads 2 --out "$work/$name-1x2")")
    c+=("$(seconds mpiexec -n 2 "$femto" "$@" --threads 1 --out "$work/$name-2x1")")
  done
  local same=identical
  for f in transient.npy fluence.npy moments.csv; do
    [ -f "$work/$name-1x1/$f" ] || continue
    cmp -s "$work/$name-1x1/$f" "$work/$name-2x1/$f" || same=DIFFERENT
  done
  local ma mb mc
  ma=$(median "${a[@]}") mb=$(median "${b[@]}") mc=$(median "${c[@]}")
  printf '%-10s 1x1 %6.2f s   1x2 %6.2f s (%.2fx)   2 ranks x1 %6.2f s (%.2fx)   outputs %s\n' \
    "$name" "$ma" "$mb" "$(echo "$ma / $mb" | bc -l)" "$mc" "$(echo "$ma / $mc" | bc -l)" "$same"
}
run path render --integrator path --spp 16 --frames none --no-previews
run hybrid render --spp 4 --frames none --no-previews
run tissue tissue data/scenes/cube60.json --photons 100000
run diffusion diffusion --photons 200000
