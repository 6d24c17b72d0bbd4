"""Camera raw files: a DNG the virtual camera writes is read by an independent reader
(LibRaw, through rawpy) as written, and estimated from Python like a JPEG, with the light's
colour read on the sensor's mosaic."""

import numpy as np
import pytest
import rawpy

import spdcam

#: CIE A's chromaticity (CIE 015:2018, table 11.3).
A_XY = (0.44757, 0.40745)


@pytest.fixture(scope="module")
def dng(cli, tmp_path_factory):
    """A 1200×900 scene photo of the ColorChecker 24 under CIE A, as a raw DNG."""
    path = tmp_path_factory.mktemp("raw") / "scene.dng"
    done = cli("render", "--spd", "A", "--scene", "1200x900", "--seed", "4", "-o", str(path))
    assert done.returncode == 0, done.stderr
    return path


def test_libraw_reads_the_dng_as_written(dng):
    with rawpy.imread(str(dng)) as raw:
        assert raw.raw_image_visible.shape == (900, 1200)
        # RGGB, LibRaw's colour indices (0 R, 1 G, 2 B, 3 the second G).
        assert raw.raw_pattern.tolist() == [[0, 1], [3, 2]]
        assert raw.black_level_per_channel == [256, 256, 256, 256]
        assert raw.white_level == 16383
        values = raw.raw_image_visible
        assert 256 - 64 <= values.min() and values.max() <= 16383
        # The as-shot neutral under A: LibRaw's camera white balance is its inverse, the
        # blue gain well above the red one for a warm light.
        wb = raw.camera_whitebalance
        assert wb[2] / wb[1] > 1.5 * (wb[0] / wb[1]), wb
        # LibRaw develops it too (demosaicing, white balance, the file's matrix).
        rgb = raw.postprocess(use_camera_wb=True, no_auto_bright=True)
        assert rgb.shape == (900, 1200, 3) and rgb.mean() > 10


def test_python_estimates_a_dng_with_the_light_read_on_the_mosaic(dng):
    e = spdcam.estimate(str(dng))
    assert e.detection.raw is not None
    light = e.detection.raw["light_xy"]
    assert abs(light[0] - A_XY[0]) < 0.003 and abs(light[1] - A_XY[1]) < 0.003, light
    # The estimate carries that colour, less the matrices' bias for the shape it reads
    # (models/raw-colour.json): still within 0.003 of A's.
    assert np.allclose(e.xy, A_XY, atol=0.003), (e.xy, light)
    assert e.detection.raw["colour"]["matrices"] == ["A", "D65"]
    # The spectrum is the shipped ColorChecker 24 raw model's, as on the command line.
    assert e.detection.raw["spectrum_model"] == "the shipped ColorChecker 24 raw model"


def test_a_truncated_dng_is_refused_with_its_name(dng):
    data = dng.read_bytes()
    with pytest.raises(spdcam.SpdcamError, match="cut.dng"):
        spdcam.estimate(data[: len(data) // 3], source="cut.dng")


def test_a_dng_told_its_illuminance_gives_absolute_levels(cli, tmp_path):
    """`render --illuminance` writes the DNG's EXIF exposure (ISO 12232 saturation-based
    speed); Python reads the absolute levels of the raw photo back as it does a JPEG's."""
    path = tmp_path / "lit.dng"
    done = cli(
        "render", "--spd", "A", "--scene", "1200x900", "--chart-centre", "0.5,0.5",
        "--chart-width", "0.4", "--seed", "30", "--illuminance", "250", "-o", str(path),
    )
    assert done.returncode == 0, done.stderr
    e = spdcam.estimate(str(path))
    assert e.absolute is not None, e.json.get("absolute_reason")
    # Read back within 3 % (crates/spdcam/tests/cli_raw.rs says why).
    assert abs(e.absolute["illuminance_lux"] / 250.0 - 1.0) < 0.03, e.absolute
    assert "saturation-based speed" in e.absolute["note"]
