#!/usr/bin/env bash
# Two builds of femto-bench-tissue compared on a shared machine (docs/PERFORMANCE.md, "Faces in
# closed form"): each pair runs both at the same time, one pinned to each core (the cores swapped
# from pair to pair), so both see the same load from outside; prints each pair's 1-thread photons
# per CPU-ms and the mean ratio new / old +- its standard error over the pairs, then the ratio of
# each build's mean on the same core (for hosts whose two cores run at different speeds).
# Usage: bench/tissue_ab.sh OLD NEW [PAIRS] [PHOTONS] [SCENE]   (run from the source root)
set -eu
old=$1 new=$2 pairs=${3:-8} photons=${4:-2e5} scene=${5:-data/scenes/cube60.json}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "CPU: $(lscpu | sed -n 's/^Model name: *//p'), $(nproc) cores; load $(cut -d' ' -f1-3 /proc/loadavg)"
# The first line of 1-thread figures (with one core in its mask the bench's 2-thread run is 1 too).
rate() { awk '$1 == "1" && NF == 9 {print $8; exit}' "$1"; }
for i in $(seq "$pairs"); do
  a=$((i % 2)) b=$(((i + 1) % 2))
  taskset -c "$a" "$old" "$scene" "$photons" > "$work/old" 2>&1 &
  taskset -c "$b" "$new" "$scene" "$photons" > "$work/new" 2>&1 &
  wait
  echo "$(rate "$work/old") $(rate "$work/new") $a"
done | awk '{print "old " $1 "  new " $2 "  (old on core " $3 ")"; r = $2 / $1; s += r; ss += r * r; n++
    # Per core: when the two cores run at different speeds (a busy neighbour on one), a pair
    # ratio is mostly the ratio of the cores; the mean of each build on each core cancels that.
    old_on[$3] += $1; new_on[1 - $3] += $2; k[$3]++}
  END {m = s / n; printf "new / old: %.3f +- %.3f (standard error, %d pairs)\n", m, sqrt((ss / n - m * m) / (n - 1)), n
    if (k[0] > 0 && k[1] > 0)
      printf "new / old, core by core: %.3f (core 0: %.3f, core 1: %.3f)\n",
        sqrt((new_on[0] / k[1]) / (old_on[0] / k[0]) * (new_on[1] / k[0]) / (old_on[1] / k[1])),
        (new_on[0] / k[1]) / (old_on[0] / k[0]), (new_on[1] / k[0]) / (old_on[1] / k[1])}'
