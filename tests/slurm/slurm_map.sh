#!/usr/bin/env bash
# A sharded stiffness map through a real Slurm: a single-node cluster is started on this machine
# (scripts/slurm/local-cluster.sh), the job array of scripts/slurm/map-array.sh maps a small
# meristem in 4 shards, `merge` gathers them, and the merged table and surface must be the same
# bytes as a single-process run's. Then a shard is "pre-empted" (its folder emptied of two
# results) and resubmitted: it redoes only those. Usage: slurm_map.sh TISSUEPROBE_CLI WORKDIR
set -euo pipefail
cli=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
work=$2
here=$(cd "$(dirname "$0")/../.." && pwd)
rm -rf "$work"
mkdir -p "$work"
cd "$work"

cluster=$work/cluster
trap 'bash "$here/scripts/slurm/local-cluster.sh" stop "$cluster"' EXIT
eval "$(bash "$here/scripts/slurm/local-cluster.sh" start "$cluster")"
echo "slurm_map: cluster up ($SLURM_CONF)"

"$cli" build --generate --cells 60 --diameter 30 --cap-height 12 --stem-height 4 --seed 3 \
  --out small.ply > /dev/null
opts=(--mesh "$work/small.ply" --refine 0 --depth 0.2 --steps 3 --sites cells --quiet)

"$cli" map "${opts[@]}" --jobs 2 --out single
test -s single/map.csv
rows=$(($(wc -l < single/map.csv) - 1))
echo "slurm_map: single run: $rows sites"
[ "$rows" -gt 20 ] || { echo "slurm_map: expected over 20 sites, got $rows" >&2; exit 1; }

export TP_CLI=$cli
sbatch --wait --array=0-3 --cpus-per-task=1 --chdir="$work" --output="$work/array-%a.log" \
  "$here/scripts/slurm/map-array.sh" "$work/array" map "${opts[@]}"
for i in 0 1 2 3; do
  grep -q "start shard $i/4 on " "array/shard-$i/run.log" ||
    { echo "slurm_map: shard $i/4 did not run under Slurm" >&2; cat "array-$i.log" >&2; exit 1; }
  [ ! -e "array/shard-$i/map.csv" ] || { echo "slurm_map: shard $i wrote the whole table" >&2; exit 1; }
done
"$cli" merge array/shard-0 array/shard-1 array/shard-2 array/shard-3 --out array/map --quiet
cmp single/map.csv array/map/map.csv
cmp single/map-surface.vtu array/map/map-surface.vtu
cmp single/map.json array/map/map.json
echo "slurm_map: 4 shards under Slurm merged: the same table and surface as one process"

# A pre-empted shard: two of its results gone; resubmitted alone, it redoes those two only.
ls array/shard-2/results/task-*.json | head -2 | xargs rm
TP_SHARDS=4 sbatch --wait --array=2 --cpus-per-task=1 --chdir="$work" --output="$work/again-%a.log" \
  "$here/scripts/slurm/map-array.sh" "$work/array" map "${opts[@]}"
tail -n 1 array/shard-2/run.log | grep -q " 2 done (0 not converged)" ||
  { echo "slurm_map: the resubmitted shard did not redo exactly its two missing sites:" >&2;
    tail -n 3 array/shard-2/run.log >&2; exit 1; }
rm -rf array/map
"$cli" merge array/shard-0 array/shard-1 array/shard-2 array/shard-3 --out array/map --quiet
cmp single/map.csv array/map/map.csv
echo "slurm_map: a pre-empted shard resubmitted redid its two missing sites; the same table"
