"""Datasets, training and fine-tuning from Python: the same library runs as `spdcam
generate`, `spdcam train` and `spdcam finetune`, kept small (seconds)."""

import numpy as np
import pyarrow.parquet as pq
import pytest

import spdcam

LIGHTING = "gaussian:4"


def feature_columns(table):
    return [c for c in table.column_names if c.startswith("p") and c[-2:] in ("_r", "_g", "_b")]


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    """300 noise-free samples (the fast pipeline), for training."""
    out = tmp_path_factory.mktemp("learn") / "set"
    return spdcam.generate(out, LIGHTING, 300, seed=5, fast=True, progress=False)


@pytest.fixture(scope="module")
def mlp(data, tmp_path_factory):
    """A tiny MLP (2 epochs) and the progress it reported."""
    calls = []
    path = tmp_path_factory.mktemp("models") / "mlp.spdm"
    model = spdcam.train(data, path, "mlp", epochs=2, progress=lambda d, t: calls.append((d, t)))
    return path, model, calls


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


def test_a_linear_model_estimates_the_dataset_rows(data, tmp_path):
    model = spdcam.train(data, tmp_path / "linear.spdm", "linear", progress=False)
    assert (tmp_path / "linear.spdm").is_file()
    assert model.charts == ["colorchecker24"] and model.grids == ["400-700:5"]
    frame = data.to_pandas()
    rows = spdcam.estimate_features(frame[model.feature_names[0]], model=model)
    assert rows.spd.shape == (300, 61)
    assert np.all(np.isfinite(rows.spd)) and np.allclose(rows.spd.max(axis=1), 1.0)


def test_an_mlp_reports_its_epochs_and_estimates(mlp, data):
    path, model, calls = mlp
    assert calls == [(1, 2), (2, 2)]
    table = data.to_arrow()
    features = table.select(model.feature_names[0]).to_pandas().to_numpy()[:10]
    rows = spdcam.estimate_features(features, model=path)
    assert rows.spd.shape == (10, 61) and np.all(np.isfinite(rows.spd))
    assert rows.model == model.names[0]


def test_finetune_with_a_recipe(mlp, tmp_path):
    path, _, _ = mlp
    small = spdcam.generate(tmp_path / "small", "gaussian:2", 40, seed=8, fast=True,
                            progress=False)
    calls = []
    tuned = spdcam.finetune(path, small, tmp_path / "tuned.spdm", epochs=2,
                            progress=lambda d, t: calls.append((d, t)))
    assert (tmp_path / "tuned.spdm").is_file() and calls == [(1, 2), (2, 2)]
    rows = spdcam.estimate_features(small.to_pandas()[tuned.feature_names[0]], model=tuned)
    assert rows.spd.shape == (40, 61) and np.all(np.isfinite(rows.spd))


def test_finetune_chooses_the_recipe_by_cross_validation(mlp, tmp_path):
    path, _, _ = mlp
    few = spdcam.generate(tmp_path / "few", "gaussian:2", 4, seed=8, fast=True, progress=False)
    calls = []
    tuned = spdcam.finetune(path, few, tmp_path / "chosen.spdm",
                            progress=lambda d, t: calls.append((d, t)))
    assert tuned.feature_names[0][0] == "p01_r"
    # 2 folds × 7 candidate recipes, then the chosen one on all the samples.
    assert [d for d, _ in calls] == list(range(1, 16)) and {t for _, t in calls} == {15}


def test_an_exception_of_the_callback_reaches_the_caller(data, tmp_path):
    def boom(done, total):
        raise RuntimeError("stop")

    with pytest.raises(RuntimeError, match="stop"):
        spdcam.train(data, tmp_path / "m.spdm", "mlp", epochs=1, progress=boom)


def errors_match(cli, caught, *args):
    """The command line fails on the same input with the same message."""
    done = cli(*args)
    assert done.returncode != 0
    assert str(caught.value) in done.stderr, done.stderr


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


def test_a_missing_dataset_gives_the_cli_message(cli, tmp_path):
    missing = tmp_path / "missing"
    with pytest.raises(spdcam.SpdcamError, match="opening dataset .*missing") as caught:
        spdcam.train(missing, tmp_path / "m.spdm", "linear", progress=False)
    errors_match(cli, caught, "train", "--data", str(missing), "--model", "linear",
                 "-o", str(tmp_path / "m.spdm"))


def test_too_few_rows_give_the_cli_message(cli, tmp_path):
    tiny = spdcam.generate(tmp_path / "tiny", LIGHTING, 2, fast=True, progress=False)
    with pytest.raises(spdcam.SpdcamError, match="2") as caught:
        spdcam.train(tiny, tmp_path / "m.spdm", "mlp", epochs=1, progress=False)
    errors_match(cli, caught, "train", "--data", tiny.path, "--model", "mlp", "--epochs", "1",
                 "-o", str(tmp_path / "m.spdm"))


def test_an_unknown_model_kind_is_named(data, tmp_path):
    with pytest.raises(spdcam.SpdcamError, match="unknown model 'transformer'.*cnn1d"):
        spdcam.train(data, tmp_path / "m.spdm", "transformer")


def test_a_linear_model_cannot_be_finetuned(data, tmp_path):
    linear = tmp_path / "linear.spdm"
    spdcam.train(data, linear, "linear", progress=False)
    with pytest.raises(spdcam.SpdcamError, match="linear model has no layers"):
        spdcam.finetune(linear, data, tmp_path / "t.spdm", epochs=1, progress=False)


def test_choosing_a_recipe_needs_four_samples(mlp, tmp_path):
    path, _, _ = mlp
    three = spdcam.generate(tmp_path / "three", LIGHTING, 3, fast=True, progress=False)
    with pytest.raises(spdcam.SpdcamError, match="3 sample.*at least 4"):
        spdcam.finetune(path, three, tmp_path / "t.spdm", progress=False)


def test_an_output_onto_an_input_is_refused_and_the_input_kept(mlp, tmp_path):
    """Issue 39: the one output guard of the command line holds in Python too."""
    path, _, _ = mlp
    before = path.read_bytes()
    small = spdcam.generate(tmp_path / "small", "gaussian:2", 40, seed=8, fast=True,
                            progress=False)
    with pytest.raises(spdcam.SpdcamError, match="output= .* is the input model="):
        spdcam.finetune(path, small, path, epochs=1, progress=False)
    assert path.read_bytes() == before
    manifest = tmp_path / "small" / "manifest.json"
    kept = manifest.read_bytes()
    with pytest.raises(spdcam.SpdcamError, match="lies inside the input data="):
        spdcam.train(small, manifest, "linear", progress=False)
    assert manifest.read_bytes() == kept
