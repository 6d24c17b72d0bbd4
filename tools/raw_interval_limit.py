"""How narrow a raw photo's CCT interval can be: the part of the error no reading of the
light can predict.

Each lamp of the colour experiment's raw scenes is photographed through two held-out
cameras (`--photos 2`), so each lamp's signed relative CCT error (estimate / truth − 1)
splits into what the lamp shares through every camera and what one camera adds. With
two photos e₁, e₂ of a lamp read by one model, (e₁ − e₂)² / 2 is an unbiased estimate of
the camera-to-camera variance; its mean over lamps, pooled by lamp type, is the spread that
remains even for an interval that knew the lamp exactly (its kind, its shape, the bias its
matrices share): a 95 % interval must then still be about 1.96 of that standard deviation
wide (a normal error), whatever it is conditioned on. The same photos give the shipped
intervals' median half-width and how often they hold, by lamp type, beside it.

Then the goal's own set: "common white lamps" are read as every lamp type but the
mixed-colour LEDs (RGB and RGBA mixtures), the medians of the test lamps taken without them.

    python3 tools/raw_interval_limit.py PHOTOS.csv

PHOTOS.csv: `spdcam experiment colour --raw --photos-csv` (its command in
docs/raw-scenes.md). Standard library only. The result is in docs/raw.md ("What it means,
and what limits it").
"""

import csv
import math
import statistics
import sys
from collections import defaultdict

SETS = ("validation lamps", "test lamps")
MIXED = "mixed-colour LED"


def scored(path):
    """The raw scene photos that were found and score a CCT, with their relative CCT error
    (per cent) and their 95 % half-width (per cent of the estimate)."""
    rows = []
    for r in csv.DictReader(open(path, encoding="utf-8")):
        if r["photo"] != "scene" or r["refused"] != "false" or r["light_named"] != "false":
            continue
        if not (r["estimate_cct_k"] and r["true_cct_k"]):
            continue
        estimate, truth = float(r["estimate_cct_k"]), float(r["true_cct_k"])
        r["error"] = 100.0 * (estimate / truth - 1.0)
        r["half"] = 100.0 * float(r["cct_half95_k"]) / estimate if r["cct_half95_k"] else None
        rows.append(r)
    return rows


def camera_spread(rows):
    """Per lamp type: (lamps, the camera-to-camera standard deviation of the error, per
    cent), from every lamp that one model read through exactly two cameras."""
    pairs = defaultdict(list)
    for r in rows:
        pairs[(r["model"], r["light"])].append(r)
    variances = defaultdict(list)
    for photos in pairs.values():
        if len(photos) == 2 and photos[0]["camera"] != photos[1]["camera"]:
            e1, e2 = photos[0]["error"], photos[1]["error"]
            variances[photos[0]["lamp_type"]].append((e1 - e2) ** 2 / 2.0)
            variances["all"].append((e1 - e2) ** 2 / 2.0)
    return {t: (len(v), math.sqrt(statistics.fmean(v))) for t, v in variances.items()}


def shipped(rows):
    """(photos, median 95 % half-width, share of intervals that hold), per cent."""
    judged = [r for r in rows if r["half"] is not None]
    if not judged:
        return 0, float("nan"), float("nan")
    held = sum(abs(r["error"]) <= r["half"] for r in judged) / len(judged)
    return len(judged), statistics.median(r["half"] for r in judged), 100.0 * held


def main(path):
    rows = scored(path)
    for label in SETS:
        in_set = [r for r in rows if r["set"] == label]
        print(f"{label}:")
        spread = camera_spread(in_set)
        types = sorted({r["lamp_type"] for r in in_set})
        for t in types + ["all"]:
            of_type = [r for r in in_set if t == "all" or r["lamp_type"] == t]
            n, half, held = shipped(of_type)
            lamps, sd = spread.get(t, (0, float("nan")))
            print(f"  {t:22s} photos {n:3d}  shipped ±{half:4.1f} % holding {held:3.0f} %  "
                  f"camera-to-camera SD {sd:4.2f} % over {lamps:2d} lamp readings "
                  f"(95 %: ±{1.96 * sd:4.1f} %)")
        # The median photo's floor: each photo's own lamp type's camera spread.
        floors = [1.96 * spread[r["lamp_type"]][1] for r in in_set if r["lamp_type"] in spread]
        print(f"  median over the photos of their lamp type's ±1.96 SD: "
              f"±{statistics.median(floors):.1f} %")
        for model in sorted({r["model"] for r in in_set}):
            white = [r for r in in_set if r["model"] == model and r["lamp_type"] != MIXED]
            n, half, held = shipped(white)
            signed = statistics.median(r["error"] for r in white)
            absolute = statistics.median(abs(r["error"]) for r in white)
            print(f"  {model}, without the mixed-colour LEDs: {n} photos, CCT error "
                  f"{signed:+.2f} % (absolute {absolute:.2f} %), ±{half:.2f} % holding "
                  f"{held:.0f} %")


if __name__ == "__main__":
    main(sys.argv[1])
