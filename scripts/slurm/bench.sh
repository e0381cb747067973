#!/usr/bin/env bash
# A render split over a Slurm job array against one process on the same
# machine: wall times, the scheduler's overhead, the merge, and whether the
# images are equal. Numbers in docs/src/slurm.md.
#
#   bench.sh LUMIS SCENE SPP TASKS [OUT]
#
# LUMIS is a release build of lumis. The Slurm run uses the cluster that
# SLURM_CONF names, else starts one with local-cluster.sh in OUT/cluster
# (and stops it at the end).
set -euo pipefail
[ $# -ge 4 ] || { echo "usage: $0 LUMIS SCENE SPP TASKS [OUT]" >&2; exit 64; }
lumis=$(realpath "$1")
scene=$(realpath "$2")
spp=$3
tasks=$4
out=$(realpath -m "${5:-slurm-bench}")
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
rm -rf "$out/single.exr" "$out/single.png" "$out/run" "$out/merge-again.exr" "$out/merge-again.png"

started_cluster=""
if [ -z "${SLURM_CONF:-}" ]; then
  eval "$("$here/local-cluster.sh" start "$out/cluster")"
  started_cluster=1
fi
stop() { [ -z "$started_cluster" ] || "$here/local-cluster.sh" stop "$out/cluster"; }
trap stop EXIT

now() { date +%s.%N; }
since() { echo "$(now) - $1" | bc; }

# One process with the parts' slice boundaries: the merge's image bit for bit.
t=$(now)
"$lumis" render "$scene" --spp "$spp" --parts "$tasks" -q -o "$out/single.exr" >/dev/null
single=$(since "$t")

t=$(now)
"$lumis" slurm "$scene" --tasks "$tasks" --spp "$spp" --out "$out/run" >/dev/null
submitted=$(since "$t")
parts_done=""
while [ ! -f "$out/run/$(basename "${scene%.toml}").exr" ]; do
  if [ -z "$parts_done" ] && [ "$(ls "$out/run"/part-*.exr 2>/dev/null | wc -l)" -eq "$tasks" ]; then
    parts_done=$(since "$t")
  fi
  sleep 0.05
done
image=$(since "$t")
[ -n "$parts_done" ] || parts_done=$image
# The parts' own render time, as their EXR headers record it.
part_seconds=$(for p in "$out/run"/part-*.exr; do grep -a -o 'lumis.seconds[^0-9]*[0-9.]*' "$p" | grep -a -o '[0-9.]*$' | head -1; done | paste -sd+ | bc)
# The merge command alone, outside Slurm.
parts=$(ls "$out/run"/part-*.exr)
t=$(now)
# shellcheck disable=SC2086
"$lumis" merge $parts -o "$out/merge-again.exr" >/dev/null
merge=$(since "$t")
# An MSE printed as 0.0000e0 is exactly zero: every pixel equal.
mse=$("$lumis" diff "$out/run/$(basename "${scene%.toml}").exr" "$out/single.exr" | awk '$1 == "image" { print $2 }')
equal=no
[ "$mse" = 0.0000e0 ] && equal=yes

printf 'scene %s, %s spp, %s parts, %s CPUs\n' "$(basename "$scene")" "$spp" "$tasks" "$(nproc)"
printf 'one process:                 %8.2f s\n' "$single"
printf 'lumis slurm returned after:  %8.2f s\n' "$submitted"
printf 'submit -> all parts written: %8.2f s\n' "$parts_done"
printf 'submit -> merged image:      %8.2f s\n' "$image"
printf "parts' render time, summed:  %8.2f s\n" "$part_seconds"
# The parts' time spread over the CPUs they ran on (one task per CPU):
# what the array would take with no scheduler between the tasks.
slots=$(( tasks < $(nproc) ? tasks : $(nproc) ))
printf 'scheduler overhead:          %8.2f s (all parts written - summed / %s)\n' \
  "$(echo "$parts_done - $part_seconds / $slots" | bc -l)" "$slots"
printf 'merge job, parts -> image:   %8.2f s\n' "$(echo "$image - $parts_done" | bc -l)"
printf 'lumis merge alone:           %8.2f s\n' "$merge"
printf 'image equal to one process:  %s\n' "$equal"
