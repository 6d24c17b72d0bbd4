#!/usr/bin/env python3
"""The candidates for a correction of the light's colour (docs/colour-models.md, "A map of
white light's colour"), measured on per-photo results of `spdcam experiment colour
--photos-csv` and on the real photo sets' validation photos.

Every candidate is fitted on the split's validation lamps photographed by its *training*
cameras and judged on the validation lamps' scene photos through the *held-out* cameras and
on the real sets' validation photos (choose on these; the test lamps are reported by
`spdcam experiment colour` on the model chosen). Candidates:

- affine: u'v' -> u'v' by least squares over every photo;
- affine, white only: the same fitted on estimates with |Duv| < 0.03, applied in full up to
  |Duv| 0.015 and fading to nothing at 0.03 (as `spdcam_infer::colour_map`);
- shift: mired and Duv moved by their mean errors, white only;
- lines: mired and Duv each by a least-squares line, white only (what `spdcam colour-map
  fit` fits);
each fitted on scene photos alone or on scene and patch-level photos.

    # the shipped models without a map (git show <rev>:models/…), per-photo CSVs:
    spdcam experiment colour --model M.spdm --split docs/validation-split.json --seed 1 \
        --photos-csv held-out.csv -o /dev/null
    # the training cameras as "held out": a split whose held_out lists 14 training cameras
    spdcam experiment colour --model M.spdm --split training-cameras-split.json --seed 3 \
        --photos 4 --photos-csv training.csv -o /dev/null
    # the real sets' validation photos, estimated by the SG model (JSON Lines):
    spdcam estimate --features DATA/thesis/measured/SET/features.csv --json > real-SET.jsonl
    python3 tools/colour_map_candidates.py held-out.csv training.csv DATA [real-*.jsonl]

Needs numpy and pandas. CCT and Duv here come from a Planckian table at 0.05 mired (nearest
point, CIE 1931 2° observer): good to a few kelvin, enough to compare candidates.
"""
import json
import pathlib
import sys

import numpy as np
import pandas as pd

FULL_DUV, NO_DUV, WHITE_DUV = 0.015, 0.03, 0.02


class Locus:
    """The Planckian locus in CIE 1960 uv with its normals, from the data directory's CMFs."""

    def __init__(self, data):
        cmf = pd.read_csv(data / "cie" / "cie_1931_2deg_xyz_cmf.csv")
        self.cmf = cmf.set_index(cmf.columns[0])
        wl = cmf.iloc[:, 0].values * 1e-9
        xbar = cmf.iloc[:, 1:4].values
        self.t = 1e6 / np.arange(1e6 / 25000, 1e6 / 1000, 0.05)
        planck = 1 / (wl[None, :] ** 5 * (np.exp(1.4388e-2 / (wl[None, :] * self.t[:, None])) - 1))
        xyz = planck @ xbar
        d = xyz[:, 0] + 15 * xyz[:, 1] + 3 * xyz[:, 2]
        self.uv = np.stack([4 * xyz[:, 0] / d, 6 * xyz[:, 1] / d], 1)
        tangent = np.gradient(self.uv, axis=0)
        tangent /= np.linalg.norm(tangent, axis=1)[:, None]
        normal = np.stack([-tangent[:, 1], tangent[:, 0]], 1)
        self.normal = normal * np.sign(normal[:, 1])[:, None]

    def nearest(self, uvp):
        uv = np.stack([uvp[:, 0], uvp[:, 1] / 1.5], 1)
        k = np.array([np.argmin(((self.uv - p) ** 2).sum(1)) for p in uv])
        return uv, k

    def mired_duv(self, uvp):
        uv, k = self.nearest(uvp)
        return 1e6 / self.t[k], ((uv - self.uv[k]) * self.normal[k]).sum(1)

    def uvp(self, mired, duv):
        k = np.clip(np.searchsorted(-self.t, -1e6 / mired), 0, len(self.t) - 1)
        uv = self.uv[k] + duv[:, None] * self.normal[k]
        return np.stack([uv[:, 0], 1.5 * uv[:, 1]], 1)


def weight(duv):
    return np.clip((NO_DUV - np.abs(duv)) / (NO_DUV - FULL_DUV), 0, 1)


def affine(e, t):
    a = np.c_[e, np.ones(len(e))]
    m = np.linalg.lstsq(a, t, rcond=None)[0]
    return lambda x: np.c_[x, np.ones(len(x))] @ m


