#!/usr/bin/env python3
"""How the verdict's local GFC margin was chosen, from the calibration photos' records.

Usage:
    spdcam trust calibrate --real --scenes 4 … -o /tmp/cal --records /tmp/records
    python3 tools/local_margin_choice.py /tmp/records/colorchecker_sg96.calibration-photos.csv

An estimate is `ok` only where 95 % of estimates like it reach GFC 0.90: where its expected
1 − GFC times the 95 % margin stays below 0.10 (and the expected GFC is at least 0.95). The
pooled margin is the largest of each kind of calibration photo's 95 % quantile (virtual,
scene, real). A local margin takes the quantile among the K calibration photos nearest to
the photo in standardised coordinates (localised conformal prediction; Guan 2023,
Biometrika 110: 33–50). Each photo is judged here by neighbours from other lamps only (each
real photo is its own group), with its held-out residual, so the counts are cross-validated.

The rule, fixed with the candidates: a candidate is admissible when no kind of photo has more
`ok` photos below GFC 0.90 than under the pooled margin; among the admissible, the one that
lets the most photos of GFC >= 0.95 be `ok` wins.
"""

from __future__ import annotations

import csv
import math
import sys
from collections import defaultdict

CANDIDATES = [
    ("difficulty, expected gap, CCT, self-check", ["ld", "lg", "cct", "sc"]),
    ("the same and the veil", ["ld", "lg", "cct", "sc", "veil"]),
    ("difficulty, expected gap, CCT", ["ld", "lg", "cct"]),
    ("expected gap, CCT, self-check, veil", ["lg", "cct", "sc", "veil"]),
]
NEIGHBOURS = [30, 50, 100]


def conformal_q95(values: list[float]) -> float:
    """The ⌈(n+1)·0.95⌉-th smallest, the largest where that lies beyond them."""
    v = sorted(values)
    return v[min(math.ceil((len(v) + 1) * 0.95), len(v)) - 1]


def read(path: str) -> list[dict]:
    photos = []
    for r in csv.DictReader(open(path)):
        if not r["cct_k"] or not r["self_check_mean"]:
            continue
        expected = float(r["expected_gfc"])
        kind = r["source"] if r["source"] in ("virtual", "scene") else "real"
        photos.append(
            {
                "kind": kind,
                "group": (kind == "real", int(r["group"])),
                "expected": expected,
                "gfc": float(r["gfc"]),
                "residual": float(r["held_out_residual"]),
                "x": {
                    "ld": math.log(float(r["difficulty"])),
                    "lg": math.log(max(1 - expected, 1e-5)),
                    "cct": math.log(float(r["cct_k"])),
                    "sc": math.log(float(r["self_check_mean"])),
                    "veil": float(r["veil"] or 0),
                },
            }
        )
    return photos


def judge(photos: list[dict], margin_of) -> dict:
    """Per kind: photos, ok, ok below GFC 0.90, ok among GFC >= 0.95, photos of GFC >= 0.95."""
    out = defaultdict(lambda: [0, 0, 0, 0, 0])
    for i, p in enumerate(photos):
        margin = max(margin_of(i), 0.0)
        ok = p["expected"] >= 0.95 and 1 - (1 - p["expected"]) * math.exp(margin) >= 0.90
        s = out[p["kind"]]
        s[0] += 1
        s[1] += ok
        s[2] += ok and p["gfc"] < 0.90
        s[3] += ok and p["gfc"] >= 0.95
        s[4] += p["gfc"] >= 0.95
    return out


def main() -> None:
    photos = read(sys.argv[1] if len(sys.argv) > 1 else "calibration-photos.csv")
    by_kind = defaultdict(list)
    for p in photos:
        by_kind[p["kind"]].append(p["residual"])
    pooled = max(conformal_q95(v) for v in by_kind.values() if len(v) >= 30)
    base = judge(photos, lambda i: pooled)
    kinds = sorted(base)
    print("| margin | K | " + " | ".join(f"{k}: ok (GFC < 0.90)" for k in kinds) + " | ok of GFC ≥ 0.95 |")
    print("|---|---:|" + "---:|" * (len(kinds) + 1))

    def row(name: str, k: str, result: dict) -> int:
        cells = " | ".join(f"{result[c][1]} ({result[c][2]})" for c in kinds)
        good = sum(result[c][3] for c in kinds)
        total = sum(result[c][4] for c in kinds)
        print(f"| {name} | {k} | {cells} | {good} of {total} |")
        return good

    row("pooled", "–", base)
    best = None
    for name, keys in CANDIDATES:
        z = [[p["x"][k] for k in keys] for p in photos]
        d = len(keys)
        mean = [sum(r[j] for r in z) / len(z) for j in range(d)]
        sd = [max(math.sqrt(sum((r[j] - mean[j]) ** 2 for r in z) / len(z)), 1e-9) for j in range(d)]
        z = [[(r[j] - mean[j]) / sd[j] for j in range(d)] for r in z]
        order = []
        for i in range(len(photos)):
            others = [o for o in range(len(photos)) if photos[o]["group"] != photos[i]["group"]]
            others.sort(key=lambda o: sum((a - b) ** 2 for a, b in zip(z[o], z[i])))
            order.append(others)
        for k in NEIGHBOURS:
            result = judge(
                photos, lambda i: conformal_q95([photos[o]["residual"] for o in order[i][:k]])
            )
            good = row(name, str(k), result)
            admissible = all(result[c][2] <= base[c][2] for c in kinds)
            if admissible and (best is None or good > best[0]):
                best = (good, name, k)
    print(f"\nchosen: {best[1]}, K = {best[2]}" if best else "\nnone admissible: the pooled margin")


if __name__ == "__main__":
    main()
