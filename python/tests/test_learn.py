"""Training and fine-tuning from Python: the same library runs as `spdcam train` and
`spdcam finetune`, kept small (seconds). These need the training build (`python/README.md`);
`python/ci.sh` runs them against it, the other tests against the build without training."""

import numpy as np
import pytest

import spdcam
from conftest import LIGHTING, errors_match


@pytest.fixture(scope="module")
def mlp(data, tmp_path_factory):
    """A tiny MLP (2 epochs) and the progress it reported."""
    calls = []
    path = tmp_path_factory.mktemp("models") / "mlp.spdm"
    model = spdcam.train(data, path, "mlp", epochs=2, progress=lambda d, t: calls.append((d, t)))
    return path, model, calls


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