def candidate(name, fit, locus):
    e = fit[["estimate_u_prime", "estimate_v_prime"]].values
    t = fit[["true_u_prime", "true_v_prime"]].values
    me, de = locus.mired_duv(e)
    mt, dt = locus.mired_duv(t)
    if name == "affine":
        return affine(e, t)
    if name == "affine, white only":
        sel = np.abs(de) < NO_DUV
        m = affine(e[sel], t[sel])

        def f(x):
            return x + weight(locus.mired_duv(x)[1])[:, None] * (m(x) - x)

        return f
    sel = (np.abs(de) < NO_DUV) & (np.abs(dt) <= WHITE_DUV)
    if name == "shift":
        pm = (1.0, np.mean(mt[sel] - me[sel]))
        pd_ = (1.0, np.mean(dt[sel] - de[sel]))
    else:
        pm = np.polyfit(me[sel], mt[sel], 1)
        pd_ = np.polyfit(de[sel], dt[sel], 1)

    def g(x):
        m, d = locus.mired_duv(x)
        y = locus.uvp(pm[0] * m + pm[1], pd_[0] * d + pd_[1])
        return x + weight(d)[:, None] * (y - x)

    return g


def scores(est, frame, locus):
    t = frame[["true_u_prime", "true_v_prime"]].values
    duv = np.median(np.hypot(*(est - t).T))
    white = frame.true_cct_k.notna().values
    mired, _ = locus.mired_duv(est[white])
    err = (1e6 / mired - frame.true_cct_k.values[white]) / frame.true_cct_k.values[white]
    return f"{duv:.4f}, {np.median(err) * 100:+.1f} %, {np.median(np.abs(err)) * 100:.1f} %"


def real_sets(paths, data):
    out = []
    for p in paths:
        name = pathlib.Path(p).stem.removeprefix("real-")
        spds = pd.read_csv(data / "thesis" / "measured" / name / "spds.csv")
        wl = spds.columns.astype(float).astype(int)
        cmf = pd.read_csv(data / "cie" / "cie_1931_2deg_xyz_cmf.csv")
        cmf = cmf.set_index(cmf.columns[0]).loc[wl].values
        xyz = spds.values @ cmf
        d = xyz[:, 0] + 15 * xyz[:, 1] + 3 * xyz[:, 2]
        truth = np.stack([4 * xyz[:, 0] / d, 9 * xyz[:, 1] / d], 1)
        xy = np.array([json.loads(line)["colorimetry"]["xy"] for line in open(p)])
        d = -2 * xy[:, 0] + 12 * xy[:, 1] + 3
        out.append((name, np.stack([4 * xy[:, 0] / d, 9 * xy[:, 1] / d], 1), truth))
    return out


def main():
    held_out, training = pd.read_csv(sys.argv[1]), pd.read_csv(sys.argv[2])
    data = pathlib.Path(sys.argv[3])
    real = real_sets(sys.argv[4:], data)
    locus = Locus(data)
    held_out, training = held_out[held_out.refused == False], training[training.refused == False]  # noqa: E712
    names = " / ".join(name for name, _, _ in real)
    print("| model | candidate | fitted on | validation scene photos (Δu′v′, CCT error, abs) "
          f"| validation patch-level photos | real sets' validation Δu′v′ ({names}) |")
    print("|---|---|---|---|---|---|")
    for model in held_out.model.unique():
        val = held_out[(held_out.model == model) & (held_out.set == "validation lamps")]
        scene, patch = val[val.photo == "scene"], val[val.photo == "patch"]
        e = lambda f: f[["estimate_u_prime", "estimate_v_prime"]].values  # noqa: E731
        real_text = " / ".join(f"{np.median(np.hypot(*(r - t).T)):.4f}" for _, r, t in real)
        print(f"| {model} | none | – | {scores(e(scene), scene, locus)} | "
              f"{scores(e(patch), patch, locus)} | {real_text if 'sg96' in model else '–'} |")
        fits = training[(training.model == model) & (training.set == "validation lamps")]
        for name in ["affine", "affine, white only", "shift", "lines"]:
            for photos in ["scene", "scene and patch"]:
                fit = fits if photos != "scene" else fits[fits.photo == "scene"]
                f = candidate(name, fit, locus)
                real_text = " / ".join(
                    f"{np.median(np.hypot(*(f(r) - t).T)):.4f}" for _, r, t in real)
                print(f"| {model} | {name} | {photos} | {scores(f(e(scene)), scene, locus)} | "
                      f"{scores(f(e(patch)), patch, locus)} | "
                      f"{real_text if 'sg96' in model else '–'} |")


if __name__ == "__main__":
    main()
