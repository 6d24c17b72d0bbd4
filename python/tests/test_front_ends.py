"""The Python package and the command line give the same estimate: the same SPD, verdict,
reasons and bands for the same photo and for the same feature rows."""

import csv
import json

import numpy as np

import spdcam


def test_a_photo_gives_the_command_lines_estimate(example, cli):
    done = cli("estimate", str(example), "--json")
    assert done.returncode == 0, done.stderr
    want = json.loads(done.stdout)[0]
    got = spdcam.estimate(example)
    np.testing.assert_array_equal(got.spd, want["spd"])
    assert got.verdict == want["verdict"] and got.reasons == want["reasons"]
    np.testing.assert_array_equal(got.band[0], want["band95"]["lower"])
    np.testing.assert_array_equal(got.band68[1], want["band68"]["upper"])
    assert got.expected_gfc == want["expected_gfc"]
    assert got.json["self_check"] == want["self_check"]


def test_feature_rows_are_judged_as_the_command_line_judges_them(example, cli, tmp_path):
    photo = spdcam.estimate(example)
    names = photo.detection.feature_names
    row = np.asarray(photo.detection.features, dtype=np.float64)
    # The photo's row, the same chart half as bright, and the patches in reverse order (a
    # chart the light cannot explain).
    reversed_patches = row.reshape(-1, 3)[::-1].reshape(-1)
    rows = np.stack([row, 0.5 * row, reversed_patches])
    path = tmp_path / "rows.csv"
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(names)
        for r in rows:
            w.writerow([repr(float(v)) for v in r])
    done = cli("estimate", "--features", str(path), "--json")
    assert done.returncode == 0, done.stderr
    # Feature rows stream as JSON Lines: one object per row.
    want = [json.loads(line) for line in done.stdout.splitlines()]
    got = spdcam.estimate_features(rows, names)
    assert len(got) == len(want) == 3
    assert got.verdicts == [w["verdict"] for w in want]
    assert got.verdicts[2] != "ok"
    for i, w in enumerate(want):
        np.testing.assert_array_equal(got.spd[i], w["spd"])
        e = got[i]
        assert e.name == w["name"]
        assert e.verdict == w["verdict"] and e.reasons == w["reasons"]
        assert e.expected_gfc == w["expected_gfc"]
        np.testing.assert_array_equal(e.band[1], w["band95"]["upper"])
        assert got.judgements[i]["self_check"] == w["self_check"]
