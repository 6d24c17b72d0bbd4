#!/usr/bin/env bash
# Measures how long a source install of the Python package takes in each build, one after
# the other on the same machine state: `pip install ./python` (without the training stack),
# then the same with `--features train` (python/README.md). Each build starts from an empty
# cargo target directory, so every crate is compiled as on a user's first install; the
# crates' sources are fetched before the timing (`cargo fetch`), as is the package's Python
# dependency (numpy). Prints the seconds of each, the size of each compiled module, the
# ratio, and the machine's cores and load average beside them (other work on the machine
# slows both builds alike only when the load stays steady).
#
# Takes $PYTHON for the interpreter; the work directory is removed at the end.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
"${PYTHON:-python3}" -m venv "$work/venv"
py="$work/venv/bin/python"
pip=("$py" -m pip install --quiet --disable-pip-version-check)
"${pip[@]}" "pip>=23.1" numpy
cargo fetch --quiet --manifest-path "$root/Cargo.toml"

# `measure NAME [pip options…]`: installs the package with a fresh target directory and
# prints NAME, the seconds it took and the compiled module's size.
measure() {
    local name="$1"
    shift
    local load start seconds so
    load="$(cut -d' ' -f1-3 /proc/loadavg)"
    start="$SECONDS"
    CARGO_TARGET_DIR="$work/target-$name" "${pip[@]}" --force-reinstall --no-deps \
        "$root/python" "$@"
    seconds=$((SECONDS - start))
    so="$("$py" -c 'import spdcam._native as n; print(n.__file__)')"
    awk -v n="$name" -v s="$seconds" -v b="$(stat -c %s "$so")" -v l="$load" 'BEGIN {
        printf "%-14s %5d s (%.1f min)   module %.1f MB   load average before: %s\n",
            n, s, s / 60, b / 1e6, l }'
    echo "$seconds" >"$work/$name.seconds"
}

echo "cores: $(nproc)"
measure estimate-only
measure train --config-settings=build-args="--features train"
awk -v e="$(cat "$work/estimate-only.seconds")" -v t="$(cat "$work/train.seconds")" \
    'BEGIN { printf "the training build takes %.1f times as long\n", t / e }'
