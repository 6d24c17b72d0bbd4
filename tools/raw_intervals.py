"""The CCT and Duv intervals of raw photos, as shipped (`spdcam_infer::measured_colour`).

The rule: the 68th and 95th split-conformal quantiles of the relative CCT error
(|estimate − truth| / truth) and of the Duv error (|estimate − truth|) on the raw scene
photos of the validation split's validation lamps, both charts pooled, the model not told
the light's kind; the test lamps and the white references only report how often the
95 % interval holds and how wide it is.

    python3 tools/raw_intervals.py PHOTOS.csv

PHOTOS.csv: `spdcam experiment colour --raw --photos-csv` (its command in docs/raw-scenes.md).
Standard library only. Prints the four numbers for `RAW_CCT_RELATIVE` and `RAW_DUV` and the
coverage of each set under them.
"""

import csv
import math
import sys


def quantile(values, q):
    """Split-conformal quantile: the ⌈(n + 1) q⌉-th smallest of n values (the largest where
    that exceeds n)."""
    ordered = sorted(values)
    k = min(len(ordered), math.ceil((len(ordered) + 1) * q))
    return ordered[k - 1]


def errors(rows):
    """(relative CCT errors, Duv errors) of the rows that score them."""
    cct = [abs(float(r["estimate_cct_k"]) / float(r["true_cct_k"]) - 1.0)
           for r in rows if r["estimate_cct_k"] and r["true_cct_k"]]
    duv = [abs(float(r["estimate_duv"]) - float(r["true_duv"]))
           for r in rows if r["estimate_duv"] and r["true_duv"]]
    return cct, duv


def main(path):
    rows = [
        r
        for r in csv.DictReader(open(path, encoding="utf-8"))
        if r["photo"] == "scene" and r["refused"] == "false" and r["light_named"] == "false"
    ]
    cct, duv = errors([r for r in rows if r["set"] == "validation lamps"])
    shipped = {
        "cct": [quantile(cct, q) for q in (0.68, 0.95)],
        "duv": [quantile(duv, q) for q in (0.68, 0.95)],
    }
    print(f"validation photos: {len(cct)} with a CCT, {len(duv)} with a Duv")
    print(f"RAW_CCT_RELATIVE = [{shipped['cct'][0]:.4f}, {shipped['cct'][1]:.4f}]")
    print(f"RAW_DUV = [{shipped['duv'][0]:.4f}, {shipped['duv'][1]:.4f}]")
    for label in ("validation lamps", "test lamps", "white references"):
        cct, duv = errors([r for r in rows if r["set"] == label])
        if not cct:
            continue
        held_cct = sum(e <= shipped["cct"][1] for e in cct) / len(cct)
        held_duv = sum(e <= shipped["duv"][1] for e in duv) / len(duv)
        print(f"{label}: the 95 % CCT interval holds {100 * held_cct:.0f} % of {len(cct)}, "
              f"the Duv interval {100 * held_duv:.0f} % of {len(duv)}")


if __name__ == "__main__":
    main(sys.argv[1])
