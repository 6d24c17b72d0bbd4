"""to_colour(): the SPD as colour-science objects, with the same xy and CCT colour-science
computes from that SPD."""

import colour
import numpy as np
import pytest

import spdcam


def colour_science_xy_cct_duv(sd):
    """xy (CIE 1931 2°, summed on the SPD's own wavelengths as spdcam), CCT and Duv (Ohno
    2013) by colour-science."""
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(sd.shape)
    xy = colour.XYZ_to_xy(colour.sd_to_XYZ(sd, cmfs=cmfs, method="Integration"))
    cct, duv = colour.uv_to_CCT(colour.xy_to_UCS_uv(xy), method="Ohno 2013")
    return xy, cct, duv


def test_to_colour_gives_colour_sciences_xy(example):
    e = spdcam.estimate(example)
    sd = e.to_colour()
    assert isinstance(sd, colour.SpectralDistribution)
    np.testing.assert_array_equal(sd.wavelengths, e.wavelengths)
    np.testing.assert_array_equal(sd.values, e.spd)
    xy, _, duv = colour_science_xy_cct_duv(sd)
    np.testing.assert_allclose(e.xy, xy, atol=2e-4)
    # This light is far from the Planckian locus: spdcam gives no CCT, and colour-science
    # agrees that it is beyond |Duv| 0.05.
    assert e.cct is None and e.duv is None and abs(duv) > 0.05


def test_cct_and_duv_equal_colour_sciences(example):
    features = spdcam.estimate(example).detection.features.reshape(-1, 3)
    # The same chart under less magenta lights: the camera's channels scaled down (within 0–255).
    rows = np.stack([(features * g).ravel() for g in ([1.0, 1.0, 0.6], [0.7, 1.0, 0.55], [0.8, 0.95, 0.7])])
    many = spdcam.estimate_features(rows)
    near = [i for i in range(len(many)) if many[i].cct is not None]
    assert near, "a rescaled chart gives a light near the Planckian locus"
    for i in near:
        xy, cct, duv = colour_science_xy_cct_duv(many[i].to_colour())
        np.testing.assert_allclose(many.xy[i], xy, atol=2e-4)
        assert many.cct[i] == pytest.approx(cct, rel=1e-3)
        assert many.duv[i] == pytest.approx(duv, abs=2e-4)


def test_many_rows_to_colour(example):
    e = spdcam.estimate(example)
    many = spdcam.estimate_features(np.tile(e.detection.features, (3, 1)))
    msds = many.to_colour()
    assert isinstance(msds, colour.MultiSpectralDistributions)
    assert msds.values.shape == (61, 3)
    np.testing.assert_allclose(msds.values[:, 2], e.spd, atol=1e-12)
