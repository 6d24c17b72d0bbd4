"""Shared fixtures: the repository's example photo, the `spdcam` command line, a small
dataset; and the check that a Python error is the command line's."""

import os
import shlex
import subprocess
from pathlib import Path

import pytest

import spdcam

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "sg-telelumen.jpg"
TRUTH = ROOT / "examples" / "sg-telelumen.truth.csv"
#: The lighting recipe of the small datasets the tests generate.
LIGHTING = "gaussian:4"


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


@pytest.fixture(scope="session")
def data(tmp_path_factory):
    """300 noise-free samples (the fast pipeline), for training and the dataset tests."""
    out = tmp_path_factory.mktemp("learn") / "set"
    return spdcam.generate(out, LIGHTING, 300, seed=5, fast=True, progress=False)


def errors_match(cli, caught, *args):
    """The command line fails on the same input with the same message."""
    done = cli(*args)
    assert done.returncode != 0
    assert str(caught.value) in done.stderr, done.stderr
