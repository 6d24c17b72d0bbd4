#!/bin/bash
# One shard of a `spdcam generate` run per Slurm array task; submit with
#   sbatch --array=0-15 docs/scale-out/slurm-generate.sh
# then, once every task has finished,
#   sbatch --dependency=afterok:<JOBID> docs/scale-out/slurm-merge.sh
# Every task runs the same command but for its shard, so the array's size is the shard count.
# A task that is requeued or rerun resumes its shard where it stopped.
#SBATCH --job-name=spdcam-generate
#SBATCH --cpus-per-task=8
#SBATCH --mem=4G
#SBATCH --time=01:00:00
#SBATCH --output=logs/generate-%A_%a.out
set -euo pipefail

OUT=${OUT:-$HOME/spdcam-runs/big}
K=$((SLURM_ARRAY_TASK_ID - SLURM_ARRAY_TASK_MIN))
N=$SLURM_ARRAY_TASK_COUNT

# Rayon uses the CPUs Slurm gave the task.
export RAYON_NUM_THREADS=${SLURM_CPUS_PER_TASK:-1}
spdcam generate \
    --lighting mix:daylight=0.5,phosphor=0.3,planck=0.2 \
    --count 100000000 --fast --seed 1 \
    --shard "$K/$N" \
    -o "$OUT/shard-$K"
