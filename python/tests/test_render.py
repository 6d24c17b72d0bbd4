"""spdcam.render against `spdcam render`."""

import csv

import numpy as np
import pytest

import spdcam


def test_render_equals_the_cli(cli, tmp_path):
    png, features = tmp_path / "a.png", tmp_path / "a.csv"
    done = cli("render", "--spd", "A", "--seed", "3", "-o", str(png), "--features", str(features))
    assert done.returncode == 0, done.stderr
    r = spdcam.render("A", seed=3)
    np.testing.assert_array_equal(r.to_uint8(), spdcam.read_photo(png))
    with open(features, newline="") as f:
        names, values = list(csv.reader(f))[:2]
    assert r.feature_names == names
    np.testing.assert_array_equal(r.features, np.array(values, dtype=np.float32))


def test_an_spd_as_arrays_renders_like_its_name():
    import colour

    a = colour.SDS_ILLUMINANTS["A"].copy().align(colour.SpectralShape(380, 780, 5))
    by_name = spdcam.render("A", seed=1)
    by_values = spdcam.render(a.values, a.wavelengths, seed=1)
    by_colour = spdcam.render(a, seed=1)
    np.testing.assert_allclose(by_values.features, by_name.features, atol=0.5)
    np.testing.assert_array_equal(by_colour.features, by_values.features)


def test_bad_lights_are_named():
    with pytest.raises(spdcam.SpdcamError, match="wavelengths"):
        spdcam.render([1.0, 2.0])
    with pytest.raises(spdcam.SpdcamError, match="3 wavelengths for 2"):
        spdcam.render([1.0, 2.0], [400, 500, 600])
    with pytest.raises(spdcam.SpdcamError, match="nolight"):
        spdcam.render("nolight")
