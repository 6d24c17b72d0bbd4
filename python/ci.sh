#!/usr/bin/env bash
# Builds and tests the Python package the way a user installs it, in both builds: a fresh
# venv, the test dependencies, then
#   1. `pip install ./python` (the package without the training stack) and pytest over
#      python/tests except the training tests (including the example notebook, and the
#      check that `spdcam.train` names the install that trains);
#   2. the same package reinstalled with `--features train` (see python/README.md) and
#      pytest over the training tests (python/tests/test_learn.py).
# Exits non-zero on any failure, also when no test ran (pytest's exit code 5).
#
# The venv goes under $CARGO_TARGET_DIR (else target/); $PYTHON picks the interpreter.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
target="${CARGO_TARGET_DIR:-$root/target}"
venv="$target/python-venv"
rm -rf "$venv"
"${PYTHON:-python3}" -m venv "$venv"
pip=("$venv/bin/python" -m pip install --quiet --disable-pip-version-check)
# `--config-settings` reaches maturin from pip 23.1 on.
"${pip[@]}" "pip>=23.1"
"${pip[@]}" pytest numpy colour-science nbclient nbformat ipykernel matplotlib pandas pyarrow rawpy
# The command line the tests compare with (with `train`, for the training tests).
cargo build --release --quiet --manifest-path "$root/Cargo.toml" --features spdcam/train
export SPDCAM_BIN="$target/release/spdcam"
pytest=("$venv/bin/python" -m pytest -q -p no:cacheprovider)
cd "$root"

echo "== the package without training"
"${pip[@]}" "$root/python"
"${pytest[@]}" python/tests --ignore=python/tests/test_learn.py

echo "== the package with training"
"${pip[@]}" --force-reinstall --no-deps "$root/python" \
    --config-settings=build-args="--features train"
"${pytest[@]}" python/tests/test_learn.py
