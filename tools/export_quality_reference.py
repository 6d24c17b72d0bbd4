#!/usr/bin/env python3
"""Reference lighting-quality numbers from independent implementations, for the Rust tests.

Usage (from the repository root):
    pip install colour-science==0.4.7 luxpy==1.12.5 "numpy<2.3" scipy matplotlib
    python tools/export_quality_reference.py LAMPS.csv

LAMPS.csv is a spectral CSV of lamps (wavelength_nm, one column per lamp), e.g. the 221
measured lamps of the IES TM-30 library in the data directory (lamps/ies_tm30_lamps.csv).
Writes, under crates/spdcam-core/tests/reference/:

- quality_lamps.csv: the numbers for every lamp of LAMPS.csv (the measured-data test tier);
- quality_shipped.csv: the numbers for CIE A, D65, D50 (data/illuminants_cie.csv) and the
  colour-science SPDs written to quality_spds.csv (the test tier without a data directory);
- quality_spds.csv: those colour-science SPDs (CIE 015 fluorescent, LED and HP illuminants,
  BSD-3-Clause, see data/LICENSE-colour-science.txt), 380-780 nm at 5 nm.

How each number is computed (the spectrum S is the given samples, Sprague-interpolated by
colour-science to 360-780 nm at 1 nm and zero outside the data, called S1 below):

- cct_k, duv: colour.temperature.uv_to_CCT_Ohno2013 of the CIE 1960 uv of
  colour.sd_to_XYZ(S1, method="Integration") (CIE 1931 2 degree observer).
- cri_ra, cri_r1..r14: colour.colour_rendering_index(S1, additional_data=True) (CIE 13.3-1995).
- tm30_*: colour.quality.colour_fidelity_index_ANSIIESTM3018(S at 5 nm over 380-780 nm,
  additional_data=True) (CIE 224:2017 / ANSI/IES TM-30-18, whose Rf, Rg and hue-bin values
  TM-30-20 keeps): rf, rg, and per hue bin h1..h16 the local fidelity rf_h, chroma shift rcs_h
  (a fraction, colour-science's percentage / 100) and hue shift rhs_h.
- elr_*, der_*: luxpy.toolboxes.photbiochem.spd_to_aopicELR / spd_to_aopicDER of S1 over
  380-780 nm (CIE S 026:2018; ELR in mW/lm; DER against luxpy's own 1 nm CIE D65). luxpy gets
  the 1 nm spectrum because its own interpolation of 5 nm data (cubic spline, negative lobes
  set to 0) differs from Sprague by up to 5 % on line spectra (mercury, fluorescent), a
  difference of resampling conventions, not of the alpha-opic method.
- sp_ratio: colour.luminous_flux(S1, SDS_LEFS_SCOTOPIC, K_m=1700) / colour.luminous_flux(S1).
- ppf_per_lux: PPF per lumen (umol/s/lm) from S1 by its definition, sum over 400-700 nm of
  S lambda / (h c N_A), over 683.002 sum S ybar (numpy).
- blh_kbv: K_B,v in W/lm, sum S B / (683.002 sum S ybar) at 1 nm with B(lambda) of
  ICNIRP 2013 / IEC 62471 built here from its definition (numpy).
- cqs_*: colour.colour_quality_scale(S1, additional_data=True, method="NIST CQS 9.0")
  (W. Davis and Y. Ohno, Optical Engineering 49(3) 033602, 2010; NIST CQS 9.0; its own CCT by
  Ohno 2013 picks the reference, Planckian below 5000 K, CIE daylight from 5000 K): qa, qf,
  qg, and per VS sample q1..q15 (saturation-corrected, scaled 0-100). CQS 9.0 defines no Qp
  and no Qd (colour-science returns None for them), so they have no columns.
"""

from __future__ import annotations

import argparse
import csv
import math
import sys
import warnings
from pathlib import Path

import numpy as np

warnings.filterwarnings("ignore")

import colour  # noqa: E402
from colour.colorimetry import SDS_LEFS_SCOTOPIC  # noqa: E402
from colour.quality import colour_fidelity_index_ANSIIESTM3018  # noqa: E402
from colour.temperature import uv_to_CCT_Ohno2013  # noqa: E402

import luxpy  # noqa: E402
from luxpy.toolboxes import photbiochem  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "crates" / "spdcam-core" / "tests" / "reference"
EXPECTED_COLOUR = "0.4.7"
SHAPE_1NM = colour.SpectralShape(360, 780, 1)
SHAPE_TM30 = colour.SpectralShape(380, 780, 5)
K_M = 683.002
H, C, N_A = 6.62607015e-34, 299792458.0, 6.02214076e23

