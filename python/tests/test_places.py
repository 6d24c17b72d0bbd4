"""The light at several places from Python: ``estimate_places`` gives one estimate per
chart of a photo, numbered from left to right, each with its place and the comparison across
the photo's places, the same as ``spdcam estimate`` prints."""

import numpy as np
import pytest

import spdcam
from conftest import ROOT

#: Three ColorChecker 24s: CIE A at the left, D65 at the right, the lower one at 0.4 of
#: the upper's light (the README's `render --place` command).
PLACES = ROOT / "examples" / "cc24-two-lights.jpg"


@pytest.fixture(scope="module")
def places():
    return spdcam.estimate_places(PLACES)


def test_one_estimate_per_chart_numbered_from_left_to_right(places):
    assert [e.name for e in places] == [f"cc24-two-lights.jpg place {k}" for k in (1, 2, 3)]
    xs = [e.detection.place["centre"][0] for e in places]
    assert xs == sorted(xs)
    assert all(e.detection.place["of"] == 3 for e in places)
    # A warm light at place 1, daylight at places 2 and 3.
    assert places[0].cct < 3600 < places[1].cct
    assert places[1].cct > 4000 and places[2].cct > 4000


def test_the_comparison_tells_the_lights_apart_and_the_levels(places):
    across = places[0].across_places
    assert across == places[1].across_places == places[2].across_places
    assert across["lights_differ"] is True
    assert across["most_different"] == 1
    levels = [p["relative_illuminance"] for p in across["places"]]
    np.testing.assert_allclose(levels, [1 / 0.979, 1.0, 0.392 / 0.979], rtol=0.05)


def test_the_same_photo_as_bytes_or_pixels_gives_the_same_places(places):
    from_bytes = spdcam.estimate_places(PLACES.read_bytes(), source="upload.jpg")
    assert [e.name for e in from_bytes] == [f"upload.jpg place {k}" for k in (1, 2, 3)]
    for a, b in zip(places, from_bytes):
        np.testing.assert_allclose(a.spd, b.spd)
    pixels = spdcam.read_photo(PLACES)
    from_pixels = spdcam.estimate_places(pixels)
    assert len(from_pixels) == 3


def test_a_photo_of_one_chart_is_a_list_of_one(example):
    (only,) = spdcam.estimate_places(example)
    assert only.detection.place is None and only.across_places is None
    np.testing.assert_allclose(only.spd, spdcam.estimate(example).spd)


def test_a_photo_without_a_chart_raises():
    with pytest.raises(spdcam.SpdcamError, match="no chart found"):
        spdcam.estimate_places(np.full((200, 300, 3), 128, dtype=np.uint8))


def test_corners_given_per_chart_place_the_same_charts(places):
    corners = [e.detection.corners.tolist() for e in places]
    placed = spdcam.estimate_places(PLACES, corners=corners[::-1])
    assert [e.detection.place["number"] for e in placed] == [1, 2, 3]
    assert all(e.detection.method == "corners" for e in placed)
    for a, b in zip(places, placed):
        assert abs(a.cct - b.cct) / a.cct < 0.02
    with pytest.raises(spdcam.SpdcamError, match="four points"):
        spdcam.estimate_places(PLACES, corners=[corners[0], corners[1][:3]])
