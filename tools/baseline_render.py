"""The numpy + colour-demosaicing counterpart of spdcam's full 1709x1212 render.

Baseline for `cargo bench -p spdcam-core --bench render`: the same stages as the thesis's
Python virtual camera (mosaic, shot + read noise, Menon 2007 demosaicing, shades-of-grey
white balance, lateral chromatic aberration, a 3x3 colour matrix and the sRGB curve).
Prints the median seconds of one render on its last line.
Needs: pip install numpy scipy colour-demosaicing
"""
import time

import numpy as np
from colour_demosaicing import demosaicing_CFA_Bayer_Menon2007
from scipy.ndimage import map_coordinates

W, H = 1709, 1212
rng = np.random.default_rng(0)


def render():
    # 4x6 patches of random colours on a dark background, as the RGGB mosaic sees them.
    rgb = np.full((H, W, 3), 0.04)
    ph, pw = H // 4, W // 6
    for r in range(4):
        for c in range(6):
            rgb[r * ph + 10:(r + 1) * ph - 10, c * pw + 10:(c + 1) * pw - 10] = rng.random(3)
    rgb /= rgb.max()
    cfa = np.zeros((H, W))
    cfa[0::2, 0::2] = rgb[0::2, 0::2, 0]
    cfa[0::2, 1::2] = rgb[0::2, 1::2, 1]
    cfa[1::2, 0::2] = rgb[1::2, 0::2, 1]
    cfa[1::2, 1::2] = rgb[1::2, 1::2, 2]
    # Noise: 16-bit, 7.1 ADU/e-, 3 e- read noise, black level 100.
    adu = cfa * (65535 - 100)
    electrons = rng.poisson(adu / 7.1) + rng.normal(0, 3.0, adu.shape)
    adu = np.clip(np.round(100 + electrons * 7.1), 0, 65535)
    cfa = (adu - 100) / (65535 - 100)
    img = demosaicing_CFA_Bayer_Menon2007(cfa, "RGGB")
    est = np.power(np.mean(np.power(np.clip(img, 0, None), 6), axis=(0, 1)), 1 / 6)
    img = img * (est[1] / est)
    yy, xx = np.mgrid[0:H, 0:W].astype(float)
    cy, cx = (H - 1) / 2, (W - 1) / 2
    for ch, s in ((0, 1 + 0.005), (2, 1 - 0.005)):
        img[..., ch] = map_coordinates(
            img[..., ch], [cy + (yy - cy) / s, cx + (xx - cx) / s], order=1, mode="nearest"
        )
    m = np.array([[1.6, -0.4, -0.2], [-0.3, 1.5, -0.2], [0.0, -0.5, 1.5]])
    lin = np.clip(img @ m.T, 0, 1)
    srgb = np.where(lin <= 0.0031308, 12.92 * lin, 1.055 * np.power(lin, 1 / 2.4) - 0.055)
    return np.round(srgb * 255).astype(np.uint8)


times = []
for _ in range(3):
    t = time.perf_counter()
    render()
    times.append(time.perf_counter() - t)
print(sorted(times)[1])
