#!/usr/bin/env bash
# A TissueProbe stiffness map (or sweep) as a Slurm job array: array task I of N runs shard I/N
# into OUT/shard-I; a killed or pre-empted task resubmitted goes on where it stopped (finished
# sites are skipped). When every task is done, gather the shards:
#   tissueprobe-cli merge OUT/shard-* --out OUT/map
# Usage (README, "Maps on a Slurm cluster"):
#   sbatch --array=0-99 scripts/slurm/map-array.sh OUT map --mesh tissue.ply --sites cells
#   sbatch --array=0-9  scripts/slurm/map-array.sh OUT sweep --vary E=50:200:4 --sites list --site-list s.csv
# A task that failed or was pre-empted is resubmitted alone with the shard count given, e.g.
#   sbatch --array=17 --export=ALL,TP_SHARDS=100 scripts/slurm/map-array.sh OUT map ...
# The program is tissueprobe-cli on the PATH, or TP_CLI. Each array task uses the CPUs Slurm
# gives it (--cpus-per-task) as worker threads.
#SBATCH --job-name=tissueprobe-map
#SBATCH --cpus-per-task=2
#SBATCH --output=tissueprobe-map-%A_%a.log
set -euo pipefail
if [ $# -lt 2 ] || [ -z "${SLURM_ARRAY_TASK_ID:-}" ]; then
  echo "usage: sbatch --array=0-(N-1) $0 OUT map|sweep [tissueprobe-cli options...]" >&2
  exit 2
fi
out=$1
command=$2
shift 2
case $command in map|sweep) ;; *) echo "$0: expected map or sweep, got '$command'" >&2; exit 2 ;; esac
cli=${TP_CLI:-tissueprobe-cli}
mkdir -p "$out"
exec "$cli" "$command" "$@" \
  --shard "${SLURM_ARRAY_TASK_ID}/${TP_SHARDS:-$SLURM_ARRAY_TASK_COUNT}" \
  --jobs "${SLURM_CPUS_PER_TASK:-1}" \
  --out "$out/shard-${SLURM_ARRAY_TASK_ID}" \
  --progress