# The colour-science SPDs shipped for the tests (CIE 015:2018 tables).
SHIPPED_ILLUMINANTS = ["FL2", "FL7", "FL11", "LED-B3", "LED-RGB1", "HP1"]

ALPHA = ["sc", "mc", "lc", "rh", "mel"]
# luxpy orders the S 026 quantities l, m, s, rh, mel.
LUXPY_ORDER = [2, 1, 0, 3, 4]

COLUMNS = (
    ["name", "cct_k", "duv", "cri_ra"]
    + [f"cri_r{i}" for i in range(1, 15)]
    + ["tm30_rf", "tm30_rg"]
    + [f"tm30_rf_h{j}" for j in range(1, 17)]
    + [f"tm30_rcs_h{j}" for j in range(1, 17)]
    + [f"tm30_rhs_h{j}" for j in range(1, 17)]
    + [f"elr_{a}" for a in ALPHA]
    + [f"der_{a}" for a in ALPHA]
    + ["sp_ratio", "ppf_per_lux", "blh_kbv"]
    + ["cqs_qa", "cqs_qf", "cqs_qg"]
    + [f"cqs_q{i}" for i in range(1, 16)]
)


def blue_light_hazard(wl: np.ndarray) -> np.ndarray:
    """B(lambda) of ICNIRP 2013 Table 2 / IEC 62471:2006 Table 4.1, 0 above 700 nm."""
    table_wl = np.arange(300.0, 501.0, 5.0)
    tab = {385: 0.013, 390: 0.025, 395: 0.05, 400: 0.10, 405: 0.20, 410: 0.40, 415: 0.80,
           420: 0.90, 425: 0.95, 430: 0.98, 435: 1.00, 440: 1.00, 445: 0.97, 450: 0.94,
           455: 0.90, 460: 0.80, 465: 0.70, 470: 0.62, 475: 0.55, 480: 0.45, 485: 0.40,
           490: 0.22, 495: 0.16, 500: 10 ** (-1.0)}
    table = np.array([tab.get(int(w), 0.01) for w in table_wl])
    b = np.where(wl <= 500, np.interp(wl, table_wl, table),
                 np.where(wl <= 600, 10 ** ((450 - wl) / 50), 0.001))
    return np.where(wl > 700, 0.0, b)


def read_spectral_csv(path: Path) -> tuple[np.ndarray, list[str], np.ndarray]:
    with open(path, newline="", encoding="utf-8") as f:
        rows = [r for r in csv.reader(f) if r and not r[0].startswith("#")]
    header = rows[0]
    assert header[0] == "wavelength_nm", f"{path}: first column is {header[0]!r}"
    body = np.array([[float(v) for v in r] for r in rows[1:]])
    return body[:, 0], header[1:], body[:, 1:]


def to_1nm(wl: np.ndarray, values: np.ndarray, name: str) -> colour.SpectralDistribution:
    sd = colour.SpectralDistribution(values, wl, name=name)
    return sd.copy().align(
        SHAPE_1NM, extrapolator_kwargs={"method": "Constant", "left": 0, "right": 0}
    )


def metrics(wl: np.ndarray, values: np.ndarray, name: str) -> dict:
    s1 = to_1nm(wl, values, name)
    xyz = colour.sd_to_XYZ(s1, method="Integration")
    cct, duv = uv_to_CCT_Ohno2013(colour.UCS_to_uv(colour.XYZ_to_UCS(xyz)))
    row = {"name": name, "cct_k": cct, "duv": duv}

    cri = colour.colour_rendering_index(s1, additional_data=True)
    row["cri_ra"] = cri.Q_a
    for i in range(1, 15):
        row[f"cri_r{i}"] = cri.Q_as[i].Q_a

    s5 = colour.SpectralDistribution(values, wl, name=name).copy()
    s5 = s5.align(SHAPE_TM30, extrapolator_kwargs={"method": "Constant", "left": 0, "right": 0})
    tm = colour_fidelity_index_ANSIIESTM3018(s5, additional_data=True)
    row["tm30_rf"], row["tm30_rg"] = tm.R_f, tm.R_g
    for j in range(16):
        row[f"tm30_rf_h{j + 1}"] = tm.R_fs[j]
        row[f"tm30_rcs_h{j + 1}"] = tm.R_cs[j] / 100.0
        row[f"tm30_rhs_h{j + 1}"] = tm.R_hs[j]

    inside = s1.wavelengths >= 380
    spd = np.vstack((s1.wavelengths[inside], s1.values[inside]))
    elr = photbiochem.spd_to_aopicELR(spd)[0]
    der = photbiochem.spd_to_aopicDER(spd)[0]
    for k, a in enumerate(ALPHA):
        row[f"elr_{a}"] = 1000.0 * elr[LUXPY_ORDER[k]]
        row[f"der_{a}"] = der[LUXPY_ORDER[k]]

    row["sp_ratio"] = colour.luminous_flux(
        s1, SDS_LEFS_SCOTOPIC["CIE 1951 Scotopic Standard Observer"], K_m=1700
    ) / colour.luminous_flux(s1, K_m=683)
    w1, v1 = s1.wavelengths, s1.values
    ybar = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(SHAPE_1NM).values[:, 1]
    lum = K_M * np.sum(v1 * ybar)
    par = (w1 >= 400) & (w1 <= 700)
    row["ppf_per_lux"] = np.sum(v1[par] * w1[par] * 1e-9 / (H * C * N_A) * 1e6) / lum
    row["blh_kbv"] = np.sum(v1 * blue_light_hazard(w1)) / lum

    cqs = colour.colour_quality_scale(s1, additional_data=True, method="NIST CQS 9.0")
    assert cqs.Q_p is None and cqs.Q_d is None, (name, cqs.Q_p, cqs.Q_d)
    row["cqs_qa"], row["cqs_qf"], row["cqs_qg"] = cqs.Q_a, cqs.Q_f, cqs.Q_g
    for i in range(1, 16):
        row[f"cqs_q{i}"] = cqs.Q_as[i].Q_a
    for k, v in row.items():
        if k != "name":
            row[k] = float(v)
            assert math.isfinite(row[k]), (name, k, v)
    return row


