"""Datasets from Python: the same library run as `spdcam generate`, in the package built
without training as in the one with it."""

import numpy as np
import pyarrow.parquet as pq
import pytest

import spdcam
from conftest import LIGHTING, errors_match


def feature_columns(table):
    return [c for c in table.column_names if c.startswith("p") and c[-2:] in ("_r", "_g", "_b")]


def test_generate_writes_the_columns_and_rows(data):
    table = data.to_arrow()
    assert table.num_rows == len(data) == 300
    assert table.column("sample").to_pylist() == list(range(300))
    features = feature_columns(table)
    assert features[:3] == ["p01_r", "p01_g", "p01_b"] and len(features) == 72
    spds = [c for c in table.column_names if c.startswith("spd_")]
    assert spds[0] == "spd_380" and spds[-1] == "spd_780" and len(spds) == 81
    frame = data.to_pandas()
    assert frame.shape == (table.num_rows, table.num_columns)
    assert np.all(np.isfinite(frame[features].to_numpy()))


def test_generate_equals_the_command_line(cli, tmp_path):
    calls = []
    ours = spdcam.generate(
        tmp_path / "py", LIGHTING, 40, seed=3, progress=lambda d, t: calls.append((d, t))
    )
    done = cli("generate", "--lighting", LIGHTING, "--count", "40", "--seed", "3",
               "-o", str(tmp_path / "cli"))
    assert done.returncode == 0, done.stderr
    theirs = pq.read_table(tmp_path / "cli" / "samples")
    assert ours.to_arrow().equals(theirs)
    assert ours.manifest["files"] == spdcam.Dataset(str(tmp_path / "cli")).manifest["files"]
    assert calls and calls[-1] == (40, 40)
    assert all(a[0] < b[0] for a, b in zip(calls, calls[1:]))


def test_generate_resumes_and_replaces(tmp_path):
    first = spdcam.generate(tmp_path / "set", LIGHTING, 20, fast=True, progress=False)
    again = spdcam.generate(tmp_path / "set", LIGHTING, 20, fast=True, progress=False)
    assert again.to_arrow().equals(first.to_arrow())
    other = spdcam.generate(tmp_path / "set", LIGHTING, 10, seed=9, fast=True, force=True,
                            progress=False)
    assert len(other) == 10


def test_a_bad_lighting_spec_gives_the_cli_message(cli, tmp_path):
    with pytest.raises(spdcam.SpdcamError, match="nonsense") as caught:
        spdcam.generate(tmp_path / "x", "nonsense:3", 10, progress=False)
    errors_match(cli, caught, "generate", "--lighting", "nonsense:3", "--count", "10",
                 "-o", str(tmp_path / "y"))


def test_a_count_below_one_is_refused(cli, tmp_path):
    with pytest.raises(spdcam.SpdcamError, match="at least 1") as caught:
        spdcam.generate(tmp_path / "x", LIGHTING, 0, progress=False)
    errors_match(cli, caught, "generate", "--lighting", LIGHTING, "--count", "0",
                 "-o", str(tmp_path / "y"))
