#!/bin/bash
# Joins the shards written by slurm-generate.sh into one dataset, the files one
# uninterrupted run would have written (`spdcam dataset merge` checks that every shard of
# the run is there and that none overlaps another).
#SBATCH --job-name=spdcam-merge
#SBATCH --cpus-per-task=2
#SBATCH --mem=4G
#SBATCH --time=01:00:00
#SBATCH --output=logs/merge-%j.out
set -euo pipefail

OUT=${OUT:-$HOME/spdcam-runs/big}
spdcam dataset merge -o "$OUT/merged" "$OUT"/shard-*
spdcam dataset info "$OUT/merged"
