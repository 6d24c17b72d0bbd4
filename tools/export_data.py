#!/usr/bin/env python3
"""Export spectral data sets from colour-science 0.4.7 to data/*.csv.

Usage (from the repository root):
    pip install colour-science==0.4.7 scipy
    python tools/export_data.py

Writes data/*.csv, data/PROVENANCE.md and data/LICENSE-colour-science.txt.
The CSV layout is: one header row, first column `wavelength_nm` (strictly
increasing), then one column per item; values are Python float reprs.
"""

from __future__ import annotations

import warnings
from importlib import metadata
from pathlib import Path

import numpy as np

warnings.filterwarnings("ignore")

import colour  # noqa: E402
from colour.colorimetry.datasets.illuminants.sds_d_illuminant_series import (  # noqa: E402
    SDS_BASIS_FUNCTIONS_CIE_ILLUMINANT_D_SERIES,
)
from colour.quality.cfi2017 import load_TCS_CIE2017  # noqa: E402

EXPECTED_VERSION = "0.4.7"
ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "data"

PATCH_NAMES_OHTA = [
    "dark skin", "light skin", "blue sky", "foliage", "blue flower",
    "bluish green", "orange", "purplish blue", "moderate red", "purple",
    "yellow green", "orange yellow", "blue", "green", "red", "yellow",
    "magenta", "cyan", "white 9.5 (.05 D)", "neutral 8 (.23 D)",
    "neutral 6.5 (.44 D)", "neutral 5 (.70 D)", "neutral 3.5 (1.05 D)",
    "black 2 (1.5 D)",
]


def fmt_wl(w: float) -> str:
    w = float(w)
    return str(int(w)) if w.is_integer() else repr(w)


def write_csv(name: str, wavelengths, columns: dict[str, np.ndarray]) -> str:
    wl = np.asarray(wavelengths, dtype=float)
    assert wl.ndim == 1 and np.all(np.diff(wl) > 0), name
    for key, col in columns.items():
        col = np.asarray(col, dtype=float)
        assert col.shape == wl.shape, (name, key)
        assert np.all(np.isfinite(col)), (name, key)
    lines = [",".join(["wavelength_nm", *columns.keys()])]
    for i, w in enumerate(wl):
        row = [fmt_wl(w)] + [repr(float(c[i])) for c in columns.values()]
        lines.append(",".join(row))
    (DATA / name).write_text("\n".join(lines) + "\n", encoding="utf-8")
    return f"{fmt_wl(wl[0])}–{fmt_wl(wl[-1])} nm, {fmt_wl(wl[1] - wl[0])} nm step, {len(wl)} rows"


