#!/usr/bin/env python3
"""Reference film/TV and colour-meter numbers from colour-science, for the Rust tests.

Usage (from the repository root):
    pip install colour-science==0.4.7 "numpy<2.3" scipy
    python tools/export_film_tv_reference.py [LAMPS.csv]

LAMPS.csv is a spectral CSV of lamps (wavelength_nm, one column per lamp), e.g. the 221
measured lamps of the IES TM-30 library in the data directory (lamps/ies_tm30_lamps.csv).
Writes, under crates/spdcam-core/tests/reference/:

- film_tv_shipped.csv: the numbers for CIE A, D65, D50 (data/illuminants_cie.csv), the six
  spectra of quality_spds.csv and the coloured lights of film_tv_spds.csv (the test tier
  without a data directory);
- film_tv_spds.csv: coloured and LED-like test lights built here from Gaussian bands
  (colour.colorimetry.sd_gaussian) and mixtures of them, 380-780 nm at 5 nm: single LEDs
  (dominant wavelength), purples (complementary wavelength), white LED-like mixtures;
- film_tv_lamps.csv: the numbers for every lamp of LAMPS.csv, when given (the measured-data
  test tier).

How each number is computed (the spectrum S is the given samples, Sprague-interpolated by
colour-science to 360-780 nm at 1 nm and zero outside the data, called S1 below):

- cct_k, duv: colour.temperature.uv_to_CCT_Ohno2013 of the CIE 1960 uv of
  colour.sd_to_XYZ(S1, method="Integration") (CIE 1931 2 degree observer).
- dominant_nm, purity: colour.dominant_wavelength(xy, xy_E) and colour.excitation_purity(xy,
  xy_E) of the CIE 1931 xy of S1 against the equi-energy illuminant E (1/3, 1/3), CIE 1931
  2 degree spectral locus at 1 nm over 360-780 nm (colour-science's default). dominant_nm is
  the nearest tabulated wavelength, negative for a complementary wavelength (purples).
- cri_r15: colour.colour_rendering_index(S1, additional_data=True, method="CIE 2024")
  .Q_as[15] (CIE 13.3-1995 method on test colour sample 15, JIS Z 8726 Japanese skin).
- ssi_cct, ssi_p3200, ssi_d5500: colour.spectral_similarity_index(S1, reference,
  round_result=False) with reference = the CCT-matched one (colour.sd_blackbody(cct) on
  360-780 nm at 1 nm below 4000 K; colour.sd_CIE_illuminant_D_series(CCT_to_xy_CIE_D(cct))
  from 4000 K), a 3200 K blackbody, and CIE daylight at 5500 K.
- mired_5600, mired_3200: 1e6/5600 - 1e6/cct and 1e6/3200 - 1e6/cct (numpy).
- Empty: cri_r15 and ssi_cct where the light has no CCT-matched reference (|duv| > 0.05, where
  a CCT is not meaningful (Ohno 2014), or CCT outside 1000-25000 K); mired_* where |duv| >
  0.05 or CCT outside 1000-100000 K.
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
from colour.temperature import CCT_to_xy_CIE_D, uv_to_CCT_Ohno2013  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "crates" / "spdcam-core" / "tests" / "reference"
EXPECTED_COLOUR = "0.4.7"
SHAPE_1NM = colour.SpectralShape(360, 780, 1)
SHAPE_5NM = colour.SpectralShape(380, 780, 5)
XY_E = np.array([1 / 3, 1 / 3])
# Beyond this distance from the Planckian locus a CCT is not meaningful (Ohno 2014).
MAX_ABS_DUV = 0.05

COLUMNS = [
    "name", "cct_k", "duv", "dominant_nm", "purity", "cri_r15",
    "ssi_cct", "ssi_p3200", "ssi_d5500", "mired_5600", "mired_3200",
]

# Coloured and LED-like test lights: (name, [(peak nm, FWHM nm, weight), ...]).
BANDS = [
    ("led_royal_blue_450", [(450, 20, 1.0)]),
    ("led_blue_470", [(470, 25, 1.0)]),
    ("led_cyan_500", [(500, 30, 1.0)]),
    ("led_green_525", [(525, 35, 1.0)]),
    ("led_lime_565", [(565, 80, 1.0)]),
    ("led_amber_590", [(590, 15, 1.0)]),
    ("led_red_630", [(630, 18, 1.0)]),
    ("led_deep_red_660", [(660, 20, 1.0)]),
    ("line_550", [(550, 2, 1.0)]),
    ("purple_450_650", [(450, 20, 1.0), (650, 20, 1.0)]),
    ("magenta_460_630", [(460, 20, 0.6), (630, 20, 1.0)]),
    ("violet_430_620", [(430, 15, 1.0), (620, 20, 0.4)]),
    ("white_rgb", [(455, 20, 0.9), (530, 30, 0.8), (625, 20, 1.0)]),
    ("white_phosphor_5000", [(450, 20, 1.0), (560, 110, 1.6)]),
    ("white_phosphor_3000", [(450, 20, 0.6), (600, 120, 2.2)]),
]


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


def ssi_or_nan(s1: colour.SpectralDistribution, reference) -> float:
    if reference is None:
        return math.nan
    return float(colour.spectral_similarity_index(s1, reference, round_result=False))


def metrics(wl: np.ndarray, values: np.ndarray, name: str) -> dict:
    s1 = to_1nm(wl, values, name)
    xyz = colour.sd_to_XYZ(s1, method="Integration")
    xy = colour.XYZ_to_xy(xyz)
    cct, duv = uv_to_CCT_Ohno2013(colour.UCS_to_uv(colour.XYZ_to_UCS(xyz)))
    row = {"name": name, "cct_k": cct, "duv": duv}
    row["dominant_nm"] = colour.dominant_wavelength(xy, XY_E)[0]
    row["purity"] = colour.excitation_purity(xy, XY_E)
    near_locus = abs(duv) <= MAX_ABS_DUV
    if near_locus and 1000 <= cct <= 25000:
        cri = colour.colour_rendering_index(s1, additional_data=True, method="CIE 2024")
        row["cri_r15"] = cri.Q_as[15].Q_a
        if cct < 4000:
            matched = colour.sd_blackbody(cct, SHAPE_1NM)
        else:
            matched = colour.sd_CIE_illuminant_D_series(CCT_to_xy_CIE_D(cct))
    else:
        matched = None
        row["cri_r15"] = math.nan
    if near_locus and 1000 <= cct <= 100000:
        row["mired_5600"] = 1e6 / 5600 - 1e6 / cct
        row["mired_3200"] = 1e6 / 3200 - 1e6 / cct
    else:
        row["mired_5600"] = row["mired_3200"] = math.nan
    row["ssi_cct"] = ssi_or_nan(s1, matched)
    row["ssi_p3200"] = ssi_or_nan(s1, colour.sd_blackbody(3200, SHAPE_1NM))
    row["ssi_d5500"] = ssi_or_nan(
        s1, colour.sd_CIE_illuminant_D_series(CCT_to_xy_CIE_D(5500))
    )
    for k, v in row.items():
        if k != "name":
            row[k] = float(v)
    return row


def write_rows(path: Path, description: str, rows: list[dict]) -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="", encoding="utf-8") as f:
        for line in description.strip().splitlines():
            f.write(f"# {line}\n".replace("# \n", "#\n"))
        w = csv.writer(f, lineterminator="\n")
        w.writerow(COLUMNS)
        for r in rows:
            w.writerow(
                [r["name"]] + ["" if math.isnan(r[c]) else repr(r[c]) for c in COLUMNS[1:]]
            )


def band_spectra() -> tuple[np.ndarray, dict[str, np.ndarray]]:
    wl = SHAPE_5NM.wavelengths
    spds = {}
    for name, bands in BANDS:
        total = np.zeros_like(wl)
        for peak, fwhm, weight in bands:
            sd = colour.sd_gaussian(peak, fwhm, SHAPE_5NM, method="FWHM")
            total = total + weight * sd.values
        spds[name] = total / total.max()
    return wl, spds


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("lamps", type=Path, nargs="?", help="spectral CSV of lamps")
    args = parser.parse_args()
    assert colour.__version__ == EXPECTED_COLOUR, f"need colour-science {EXPECTED_COLOUR}"
    versions = f"colour-science {colour.__version__}, numpy {np.__version__}"
    how = (__doc__.split("How each number is computed")[1]).strip()

    wl_b, spds = band_spectra()
    with open(OUT / "film_tv_spds.csv", "w", newline="", encoding="utf-8") as f:
        f.write(
            "# Coloured and LED-like test lights: sums of Gaussian bands (peak nm, FWHM nm,\n"
            "# weight) made with colour.colorimetry.sd_gaussian of colour-science "
            f"{colour.__version__},\n# normalised to peak 1, on 380-780 nm at 5 nm; "
            "written by tools/export_film_tv_reference.py.\n"
        )
        for name, bands in BANDS:
            f.write(f"# {name}: {bands}\n")
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["wavelength_nm"] + list(spds))
        for i, x in enumerate(wl_b):
            w.writerow([str(int(x))] + [repr(float(spds[k][i])) for k in spds])

    shipped = []
    for path in (ROOT / "data" / "illuminants_cie.csv", OUT / "quality_spds.csv"):
        wl_i, names_i, values_i = read_spectral_csv(path)
        shipped += [metrics(wl_i, values_i[:, i], n) for i, n in enumerate(names_i)]
    shipped += [metrics(wl_b, v, n) for n, v in spds.items()]
    write_rows(
        OUT / "film_tv_shipped.csv",
        "Reference film/TV and colour-meter numbers of CIE A, D65, D50\n"
        "(data/illuminants_cie.csv), the spectra of quality_spds.csv and of film_tv_spds.csv,\n"
        f"written by tools/export_film_tv_reference.py with {versions}.\n"
        "How each number is computed " + how,
        shipped,
    )
    count = len(shipped)
    if args.lamps:
        wl, names, values = read_spectral_csv(args.lamps)
        rows = [metrics(wl, values[:, i], n) for i, n in enumerate(names)]
        write_rows(
            OUT / "film_tv_lamps.csv",
            f"Reference film/TV and colour-meter numbers of the {len(rows)} lamps of "
            f"{args.lamps.name}\nwritten by tools/export_film_tv_reference.py with {versions}.\n"
            "How each number is computed " + how,
            rows,
        )
        count += len(rows)
    print(f"wrote {count} rows to {OUT}", file=sys.stderr)


if __name__ == "__main__":
    main()
