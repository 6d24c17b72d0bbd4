"""The package built without training (a plain `pip install ./python`): training and
fine-tuning are absent and say how to install the build that has them. `python/ci.sh` runs
this file against that build, and `test_learn.py` against the training build."""

import re

import pytest

import spdcam

INSTALL = 'pip install ./python --config-settings=build-args="--features train"'


def test_this_build_has_no_training_stack():
    assert not spdcam.CAN_TRAIN, "this file tests the package built without `--features train`"
    assert not hasattr(spdcam._native, "train") and not hasattr(spdcam._native, "finetune")


def test_train_names_the_install_that_trains(tmp_path):
    with pytest.raises(ImportError, match=r"spdcam\.train\(\) needs the training build") as e:
        spdcam.train(tmp_path, tmp_path / "m.spdm", "linear", progress=False)
    assert INSTALL in str(e.value)
    assert not (tmp_path / "m.spdm").exists()


def test_finetune_names_the_install_that_trains(tmp_path):
    with pytest.raises(ImportError, match=re.escape(INSTALL)):
        spdcam.finetune(tmp_path / "m.spdm", tmp_path, tmp_path / "t.spdm", progress=False)