def main() -> None:
    version = colour.__version__
    assert version == EXPECTED_VERSION, f"need colour-science {EXPECTED_VERSION}, got {version}"
    DATA.mkdir(exist_ok=True)
    src = f"colour-science {version} (PyPI)"
    prov: list[str] = []

    # CIE 1931 2° CMF, native 360–830 nm at 1 nm.
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    s = write_csv(
        "cie_1931_2deg_cmf.csv", cmfs.wavelengths,
        {"x_bar": cmfs.values[:, 0], "y_bar": cmfs.values[:, 1], "z_bar": cmfs.values[:, 2]},
    )
    prov.append(
        "## cie_1931_2deg_cmf.csv\n\n"
        "- Columns: `wavelength_nm,x_bar,y_bar,z_bar`\n"
        f"- Source: {src}, `colour.MSDS_CMFS['CIE 1931 2 Degree Standard Observer']`"
        " (CIE 1931 2° standard observer, CIE tabulation).\n"
        f"- Sampling: native, {s}.\n"
        "- Processing: none (values written as stored).\n"
    )

    # Illuminants D65, A, D50 on 300–780 nm at 5 nm.
    shape = colour.SpectralShape(300, 780, 5)
    wl = shape.wavelengths
    d65 = colour.SDS_ILLUMINANTS["D65"]
    d50 = colour.SDS_ILLUMINANTS["D50"]
    for sd in (d65, d50):
        assert sd.shape == shape, sd.shape
        assert np.array_equal(sd.wavelengths, wl)
    a = colour.sd_CIE_standard_illuminant_A(shape)
    s = write_csv("illuminants_cie.csv", wl, {"D65": d65.values, "A": a.values, "D50": d50.values})
    prov.append(
        "## illuminants_cie.csv\n\n"
        "- Columns: `wavelength_nm,D65,A,D50`\n"
        f"- Source: {src}. D65: `colour.SDS_ILLUMINANTS['D65']`; D50: "
        "`colour.SDS_ILLUMINANTS['D50']` (CIE tabulated relative SPDs, normalised to 100 at 560 nm); "
        "A: `colour.sd_CIE_standard_illuminant_A(colour.SpectralShape(300, 780, 5))`, i.e. the "
        "CIE 015 formula S(λ) = 100 (560/λ)^5 (exp(1.435e7/(2848·560)) − 1) / (exp(1.435e7/(2848·λ)) − 1), "
        "evaluated in double precision (not rounded to the 6-digit CIE table).\n"
        f"- Sampling: {s}. D65 and D50 are stored by colour-science on exactly 300–780 nm at 5 nm, so "
        "the tabulated values are written unchanged (no interpolation or extrapolation; the script "
        "asserts that the stored shape equals SpectralShape(300, 780, 5)). In the CIE 5 nm D-series "
        "tables the values at odd multiples of 5 nm are linear interpolations of the 10 nm values.\n"
        "- Processing: none beyond the above.\n"
    )

    # CIE daylight basis functions S0, S1, S2.
    b = SDS_BASIS_FUNCTIONS_CIE_ILLUMINANT_D_SERIES
    assert b["S0"].shape == b["S1"].shape == b["S2"].shape
    s = write_csv(
        "cie_daylight_basis.csv", b["S0"].wavelengths,
        {"S0": b["S0"].values, "S1": b["S1"].values, "S2": b["S2"].values},
    )
    prov.append(
        "## cie_daylight_basis.csv\n\n"
        "- Columns: `wavelength_nm,S0,S1,S2`\n"
        f"- Source: {src}, `colour.colorimetry.datasets.illuminants.sds_d_illuminant_series."
        "SDS_BASIS_FUNCTIONS_CIE_ILLUMINANT_D_SERIES['S0'|'S1'|'S2']` (CIE 015 components of daylight).\n"
        f"- Sampling: native as stored, {s}. The CIE publishes these at 10 nm; the stored values at "
        "odd multiples of 5 nm are the linear interpolations recommended by CIE 015.\n"
        "- Processing: none. A D-series SPD is S0 + M1·S1 + M2·S2 with "
        "M = 0.0241 + 0.2562x − 0.7341y, M1 = (−1.3515 − 1.7703x + 5.9114y)/M, "
        "M2 = (0.0300 − 31.4424x + 30.0717y)/M (CIE 015; M1, M2 rounded to 3 decimals).\n"
    )

    # ColorChecker N Ohta.
    cc = colour.SDS_COLOURCHECKERS["ColorChecker N Ohta"]
    names = list(cc.keys())
    assert names == PATCH_NAMES_OHTA, names
    wl_cc = cc[names[0]].wavelengths
    cols = {}
    for i, n in enumerate(names):
        assert np.array_equal(cc[n].wavelengths, wl_cc)
        cols[f"p{i + 1:02d}"] = cc[n].values
    s = write_csv("colorchecker24.csv", wl_cc, cols)
    patch_list = "\n".join(f"  - `p{i + 1:02d}`: {n}" for i, n in enumerate(names))
    prov.append(
        "## colorchecker24.csv\n\n"
        "- Columns: `wavelength_nm,p01,...,p24`\n"
        f"- Source: {src}, `colour.SDS_COLOURCHECKERS['ColorChecker N Ohta']` (spectral reflectance "
        "factors of the ColorChecker measured by N. Ohta), in the standard chart order (row by row, "
        "top-left dark skin to bottom-right black).\n"
        f"- Sampling: native, {s}.\n"
        "- Processing: none. Patch names (colour-science keys):\n"
        f"{patch_list}\n"
    )

    # Camera sensitivities.
    for key, fname in (
        ("Nikon 5100 (NPL)", "camera_nikon_d5100_npl.csv"),
        ("Sigma SDMerill (NPL)", "camera_sigma_sd_merrill_npl.csv"),
    ):
        m = colour.MSDS_CAMERA_SENSITIVITIES[key]
        assert list(m.labels) == ["red", "green", "blue"], m.labels
        s = write_csv(fname, m.wavelengths, {"r": m.values[:, 0], "g": m.values[:, 1], "b": m.values[:, 2]})
        prov.append(
            f"## {fname}\n\n"
            "- Columns: `wavelength_nm,r,g,b`\n"
            f"- Source: {src}, `colour.MSDS_CAMERA_SENSITIVITIES['{key}']` (labels red, green, blue; "
            "camera spectral sensitivities measured by the UK National Physical Laboratory, as "
            "distributed with colour-science)."
            + (" Note the key spelling `SDMerill` (sic)." if "SDMerill" in key else "")
            + "\n"
            f"- Sampling: native, {s}.\n"
            "- Processing: none (values as stored; each channel is normalised by colour-science to a peak of 1).\n"
        )

    # CIE 2017 / TM-30 colour evaluation samples.
    tcs = load_TCS_CIE2017(colour.SpectralShape(380, 780, 5))
    assert len(tcs.labels) == 99
    assert list(tcs.labels) == [f"TCS{i} (CIE 2017)" for i in range(99)]
    s = write_csv("tm30_ces99.csv", tcs.wavelengths, {f"ces{i + 1:02d}": tcs.values[:, i] for i in range(99)})
    prov.append(
        "## tm30_ces99.csv\n\n"
        "- Columns: `wavelength_nm,ces01,...,ces99`\n"
        f"- Source: {src}, `colour.quality.cfi2017.load_TCS_CIE2017(colour.SpectralShape(380, 780, 5))`, "
        "which reads the package file `colour/quality/datasets/tcs_cfi2017_5_nm.csv.gz` "
        "(the 99 colour evaluation samples of CIE 224:2017 / ANSI/IES TM-30). colour-science labels "
        "them `TCS0 (CIE 2017)` … `TCS98 (CIE 2017)`; here `cesNN` = `TCS{NN-1}`, i.e. ces01 = TCS0.\n"
        f"- Sampling: {s} (the 5 nm file of the package; it also ships a 1 nm file over "
        "380–780 nm whose every 5th row equals the 5 nm file exactly).\n"
        "- Processing: none.\n"
    )

    # Licence.
    dist = metadata.distribution("colour-science")
    lic_files = [f for f in (dist.files or []) if f.name == "LICENSE"]
    assert lic_files, "LICENSE not found in colour-science metadata"
    lic = lic_files[0].read_text(encoding="utf-8").rstrip("\n") + "\n"
    (DATA / "LICENSE-colour-science.txt").write_text(lic, encoding="utf-8")

    header = (
        "# Provenance of data/\n\n"
        f"The files down to the lighting-quality section were generated by `tools/export_data.py` from the Python package "
        f"colour-science {version} (https://www.colour-science.org, PyPI `colour-science=={version}`).\n\n"
        "Licence: colour-science is distributed under the BSD-3-Clause licence "
        "(Copyright 2013 Colour Developers); its text is in `LICENSE-colour-science.txt`. "
        "The underlying CIE data (colour matching functions, standard illuminants, daylight basis "
        "functions, CIE 2017 colour evaluation samples) are CIE tables as published by the CIE and "
        "redistributed by colour-science; the ColorChecker reflectances are N. Ohta's measurements and "
        "the camera sensitivities are NPL measurements, both as redistributed by colour-science.\n\n"
        "CSV layout: one header row; first column `wavelength_nm` strictly increasing; one column per "
        "item; values are shortest round-trip decimal representations of the IEEE-754 doubles held by "
        "colour-science; no comment lines. No file was resampled.\n\n"
    )
    # Keep the section tools/export_quality_data.py maintains after its marker line.
    path = DATA / "PROVENANCE.md"
    marker = "<!-- lighting-quality tables: tools/export_quality_data.py -->"
    old = path.read_text(encoding="utf-8") if path.is_file() else ""
    kept = "\n" + marker + old.split(marker, 1)[1] if marker in old else ""
    path.write_text(header + "\n".join(prov) + kept, encoding="utf-8")
    print("wrote", sorted(p.name for p in DATA.iterdir()))


if __name__ == "__main__":
    main()
