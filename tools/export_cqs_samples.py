#!/usr/bin/env python3
"""Export the 15 reflectance samples of the NIST Colour Quality Scale 9.0 to data/.

Usage (from the repository root):
    pip install colour-science==0.4.7
    python tools/export_cqs_samples.py

Writes data/nist_cqs90_vs15.csv: colour-science's `colour.quality.datasets.SDS_VS["NIST CQS
9.0"]` (the 15 Munsell samples VS1-VS15 of W. Davis and Y. Ohno, "Color quality scale",
Optical Engineering 49(3) 033602, 2010, as tabulated in the NIST CQS 9.0 spreadsheet;
colour-science is BSD-3-Clause, see data/LICENSE-colour-science.txt), in the layout of
data/cie_1995_tcs14.csv: `wavelength_nm,vs01,...,vs15`, values as stored (shortest
round-trip decimals), native sampling. Its provenance entry is in data/PROVENANCE.md.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

warnings.filterwarnings("ignore")

import colour  # noqa: E402
from colour.quality.datasets import SDS_VS  # noqa: E402

EXPECTED_COLOUR = "0.4.7"
ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "data" / "nist_cqs90_vs15.csv"


def main() -> None:
    assert colour.__version__ == EXPECTED_COLOUR, f"need colour-science {EXPECTED_COLOUR}"
    vs = SDS_VS["NIST CQS 9.0"]
    names = [f"VS{i}" for i in range(1, 16)]
    assert list(vs.keys()) == names, list(vs.keys())
    wl = vs[names[0]].wavelengths
    assert np.array_equal(wl, np.arange(360.0, 831.0, 5.0)), "VS table is not 360-830 nm at 5 nm"
    for n in names:
        assert np.array_equal(vs[n].wavelengths, wl), n
        assert np.all(np.isfinite(vs[n].values)), n
    lines = [",".join(["wavelength_nm"] + [f"vs{i:02d}" for i in range(1, 16)])]
    for i, w in enumerate(wl):
        lines.append(",".join([str(int(w))] + [repr(float(vs[n].values[i])) for n in names]))
    OUT.write_text("\n".join(lines) + "\n", encoding="utf-8")
    print(f"wrote {OUT.relative_to(ROOT)}: {len(wl)} rows, {len(names)} samples")


if __name__ == "__main__":
    main()
