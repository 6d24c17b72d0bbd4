#!/bin/sh
# Runs `spdcam generate` as N local processes, one shard each, then merges the shards into
# the dataset one run of the same command writes (byte for byte; the test
# `shards_as_parallel_processes_merge_into_one_run` in crates/spdcam/tests/cli_dataset.rs
# checks it). The recipe of docs/scale-out.md on one machine:
#   tools/generate_shards.sh 4 out/big --lighting daylight --count 1000000 --fast --seed 1
# Each process gets one rayon thread per core it shares; SPDCAM (default: spdcam) names the
# binary.
set -eu
if [ $# -lt 3 ]; then
    echo "usage: $0 N OUT GENERATE-ARGS..." >&2
    exit 2
fi
n=$1
out=$2
shift 2
spdcam=${SPDCAM:-spdcam}
cores=$(getconf _NPROCESSORS_ONLN 2>/dev/null || echo 1)
threads=$(( (cores + n - 1) / n ))
mkdir -p "$out"
pids=""
k=0
while [ "$k" -lt "$n" ]; do
    RAYON_NUM_THREADS=$threads "$spdcam" generate "$@" --shard "$k/$n" -o "$out/shard-$k" &
    pids="$pids $!"
    k=$((k + 1))
done
status=0
for pid in $pids; do
    wait "$pid" || status=1
done
if [ "$status" -ne 0 ]; then
    echo "a shard failed; run the same command again to finish it" >&2
    exit 1
fi
shards=""
k=0
while [ "$k" -lt "$n" ]; do
    shards="$shards $out/shard-$k"
    k=$((k + 1))
done
# shellcheck disable=SC2086
"$spdcam" dataset merge -o "$out/merged" $shards
