"""Scores a model on an exported dataset (`spdcam dataset export --csv`) as a colour meter
would: mean GFC over 400-700 nm, median and 90th-percentile delta u'v' (CIE 1976, CIE 1931 2 deg),
median signed and absolute CCT error (%) over the lights within |Duv| <= 0.02.

    python tools/colour_probe_score.py SPDCAM DATASET_CSV_DIR MODEL.spdm

SPDCAM is the spdcam binary; it estimates the rows and computes every light's colorimetry
(`spdcam metrics --json`), so the numbers are the program's own.
"""
import csv, json, math, os, statistics as st, subprocess, sys, tempfile

spdcam, data, model = sys.argv[1:4]
work = tempfile.mkdtemp(prefix="colour-probe-")


def columns_csv(rows_by_name, path):
    """Writes a spectral CSV (wavelength_nm, then one column per light)."""
    names = list(rows_by_name)
    wl = rows_by_name[names[0]][0]
    with open(path, "w") as f:
        f.write("wavelength_nm," + ",".join(names) + "\n")
        for j, w in enumerate(wl):
            f.write(w + "," + ",".join(rows_by_name[n][1][j] for n in names) + "\n")


def metrics(path):
    out = subprocess.run([spdcam, "metrics", path, "--json"], capture_output=True, text=True, check=True)
    return json.loads(out.stdout)


spd_rows = list(csv.reader(open(os.path.join(data, "spds.csv"))))
truth = {f"s{i}": (spd_rows[0], r) for i, r in enumerate(spd_rows[1:])}
columns_csv(truth, os.path.join(work, "truth.csv"))
est_long = os.path.join(work, "estimates.csv")
subprocess.run([spdcam, "estimate", "--features", os.path.join(data, "features.csv"), "--model", model,
                "--layout", "long", "-o", est_long], capture_output=True, check=True)
est_rows = list(csv.reader(open(est_long)))
est = {f"e{i}": (est_rows[0][1:], r[1:]) for i, r in enumerate(est_rows[1:])}
columns_csv(est, os.path.join(work, "estimates_wide.csv"))
tm, em = metrics(os.path.join(work, "truth.csv")), metrics(os.path.join(work, "estimates_wide.csv"))
index = [spd_rows[0].index(w) for w in est_rows[0][1:]]
gfc, duv, cct = [], [], []
for i, (t, e) in enumerate(zip(spd_rows[1:], est_rows[1:])):
    a, b = [float(t[k]) for k in index], [float(x) for x in e[1:]]
    gfc.append(sum(x * y for x, y in zip(a, b)) / math.sqrt(sum(x * x for x in a) * sum(y * y for y in b)))
    (u1, v1), (u2, v2) = tm[i]["uv_prime_1976"], em[i]["uv_prime_1976"]
    duv.append(math.hypot(u1 - u2, v1 - v2))
    if tm[i].get("cct_k") and em[i].get("cct_k") and abs(tm[i].get("duv") or 1) <= 0.02:
        cct.append(100 * (em[i]["cct_k"] / tm[i]["cct_k"] - 1))
print(f"{os.path.basename(model)}: GFC {st.mean(gfc):.4f}, median du'v' {st.median(duv):.4f} "
      f"(90th percentile {sorted(duv)[int(0.9 * len(duv))]:.4f}), median CCT error {st.median(cct):+.1f} % "
      f"(absolute {st.median([abs(c) for c in cct]):.1f} %), {len(duv)} photos, {len(cct)} with a CCT")
