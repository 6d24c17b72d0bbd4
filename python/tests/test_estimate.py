"""spdcam.estimate and spdcam.estimate_features against the command line and by hand."""

import csv
import json

import numpy as np
import pytest

import spdcam
from conftest import ROOT, TRUTH


def read_spectral_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], np.array([[float(v) for v in r] for r in rows[1:] if r])
    return header, body[:, 0], body[:, 1:]


def gfc(a, b):
    """Goodness-of-fit coefficient (Hernández-Andrés et al. 2001): |Σab| / √(Σa²·Σb²)."""
    return abs(np.dot(a, b)) / np.sqrt(np.dot(a, a) * np.dot(b, b))


def test_the_example_photo_round_trip(example):
    e = spdcam.estimate(example)
    assert e.name == "sg-telelumen.jpg"
    assert e.model == "the shipped ColorChecker Digital SG model"
    np.testing.assert_array_equal(e.wavelengths, np.arange(400.0, 701.0, 5.0))
    assert e.spd.shape == (61,) and e.spd.max() == pytest.approx(1.0)
    d = e.detection
    assert d.chart == "colorchecker_sg140" and d.method == "detected"
    # One name for the chart in everything a person reads: the model's and the detection's.
    assert d.chart_name == "ColorChecker Digital SG" and d.chart_name in e.model
    assert spdcam.charts()[d.chart] == d.chart_name
    assert spdcam.charts()["colorchecker24"] == "ColorChecker 24"
    assert d.confidence > 0.8
    assert d.corners.shape == (4, 2) and d.homography.shape == (3, 3)
    assert d.features.shape == (288,) and len(d.feature_names) == 288
    assert d.patch_rgb.shape == (140, 3) and d.clipped.shape == (140,)
    # The estimate is the light: close in shape to the true SPD measured beside the chart.
    _, wl, truth = read_spectral_csv(TRUTH)
    t = np.interp(e.wavelengths, wl, truth[:, 0])
    assert gfc(t, e.spd) > 0.9
    # Judged, with bands around the SPD as the library's JSON gives them.
    assert e.verdict in ("ok", "doubtful", "unusable") and isinstance(e.reasons, list)
    assert 0.0 < e.expected_gfc <= 1.0
    assert e.band_widening >= 1.0
    # Every interval is of a registry metric that the calibration covers, and the
    # presentation names each metric as the registry does.
    registry = {m["key"]: m for m in spdcam.METRICS}
    assert set(e.metric_uncertainty) <= {k for k, m in registry.items() if m["calibrated"]}
    for group in e.json["presentation"]["groups"]:
        for m in group["metrics"]:
            assert (m["label"], m["unit"]) == (registry[m["key"]]["label"], registry[m["key"]]["unit"])
            assert group["title"] == registry[m["key"]]["group"]
    ra = e.metric_uncertainty["cri_ra"]
    assert 0.0 < ra["half68"] < ra["half95"] == e.json["metric_uncertainty"]["cri_ra"]["half95"]
    for lower, upper in (e.band, e.band68):
        assert lower.shape == upper.shape == e.spd.shape
        assert np.all(lower <= upper)
    np.testing.assert_array_equal(e.band[0], e.json["band95"]["lower"])
    assert np.all(e.band[0] <= e.band68[0]) and np.all(e.band68[1] <= e.band[1])
    # The same photo as bytes and as the decoded array gives the same estimate.
    from_bytes = spdcam.estimate(example.read_bytes(), source="sg-telelumen.jpg")
    from_array = spdcam.estimate(spdcam.read_photo(example))
    np.testing.assert_array_equal(from_bytes.spd, e.spd)
    np.testing.assert_array_equal(from_array.spd, e.spd)
    assert from_array.duv == e.duv and from_array.name == "photo array"
    # The detection's features, estimated as a row, give the same SPD again.
    row = spdcam.estimate_features(d.features, d.feature_names)
    np.testing.assert_allclose(row.spd[0], e.spd, rtol=0, atol=1e-12)


def test_an_array_estimate_equals_the_cli_csv(example, cli, tmp_path):
    out = tmp_path / "spd.csv"
    done = cli("estimate", str(example), "-o", str(out))
    assert done.returncode == 0, done.stderr
    header, wl, values = read_spectral_csv(out)
    # The SPD, then its 68 % and 95 % bands.
    assert header == ["wavelength_nm", "sg-telelumen.jpg"] + [
        f"sg-telelumen.jpg_{edge}{level}" for level in (68, 95) for edge in ("lower", "upper")
    ]
    e = spdcam.estimate(spdcam.read_photo(example))
    np.testing.assert_array_equal(e.wavelengths, wl)
    np.testing.assert_allclose(e.spd, values[:, 0], rtol=1e-12, atol=1e-15)


def test_float_and_16_bit_arrays_are_the_same_photo(example):
    pixels = spdcam.read_photo(example)
    assert pixels.dtype == np.uint8 and pixels.shape == (1500, 2000, 3)
    wide = pixels.astype(np.uint16) * 257
    as_float = pixels.astype(np.float64) / 255.0
    a = spdcam.estimate(pixels)
    for other in (wide, as_float):
        b = spdcam.estimate(other)
        assert b.detection.chart == a.detection.chart
        np.testing.assert_allclose(b.spd, a.spd, atol=2e-3)


