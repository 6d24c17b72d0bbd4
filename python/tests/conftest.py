"""Shared fixtures: the repository's example photo and the `spdcam` command line."""

import os
import shlex
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "sg-telelumen.jpg"
TRUTH = ROOT / "examples" / "sg-telelumen.truth.csv"


@pytest.fixture(scope="session")
def example() -> Path:
    return EXAMPLE


@pytest.fixture(scope="session")
def cli():
    """Runs the `spdcam` command line (``$SPDCAM_BIN``, else ``cargo run --release`` with
    the ``train`` feature) in the repository root without a data directory; returns the
    finished process."""
    command = os.environ.get("SPDCAM_BIN")
    base = (
        shlex.split(command)
        if command
        else ["cargo", "run", "--release", "-q", "-p", "spdcam", "--features", "train", "--"]
    )
    env = {k: v for k, v in os.environ.items() if k != "SPDCAM_DATA"}

    def run(*args: str) -> subprocess.CompletedProcess:
        return subprocess.run(
            [*base, *args], cwd=ROOT, env=env, capture_output=True, text=True, timeout=600
        )

    return run
