#!/usr/bin/env python3
"""Time colour-science computing the lighting-quality metrics spdcam computes, per SPD.

Usage:
    pip install colour-science==0.4.7 scipy
    python tools/baseline_quality.py SPDS.csv

SPDS.csv is a spectral CSV (wavelength_nm, one column per SPD; the quality benchmark
`cargo bench -p spdcam-core --bench quality` writes one and runs this script on it). For every
SPD: CCT and Duv (Ohno 2013), CIE 13.3 Ra and R1-R14 (colour_rendering_index), CIE 2017 /
TM-30 Rf, Rg and hue bins (colour_fidelity_index_ANSIIESTM3018), S/P ratio
(luminous_flux), and the CIE S 026 alpha-opic ratios, PPF per lumen and blue-light hazard
efficacy as numpy dot products with the shipped tables of data/. Prints
`seconds_per_spd <s>` and `cpu_seconds_per_spd <s>` (mean wall and process CPU time per SPD)
on stdout.
"""

from __future__ import annotations

import csv
import sys
import time
import warnings
from pathlib import Path

import numpy as np

warnings.filterwarnings("ignore")

import colour  # noqa: E402
from colour.colorimetry import SDS_LEFS_SCOTOPIC  # noqa: E402
from colour.quality import colour_fidelity_index_ANSIIESTM3018  # noqa: E402
from colour.temperature import uv_to_CCT_Ohno2013  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
SHAPE_1NM = colour.SpectralShape(360, 780, 1)
SHAPE_TM30 = colour.SpectralShape(380, 780, 5)


def read(path: Path) -> tuple[np.ndarray, np.ndarray]:
    with open(path, newline="", encoding="utf-8") as f:
        rows = [r for r in csv.reader(f) if r and not r[0].startswith("#")]
    body = np.array([[float(v) for v in r] for r in rows[1:]])
    return body[:, 0], body[:, 1:]


def table_1nm(name: str) -> np.ndarray:
    """A shipped 1 nm table's columns on 360-780 nm, zero outside its range."""
    wl, values = read(ROOT / "data" / name)
    grid = np.arange(360.0, 781.0)
    return np.stack([np.interp(grid, wl, v, left=0.0, right=0.0) for v in values.T], axis=1)


def main() -> None:
    wl, spds = read(Path(sys.argv[1]))
    alpha = table_1nm("cie_s026_alpha_opic.csv")
    blh = table_1nm("blue_light_hazard.csv")[:, 0]
    ybar = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(SHAPE_1NM).values[:, 1]
    w1 = np.arange(360.0, 781.0)
    par = np.where((w1 >= 400) & (w1 <= 700), w1 * 1e-9 / (6.62607015e-34 * 299792458.0 * 6.02214076e23) * 1e6, 0.0)
    scotopic = SDS_LEFS_SCOTOPIC["CIE 1951 Scotopic Standard Observer"]
    sink = 0.0
    start, cpu_start = time.perf_counter(), time.process_time()
    for i in range(spds.shape[1]):
        sd = colour.SpectralDistribution(spds[:, i], wl)
        s1 = sd.copy().align(SHAPE_1NM, extrapolator_kwargs={"method": "Constant", "left": 0, "right": 0})
        xyz = colour.sd_to_XYZ(s1, method="Integration")
        cct, duv = uv_to_CCT_Ohno2013(colour.UCS_to_uv(colour.XYZ_to_UCS(xyz)))
        cri = colour.colour_rendering_index(s1, additional_data=True)
        s5 = sd.copy().align(SHAPE_TM30, extrapolator_kwargs={"method": "Constant", "left": 0, "right": 0})
        tm = colour_fidelity_index_ANSIIESTM3018(s5, additional_data=True)
        sp = colour.luminous_flux(s1, scotopic, K_m=1700) / colour.luminous_flux(s1, K_m=683)
        lum = 683.002 * (s1.values @ ybar)
        aopic = (s1.values @ alpha) / lum
        sink += cct + duv + cri.Q_a + tm.R_f + tm.R_g + sp + aopic.sum() + (s1.values @ par) / lum + (s1.values @ blh) / lum
    elapsed, cpu = time.perf_counter() - start, time.process_time() - cpu_start
    assert np.isfinite(sink)
    print(f"seconds_per_spd {elapsed / spds.shape[1]:.6g}")
    print(f"cpu_seconds_per_spd {cpu / spds.shape[1]:.6g}")


if __name__ == "__main__":
    main()