def test_many_feature_rows_are_estimated_at_once(example):
    e = spdcam.estimate(example)
    rows = np.tile(e.detection.features, (1000, 1)).astype(np.float64)
    rows[1::2] *= 0.5  # exposure: the scaler normalises each row by its maximum
    many = spdcam.estimate_features(rows)
    assert len(many) == 1000 and many.spd.shape == (1000, 61)
    np.testing.assert_allclose(many.spd, np.tile(e.spd, (1000, 1)), atol=1e-9)
    np.testing.assert_allclose(many.xy[0], e.xy, atol=1e-12)
    assert many[3].duv == e.duv and many[3].name == "estimate_4"
    frame = many.to_pandas()
    assert frame.shape == (1000, 61) and list(frame.columns[:2]) == ["400", "405"]


def test_a_dataframe_names_its_columns(example):
    import pandas as pd

    e = spdcam.estimate(example)
    frame = pd.DataFrame([e.detection.features], columns=e.detection.feature_names)
    shuffled = frame[list(reversed(frame.columns))]
    with pytest.raises(spdcam.SpdcamError, match="p96_b"):
        spdcam.estimate_features(shuffled)
    np.testing.assert_allclose(spdcam.estimate_features(frame).spd[0], e.spd, atol=1e-12)


def test_the_model_file_and_the_shipped_models_agree(example):
    shipped = spdcam.shipped_model()
    assert "colorchecker_sg96" in shipped.charts
    loaded = spdcam.load_model(ROOT / "models" / "colorchecker_sg96.spdm")
    a = spdcam.estimate(example)
    b = spdcam.estimate(example, model=loaded)
    np.testing.assert_array_equal(a.spd, b.spd)
    assert b.model.endswith("colorchecker_sg96.spdm")


def test_repr_shows_the_numbers_as_the_command_line_does(example, cli):
    e = spdcam.estimate(example)
    shown = repr(e)
    text = cli("estimate", str(example)).stdout
    # The meter's headline and every metric shown: the same digits as the command line.
    for r in e.json["presentation"]["meter"]["headline"]:
        assert r["value"] in shown and r["value"] in text, r
    for group in e.json["presentation"]["groups"]:
        for m in group["metrics"]:
            if m["value"] is not None:
                assert m["value"] in shown and m["value"] in text, m
            elif m["not_meaningful"].startswith("not determinable"):
                # Said with the interval the photo supports, as the command line says it.
                assert m["not_meaningful"] in shown and m["not_meaningful"] in text, m
    assert "PPF per 1000 lx" in shown


def test_the_kind_of_light_can_be_named(example, cli):
    plain = spdcam.estimate(example)
    told = spdcam.estimate(example, light="luminaire")
    assert plain.light == "unknown" and told.light == "luminaire"
    assert told.json["light"] == "luminaire"
    assert not np.array_equal(told.spd, plain.spd)
    # The same estimate as the command line's with --light.
    out = cli("estimate", str(example), "--light", "luminaire", "--json").stdout
    np.testing.assert_allclose(told.spd, json.loads(out)[0]["spd"], rtol=0, atol=1e-12)
    # Feature rows too; a wrong kind is named in the reasons, an unknown one refused.
    rows = spdcam.estimate_features(plain.detection.features, light="daylight")
    assert any("does not look like daylight" in r for r in rows.judgements[0]["reasons"])
    assert set(spdcam.LIGHT_KINDS) >= {"unknown", "daylight", "white-led", "rgb-led"}
    with pytest.raises(spdcam.SpdcamError, match="'candle' is not a kind of light"):
        spdcam.estimate(example, light="candle")


def test_a_list_of_photos_is_estimated_at_once_as_each_alone(example):
    cc24 = ROOT / "examples" / "cc24-led.jpg"
    photos = [example, cc24.read_bytes(), spdcam.read_photo(cc24), example]
    heard = []
    together = spdcam.estimate(photos, source="cc24-led.jpg", progress=lambda d, t: heard.append((d, t)))
    alone = [spdcam.estimate(p, source="cc24-led.jpg") for p in photos]
    assert [e.name for e in together] == [e.name for e in alone]
    for a, b in zip(together, alone):
        np.testing.assert_array_equal(a.spd, b.spd)
        assert a.verdict == b.verdict and a.json == b.json
    # Progress heard after each batch, ending with every photo done.
    assert heard and heard[-1] == (4, 4) and all(d <= t == 4 for d, t in heard)
    # Dicts straight from the library: the numbers keep their JSON types.
    assert isinstance(together[0].json["colorimetry"]["xy"][0], float)
    # One photo that cannot be used raises its message, as alone.
    with pytest.raises(spdcam.SpdcamError, match="^upload.png: not an image"):
        spdcam.estimate([example, b"\x00" * 64], source="upload.png")
