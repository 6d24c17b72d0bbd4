#!/usr/bin/env bash
# Builds and tests the Python package the way a user installs it: a fresh venv, then
# `pip install ./python` (maturin builds the wheel from the workspace), the test
# dependencies, and pytest over python/tests (including the example notebook). Exits
# non-zero on any failure, also when no test ran (pytest's exit code 5).
#
# The venv goes under $CARGO_TARGET_DIR (else target/); $PYTHON picks the interpreter.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
target="${CARGO_TARGET_DIR:-$root/target}"
venv="$target/python-venv"
rm -rf "$venv"
"${PYTHON:-python3}" -m venv "$venv"
pip=("$venv/bin/python" -m pip install --quiet --disable-pip-version-check)
"${pip[@]}" pytest numpy colour-science nbclient nbformat ipykernel matplotlib pandas pyarrow
"${pip[@]}" "$root/python"
# The command line the tests compare with (with `train`, for the training tests).
cargo build --release --quiet --manifest-path "$root/Cargo.toml" --features spdcam/train
export SPDCAM_BIN="$target/release/spdcam"
cd "$root"
"$venv/bin/python" -m pytest python/tests -q -p no:cacheprovider
