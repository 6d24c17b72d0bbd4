"""The CCT and Duv intervals of raw photos, by the estimate's own colour fidelity.

A raw photo's light colour is read through the file's 3×3 colour matrices, which are nearly
exact for smooth lights (incandescent, daylight) and err for spiky ones (LEDs,
fluorescents). The estimate's own TM-30 Rf says which kind the photo shows. The rule,
fixed before looking at the numbers: two groups split at the median Rf of the validation
lamps' raw scene photos (both charts pooled); each group's 68 % and 95 % half-widths are the
split-conformal quantiles of its validation photos' relative CCT errors; the test lamps only
report coverage and width. (The Duv interval stays pooled: the CSV holds no Duv.)

    python3 tools/raw_interval_choice.py PHOTOS.csv

PHOTOS.csv: `spdcam experiment colour --raw --photos-csv` (its command in docs/raw-scenes.md).
Standard library only.

Result (seed 1, the shipped models): the validation photos' median Rf is 81.2; the rule
widens the validation lamps' median 95 % half-width to ±10.0 % (pooled ±9.4 %) and holds
92 % on the test lamps at ±8.6 % (pooled 90 % at ±9.4 %). Not kept: the mixed-colour LEDs,
whose CCT the matrices read worst (median error 6–8 %), have estimates of high Rf (84–88),
so the high group is not the well-read one. docs/raw.md says so.
"""

import csv
import statistics
import sys

from raw_intervals import quantile


def main(path):
    rows = [
        r
        for r in csv.DictReader(open(path, encoding="utf-8"))
        if r["photo"] == "scene" and r["refused"] == "false" and r["true_cct_k"] and r["estimate_cct_k"]
        and r["estimate_rf"] and r["light_named"] == "false"
    ]
    for r in rows:
        r["rel"] = abs(float(r["estimate_cct_k"]) / float(r["true_cct_k"]) - 1.0)
        r["rf"] = float(r["estimate_rf"])
    validation = [r for r in rows if r["set"] == "validation lamps"]
    split = statistics.median(r["rf"] for r in validation)
    print(f"validation photos {len(validation)}; median estimate Rf {split:.2f}")
    groups = {}
    for name, member in (("high", lambda r: r["rf"] >= split), ("low", lambda r: r["rf"] < split)):
        errors = [r["rel"] for r in validation if member(r)]
        groups[name] = (member, quantile(errors, 0.68), quantile(errors, 0.95), len(errors))
        print(f"  Rf {'≥' if name == 'high' else '<'} {split:.2f}: {len(errors)} photos, "
              f"68 % {groups[name][1]:.4f}, 95 % {groups[name][2]:.4f}")
    pooled = [quantile([r["rel"] for r in validation], q) for q in (0.68, 0.95)]
    print(f"  pooled: 68 % {pooled[0]:.4f}, 95 % {pooled[1]:.4f}")
    for label in ("validation lamps", "test lamps", "white references"):
        subset = [r for r in rows if r["set"] == label]
        if not subset:
            continue
        widths, held = [], 0
        pooled_held = 0
        for r in subset:
            half = next(g[2] for g in groups.values() if g[0](r))
            widths.append(half)
            held += r["rel"] <= half
            pooled_held += r["rel"] <= pooled[1]
        n = len(subset)
        print(f"{label} ({n}): by Rf median half-width ±{100 * statistics.median(widths):.1f} %, "
              f"holds {100 * held / n:.0f} %; pooled ±{100 * pooled[1]:.1f} %, holds "
              f"{100 * pooled_held / n:.0f} %")
        for kind in sorted({r["lamp_type"] for r in subset}):
            k = [r for r in subset if r["lamp_type"] == kind]
            w = [next(g[2] for g in groups.values() if g[0](r)) for r in k]
            h = sum(r["rel"] <= next(g[2] for g in groups.values() if g[0](r)) for r in k)
            print(f"    {kind} ({len(k)}): median Rf {statistics.median(r['rf'] for r in k):.1f}, "
                  f"median error {100 * statistics.median(r['rel'] for r in k):.1f} %, "
                  f"half-width ±{100 * statistics.median(w):.1f} %, holds {100 * h / len(k):.0f} %")


if __name__ == "__main__":
    main(sys.argv[1])
