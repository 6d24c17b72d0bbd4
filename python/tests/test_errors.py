"""Bad input raises clear exceptions, with the command line's messages."""

import numpy as np
import pytest

import spdcam
from conftest import ROOT


def test_a_missing_file_is_file_not_found(tmp_path):
    missing = tmp_path / "nothing.jpg"
    with pytest.raises(FileNotFoundError, match="nothing.jpg"):
        spdcam.estimate(missing)


def test_a_file_that_is_no_image_gives_the_cli_message(cli, tmp_path):
    notes = tmp_path / "notes.jpg"
    notes.write_text("hello, this is text")
    with pytest.raises(spdcam.SpdcamError) as caught:
        spdcam.estimate(notes)
    message = str(caught.value)
    assert "notes.jpg" in message and "not a JPEG, PNG, TIFF or camera raw image" in message
    done = cli("estimate", str(notes))
    assert done.returncode != 0
    assert f"error: {message}" in done.stderr


def test_a_bad_range_gives_the_cli_message(example, cli):
    with pytest.raises(spdcam.SpdcamError) as caught:
        spdcam.estimate(example, range="700-400")
    done = cli("estimate", str(example), "--range", "700-400")
    assert done.returncode != 0
    assert f"error: {caught.value}" in done.stderr


def test_bytes_that_are_no_image_name_their_source():
    with pytest.raises(spdcam.SpdcamError, match="upload.png.*not an image"):
        spdcam.estimate(b"\x00" * 64, source="upload.png")


def test_a_photo_without_a_chart_says_so():
    grey = np.full((300, 400, 3), 128, dtype=np.uint8)
    with pytest.raises(spdcam.SpdcamError, match="grey"):
        spdcam.estimate(grey, source="grey")


@pytest.mark.parametrize(
    "array, expected",
    [
        (np.zeros((10, 10), dtype=np.uint8), "H×W×3"),
        (np.zeros((40, 40, 4), dtype=np.uint8), "H×W×3"),
        (np.zeros((40, 40, 3), dtype=np.int32), "int32"),
        (np.full((40, 40, 3), 2.0), "0–1"),
        (np.full((40, 40, 3), np.nan), "not finite"),
        (np.zeros((8, 8, 3), dtype=np.uint8), "8×8 px"),
    ],
)
def test_unusable_arrays_are_named(array, expected):
    with pytest.raises(spdcam.SpdcamError, match=expected):
        spdcam.estimate(array)


def test_feature_rows_are_checked():
    with pytest.raises(spdcam.SpdcamError, match="no model reads 5 feature columns"):
        spdcam.estimate_features(np.ones((2, 5)))
    rows = np.ones((3, 288))
    rows[2, 7] = np.inf
    with pytest.raises(spdcam.SpdcamError, match=r"row 3, column p03_g: inf is not a finite"):
        spdcam.estimate_features(rows)
    with pytest.raises(spdcam.SpdcamError, match="2 names for 288"):
        spdcam.estimate_features(np.ones((1, 288)), names=["a", "b"])
    with pytest.raises(spdcam.SpdcamError, match="real numbers"):
        spdcam.estimate_features(np.array([["a", "b"]]))


def test_a_damaged_model_file_is_named(tmp_path):
    bad = tmp_path / "bad.spdm"
    bad.write_bytes(b"not a model")
    with pytest.raises(spdcam.SpdcamError, match="bad.spdm"):
        spdcam.load_model(bad)


def test_a_photo_of_the_wrong_type_is_a_type_error():
    with pytest.raises(TypeError, match="path, the bytes"):
        spdcam.estimate(12)
    assert (ROOT / "examples").is_dir()


def test_corners_on_no_chart_raise_a_value_error_saying_what_to_do():
    # Issue 41: four corners placed on an image with no chart gave numbers.
    noise = np.random.default_rng(7).integers(0, 256, size=(300, 400, 3), dtype=np.uint8)
    corners = [(40, 30), (360, 40), (350, 270), (50, 260)]
    with pytest.raises(ValueError) as caught:
        spdcam.estimate(noise, corners=corners, chart="colorchecker24", source="noise")
    message = str(caught.value)
    assert message.startswith(
        "noise: these corners do not hold a ColorChecker 24: place them on the chart's "
        "four outer corners ("
    ), message
    assert isinstance(caught.value, spdcam.SpdcamError)
