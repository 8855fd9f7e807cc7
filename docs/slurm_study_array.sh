#!/usr/bin/env bash
# A tethash parameter study spread over a Slurm job array: array task I of N runs the study's points whose
# index % N == I (`tethash study ... --shard I/N`) into its own folder; a job started after the array merges the
# shard folders into one study (`tethash study merge`), which is the unsharded study's CSV and JSON.
#
#   jid=$(sbatch --parsable --array=0-15 docs/slurm_study_array.sh)
#   sbatch --dependency=afterok:$jid docs/slurm_study_array.sh merge
#
# Environment: TETHASH (the program; default: tethash on PATH), STUDY_OUT (default: study), STUDY_ARGS (the sweep
# and its options, split at spaces; default: the cell-size sweep of the five Teschner scenarios).
#SBATCH --job-name=tethash-study
#SBATCH --ntasks=1
#SBATCH --cpus-per-task=1
#SBATCH --time=01:00:00
#SBATCH --output=tethash-study-%A_%a.out
set -euo pipefail
tethash="${TETHASH:-tethash}"
out="${STUDY_OUT:-study}"
read -r -a study_args <<<"${STUDY_ARGS:-cell-size --teschner-scenarios}"

if [ "${1:-}" = merge ]; then
  # Warns (exit status 0) when points are missing: rerun the failed array tasks, then merge again.
  exec "$tethash" study merge "$out"/shard_* --out "$out/merged" --no-plot
fi

: "${SLURM_ARRAY_TASK_ID:?submit as a job array: sbatch --array=0-N-1 $0}"
count="${SLURM_ARRAY_TASK_COUNT:?SLURM_ARRAY_TASK_COUNT unset (Slurm sets it for job arrays)}"
index=$((SLURM_ARRAY_TASK_ID - ${SLURM_ARRAY_TASK_MIN:-0})) # arrays may start at 1
# One core per task (--cpus-per-task=1): timings of a shard are not disturbed by the other shards' threads.
export OMP_NUM_THREADS="${SLURM_CPUS_PER_TASK:-1}"
exec "$tethash" study "${study_args[@]}" --shard "$index/$count" --out "$out/shard_$index" --no-plot --quiet
