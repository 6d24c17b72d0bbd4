#!/usr/bin/env python3
"""Export the tables the lighting-quality metrics need to data/*.csv.

Usage (from the repository root):
    pip install colour-science==0.4.7 scipy
    pip install --no-deps pysilsub==0.1.1
    python tools/export_quality_data.py

Writes data/cie_1964_10deg_cmf.csv, data/cie_1995_tcs14.csv, data/cie_2024_tcs15.csv,
data/cie_1951_scotopic.csv, data/cie_s026_alpha_opic.csv, data/blue_light_hazard.csv and
data/LICENSE-pysilsub.txt, and replaces the lighting-quality section of data/PROVENANCE.md
(everything from QUALITY_MARKER on; tools/export_data.py keeps that section when it rewrites the file).

Sources: colour-science (BSD-3-Clause) for the CIE observers and test colour samples;
pysilsub (MIT) for the CIE S 026:2018 action spectra, cross-checked here against the CIE 2006
cone fundamentals and the CIE 1951 scotopic function of colour-science; the blue-light hazard
function is the table of ICNIRP (2013) / IEC 62471:2006, written out below.
"""

from __future__ import annotations

import importlib.util
import warnings
from importlib import metadata
from pathlib import Path

import numpy as np

warnings.filterwarnings("ignore")

import colour  # noqa: E402
from colour.colorimetry import MSDS_CMFS_LMS, SDS_LEFS_SCOTOPIC  # noqa: E402
from colour.quality.datasets.tcs import SDS_TCS  # noqa: E402

EXPECTED_COLOUR = "0.4.7"
EXPECTED_PYSILSUB = "0.1.1"
ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "data"
QUALITY_MARKER = "<!-- lighting-quality tables: tools/export_quality_data.py -->"

# ICNIRP (2013), "Guidelines on limits of exposure to incoherent visible and infrared
# radiation", Health Physics 105(1), 74–96, Table 2 = IEC 62471:2006 Table 4.1: the blue-light
# hazard function B(λ) at 5 nm from 300 to 500 nm; 10^((450 − λ)/50) from 500 to 600 nm;
# 0.001 from 600 to 700 nm.
BLH_TABLE_300_500 = {
    **{w: 0.01 for w in range(300, 381, 5)},
    385: 0.013, 390: 0.025, 395: 0.05, 400: 0.10, 405: 0.20, 410: 0.40, 415: 0.80,
    420: 0.90, 425: 0.95, 430: 0.98, 435: 1.00, 440: 1.00, 445: 0.97, 450: 0.94,
    455: 0.90, 460: 0.80, 465: 0.70, 470: 0.62, 475: 0.55, 480: 0.45, 485: 0.40,
    490: 0.22, 495: 0.16, 500: 10 ** ((450 - 500) / 50),
}


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


def pysilsub_dir() -> Path:
    """The installed pysilsub package directory, found without importing it (its imports pull
    in plotting libraries the export does not need)."""
    version = metadata.version("pysilsub")
    assert version == EXPECTED_PYSILSUB, f"need pysilsub {EXPECTED_PYSILSUB}, got {version}"
    spec = importlib.util.find_spec("pysilsub")
    assert spec is not None and spec.origin is not None, "pysilsub is not installed"
    return Path(spec.origin).parent


