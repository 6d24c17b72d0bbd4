"""to_colour(): the SPD as colour-science objects, with the same xy and CCT colour-science
computes from that SPD."""

import colour
import numpy as np
import pytest

import spdcam


def test_to_colour_gives_colour_sciences_xy_and_cct(example):
    e = spdcam.estimate(example)
    sd = e.to_colour()
    assert isinstance(sd, colour.SpectralDistribution)
    np.testing.assert_array_equal(sd.wavelengths, e.wavelengths)
    np.testing.assert_array_equal(sd.values, e.spd)
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    XYZ = colour.sd_to_XYZ(sd, cmfs=cmfs, method="Integration")
    xy = colour.XYZ_to_xy(XYZ)
    np.testing.assert_allclose(e.xy, xy, atol=2e-4)
    cct, duv = colour.uv_to_CCT(colour.xy_to_UCS_uv(xy), method="Ohno 2013")
    assert e.cct == pytest.approx(cct, abs=5.0)
    assert e.duv == pytest.approx(duv, abs=2e-4)


def test_many_rows_to_colour(example):
    e = spdcam.estimate(example)
    many = spdcam.estimate_features(np.tile(e.detection.features, (3, 1)))
    msds = many.to_colour()
    assert isinstance(msds, colour.MultiSpectralDistributions)
    assert msds.values.shape == (61, 3)
    np.testing.assert_allclose(msds.values[:, 2], e.spd, atol=1e-12)
