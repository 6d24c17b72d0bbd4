#!/usr/bin/env python3
"""How much glare the real photo sets carry, read from their features alone (no labels).

Usage:
    python3 tools/real_glare.py [DATA_DIR]      # DATA_DIR defaults to ../shared/data

For each photo of the SG sets the data directory's `thesis/measured/` holds (the sets a
model may be chosen on: Telelumen/Canon dev, Hue/Canon train, Telelumen/tablet train), the
green channel of each of the 96 patches is decoded to linear light (IEC 61966-2-1) and set
against what the chart's reflectance alone gives, scaled to the photo's mean:
excess = linear − mean · reflectance ÷ mean reflectance (reflectance averaged over
400–700 nm). Printed as shares of the photo's mean linear level, median (10th–90th
percentile) over the photos:

- veil: the median excess of the eight dark patches (reflectance below 0.06) other than
  the blackest — the glare laid over the whole chart;
- local: the blackest patch's excess (reflectance 0.007; row 5, column 4 of the 8 × 12
  centre) above that veil — the glow a lamp beside the chart lays on part of it.

`spdcam generate --randomise glow` draws glows up to the largest local value
(`docs/glow.md`). The JPEG tone curve is undone as plain sRGB, so these are estimates.
"""

from __future__ import annotations

import csv
import statistics as st
import sys
from pathlib import Path

SETS = [
    ("Telelumen, Canon 5D IV (dev)", "telelumen_canon5d4_dev"),
    ("Philips Hue, Canon 5D IV (train)", "hue_canon5d4_train"),
    ("Telelumen, Galaxy Tab S7 (train)", "telelumen_galaxy_tab_s7_train"),
]


def linear(v: float) -> float:
    """The sRGB decoding of a 0–255 value (IEC 61966-2-1)."""
    v /= 255.0
    return v / 12.92 if v <= 0.04045 else ((v + 0.055) / 1.055) ** 2.4


def feature_reflectances(data: Path) -> list[float]:
    """Mean 400–700 nm reflectance of each feature patch (row by row; the file runs column
    by column: feature patch 12·r + c is column 8·c + r)."""
    with open(data / "thesis" / "colorchecker_digital_sg_96_i1pro2.csv") as f:
        rows = [list(map(float, r)) for r in list(csv.reader(f))[1:]]
    visible = [r for r in rows if 400 <= r[0] <= 700]
    column = [st.mean(r[j] for r in visible) for j in range(1, 97)]
    return [column[8 * (k % 12) + k // 12] for k in range(96)]


def quantiles(values: list[float]) -> str:
    s = sorted(values)
    q = lambda p: s[round(p * (len(s) - 1))]  # noqa: E731
    return f"{q(0.5):.2f} ({q(0.1):.2f}–{q(0.9):.2f})"


def main() -> None:
    data = Path(sys.argv[1] if len(sys.argv) > 1 else "../shared/data")
    refl = feature_reflectances(data)
    black = min(range(96), key=lambda k: refl[k])
    dark = [k for k in range(96) if refl[k] < 0.06 and k != black]
    mean_refl = st.mean(refl)
    print("| photos | n | veil | local | local, largest |")
    print("|---|---:|---:|---:|---:|")
    for label, folder in SETS:
        with open(data / "thesis" / "measured" / folder / "features.csv") as f:
            photos = [list(map(float, r)) for r in list(csv.reader(f))[1:]]
        veils, locals_ = [], []
        for features in photos:
            green = [linear(features[3 * k + 1]) for k in range(96)]
            mean = st.mean(green)
            excess = [g - mean * r / mean_refl for g, r in zip(green, refl)]
            veil = st.median(excess[k] for k in dark)
            veils.append(veil / mean)
            locals_.append((excess[black] - veil) / mean)
        print(
            f"| {label} | {len(photos)} | {quantiles(veils)} | {quantiles(locals_)} "
            f"| {max(locals_):.2f} |"
        )


if __name__ == "__main__":
    main()