def alpha_opic(src: str) -> tuple[list[str], str]:
    """CIE S 026:2018 action spectra, checked against colour-science's CIE tables."""
    path = pysilsub_dir() / "data" / "CIES026.csv"
    rows = path.read_text(encoding="utf-8").strip().splitlines()
    assert rows[0].strip() == "Wavelength,sc,mc,lc,rh,mel", rows[0]
    table = np.array([[float(v) for v in r.split(",")] for r in rows[1:]])
    wl = table[:, 0]
    assert np.array_equal(wl, np.arange(380.0, 781.0)), "CIES026.csv is not 380–780 nm at 1 nm"
    cols = {k: table[:, i + 1] for i, k in enumerate(("sc", "mc", "lc", "rh", "mel"))}

    # The cone spectra of S 026 are the CIE 2006 10° cone fundamentals (CIE 170-1:2006,
    # energy, peak 1), zero below 390 nm; rhodopic is the CIE 1951 scotopic V'(λ).
    lms = MSDS_CMFS_LMS["Stockman & Sharpe 10 Degree Cone Fundamentals"]
    inside = (lms.wavelengths >= 390) & (lms.wavelengths <= 780)
    for i, key in enumerate(("lc", "mc", "sc")):
        ref = lms.values[inside, i]
        diff = np.abs(cols[key][wl >= 390] - ref).max()
        assert diff <= 5.01e-6, (key, diff)
        assert np.all(cols[key][wl < 390] == 0.0), key
    vprime = SDS_LEFS_SCOTOPIC["CIE 1951 Scotopic Standard Observer"]
    assert np.array_equal(vprime.wavelengths, wl)
    assert np.abs(cols["rh"] - vprime.values).max() <= 1e-7
    assert abs(wl[np.argmax(cols["mel"])] - 490) <= 1, "melanopic peak is not at 490 nm"
    s = write_csv("cie_s026_alpha_opic.csv", wl, cols)

    lic = (pysilsub_dir().parent / "pysilsub-0.1.1.dist-info" / "LICENSE")
    if not lic.is_file():
        dist = metadata.distribution("pysilsub")
        found = [f for f in (dist.files or []) if f.name.upper().startswith("LICENSE")]
        assert found, "pysilsub LICENSE not found"
        lic = Path(found[0].locate())
    (DATA / "LICENSE-pysilsub.txt").write_text(
        lic.read_text(encoding="utf-8").rstrip("\n") + "\n", encoding="utf-8"
    )
    prov = (
        "## cie_s026_alpha_opic.csv\n\n"
        "- Columns: `wavelength_nm,sc,mc,lc,rh,mel` (S-cone/cyanopic, M-cone/chloropic, "
        "L-cone/erythropic, rhodopic, melanopic action spectra, each peak 1).\n"
        "- Source: the α-opic action spectra of CIE S 026/E:2018 (the CIE's tables, 5 significant "
        f"digits), as distributed in the file `pysilsub/data/CIES026.csv` of the PyPI package "
        f"pysilsub {EXPECTED_PYSILSUB} (MIT licence, Copyright 2021 PySilentSubstitution; text in "
        "`LICENSE-pysilsub.txt`). The export checks the table against colour-science "
        f"{EXPECTED_COLOUR}: sc, mc, lc equal the CIE 2006 10° cone fundamentals (CIE 170-1:2006, "
        "`MSDS_CMFS_LMS['Stockman & Sharpe 10 Degree Cone Fundamentals']`) within 5e-6 and are 0 "
        "below 390 nm; rh equals the CIE 1951 scotopic V′(λ) within 1e-7.\n"
        f"- Sampling: native, {s}.\n"
        "- Processing: none (values written as stored).\n"
    )
    return [prov], s


def blue_light_hazard() -> str:
    wl = np.arange(300.0, 701.0)
    table_wl = np.array(sorted(BLH_TABLE_300_500), dtype=float)
    table = np.array([BLH_TABLE_300_500[int(w)] for w in table_wl])
    values = np.where(
        wl <= 500,
        np.interp(wl, table_wl, table),
        np.where(wl <= 600, 10 ** ((450 - wl) / 50), 0.001),
    )
    s = write_csv("blue_light_hazard.csv", wl, {"b": values})
    return (
        "## blue_light_hazard.csv\n\n"
        "- Columns: `wavelength_nm,b`\n"
        "- Source: the blue-light hazard function B(λ) of ICNIRP (2013), Guidelines on limits of "
        "exposure to incoherent visible and infrared radiation, Health Physics 105(1), 74–96, "
        "Table 2, identical to IEC 62471:2006 Table 4.1 (a published standard table; written out "
        "in `tools/export_quality_data.py`): tabulated at 5 nm from 300 to 500 nm, "
        "10^((450 − λ)/50) from 500 to 600 nm, 0.001 from 600 to 700 nm.\n"
        f"- Sampling: {s}.\n"
        "- Processing: 300–500 nm linearly interpolated from the 5 nm table; 500–600 nm the "
        "formula evaluated at each nanometre; 600–700 nm 0.001. B(λ) is taken as 0 above 700 nm.\n"
    )