def write_rows(path: Path, description: str, rows: list[dict]) -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="", encoding="utf-8") as f:
        for line in description.strip().splitlines():
            f.write(f"# {line}\n")
        w = csv.writer(f, lineterminator="\n")
        w.writerow(COLUMNS)
        for r in rows:
            w.writerow([r["name"]] + [repr(r[c]) for c in COLUMNS[1:]])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("lamps", type=Path, help="spectral CSV of lamps (one column per lamp)")
    args = parser.parse_args()
    assert colour.__version__ == EXPECTED_COLOUR, f"need colour-science {EXPECTED_COLOUR}"
    versions = f"colour-science {colour.__version__}, luxpy {luxpy.__version__}, numpy {np.__version__}"
    how = (__doc__.split("How each number is computed")[1]).strip()

    wl, names, values = read_spectral_csv(args.lamps)
    rows = [metrics(wl, values[:, i], n) for i, n in enumerate(names)]
    write_rows(
        OUT / "quality_lamps.csv",
        f"Reference lighting-quality numbers of the {len(rows)} lamps of {args.lamps.name}\n"
        f"written by tools/export_quality_reference.py with {versions}.\n"
        "How each number is computed " + how,
        rows,
    )

    # Shipped spectra: CIE A, D65, D50 from data/, colour-science illuminants.
    wl_i, names_i, values_i = read_spectral_csv(ROOT / "data" / "illuminants_cie.csv")
    shipped = [metrics(wl_i, values_i[:, i], n) for i, n in enumerate(names_i)]
    grid = np.arange(380.0, 781.0, 5.0)
    spds = {}
    for key in SHIPPED_ILLUMINANTS:
        sd = colour.SDS_ILLUMINANTS[key].copy().align(
            SHAPE_TM30, extrapolator_kwargs={"method": "Constant", "left": 0, "right": 0}
        )
        assert np.array_equal(sd.wavelengths, grid)
        spds[key] = sd.values
        shipped.append(metrics(grid, sd.values, key))
    with open(OUT / "quality_spds.csv", "w", newline="", encoding="utf-8") as f:
        f.write(
            "# CIE 015:2018 illuminants "
            + ", ".join(SHIPPED_ILLUMINANTS)
            + f" from colour-science {colour.__version__} (colour.SDS_ILLUMINANTS, BSD-3-Clause),\n"
            "# on 380-780 nm at 5 nm (Sprague-aligned where the table is finer or wider);\n"
            "# written by tools/export_quality_reference.py.\n"
        )
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["wavelength_nm"] + SHIPPED_ILLUMINANTS)
        for i, x in enumerate(grid):
            w.writerow([str(int(x))] + [repr(float(spds[k][i])) for k in SHIPPED_ILLUMINANTS])
    write_rows(
        OUT / "quality_shipped.csv",
        "Reference lighting-quality numbers of CIE A, D65, D50 (data/illuminants_cie.csv) and of\n"
        "the spectra of quality_spds.csv, written by tools/export_quality_reference.py with\n"
        f"{versions}.\nHow each number is computed " + how,
        shipped,
    )
    print(f"wrote {len(rows)} lamps and {len(shipped)} shipped spectra to {OUT}", file=sys.stderr)


if __name__ == "__main__":
    main()