def tcs15(src: str) -> str:
    """Test colour sample No. 15 (JIS Z 8726:1990, Japanese skin), as published by the CIE."""
    sd = SDS_TCS["CIE 2024"]["TCS15"]
    s = write_csv("cie_2024_tcs15.csv", sd.wavelengths, {"tcs15": sd.values})
    return (
        "## cie_2024_tcs15.csv\n\n"
        "- Columns: `wavelength_nm,tcs15`\n"
        f"- Source: {src}, `colour.quality.datasets.tcs.SDS_TCS['CIE 2024']['TCS15']`: test colour "
        "sample No. 15 of JIS Z 8726:1990 (Japanese skin complexion), spectral radiance factors as "
        "published by the CIE (2024), data set doi:10.25039/CIE.DS.7chm7z5h; gives the special "
        "colour rendering index R15.\n"
        f"- Sampling: native, {s}.\n"
        "- Processing: none.\n"
    )


def main() -> None:
    assert colour.__version__ == EXPECTED_COLOUR, f"need colour-science {EXPECTED_COLOUR}"
    src = f"colour-science {EXPECTED_COLOUR} (PyPI)"
    prov: list[str] = []

    cmfs = colour.MSDS_CMFS["CIE 1964 10 Degree Standard Observer"]
    s = write_csv(
        "cie_1964_10deg_cmf.csv", cmfs.wavelengths,
        {"x_bar": cmfs.values[:, 0], "y_bar": cmfs.values[:, 1], "z_bar": cmfs.values[:, 2]},
    )
    prov.append(
        "## cie_1964_10deg_cmf.csv\n\n"
        "- Columns: `wavelength_nm,x_bar,y_bar,z_bar`\n"
        f"- Source: {src}, `colour.MSDS_CMFS['CIE 1964 10 Degree Standard Observer']` (CIE 1964 "
        "10° supplementary standard observer, CIE 015 tabulation; the observer of CIE 224:2017 "
        "and ANSI/IES TM-30).\n"
        f"- Sampling: native, {s}.\n"
        "- Processing: none (values written as stored).\n"
    )

    tcs = SDS_TCS["CIE 1995"]
    names = [f"TCS{i:02d}" for i in range(1, 15)]
    assert list(tcs.keys()) == names, list(tcs.keys())
    wl = tcs[names[0]].wavelengths
    for n in names:
        assert np.array_equal(tcs[n].wavelengths, wl), n
    s = write_csv("cie_1995_tcs14.csv", wl, {f"tcs{i:02d}": tcs[n].values for i, n in enumerate(names, 1)})
    prov.append(
        "## cie_1995_tcs14.csv\n\n"
        "- Columns: `wavelength_nm,tcs01,...,tcs14`\n"
        f"- Source: {src}, `colour.quality.datasets.tcs.SDS_TCS['CIE 1995']` (the 14 test colour "
        "samples of CIE 13.3-1995, spectral radiance factors as tabulated by the CIE; TCS01–08 "
        "give Ra, TCS09–14 the special indices R9–R14).\n"
        f"- Sampling: native, {s}.\n"
        "- Processing: none.\n"
    )

    prov.append(tcs15(src))

    vprime = SDS_LEFS_SCOTOPIC["CIE 1951 Scotopic Standard Observer"]
    s = write_csv("cie_1951_scotopic.csv", vprime.wavelengths, {"v_prime": vprime.values})
    prov.append(
        "## cie_1951_scotopic.csv\n\n"
        "- Columns: `wavelength_nm,v_prime`\n"
        f"- Source: {src}, `colour.colorimetry.SDS_LEFS_SCOTOPIC['CIE 1951 Scotopic Standard "
        "Observer']` (CIE scotopic spectral luminous efficiency V′(λ), ISO 23539:2005/CIE S 010).\n"
        f"- Sampling: native, {s}.\n"
        "- Processing: none.\n"
    )

    more, _ = alpha_opic(src)
    prov.extend(more)
    prov.append(blue_light_hazard())

    section = (
        f"{QUALITY_MARKER}\n"
        "# Lighting-quality tables\n\n"
        "Written by `tools/export_quality_data.py` (same CSV layout as above). colour-science "
        "data: BSD-3-Clause (`LICENSE-colour-science.txt`); pysilsub data: MIT "
        "(`LICENSE-pysilsub.txt`); the underlying tables are the CIE's and ICNIRP's.\n\n"
        + "\n".join(prov)
    )
    path = DATA / "PROVENANCE.md"
    text = path.read_text(encoding="utf-8")
    head = text.split(QUALITY_MARKER)[0].rstrip("\n")
    path.write_text(head + "\n\n" + section, encoding="utf-8")


if __name__ == "__main__":
    main()
