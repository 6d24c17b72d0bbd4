//! The optics stage: what the lens does to the light before the sensor. Veiling glare,
//! vignetting, the lens's blur and the glow of a bright light just outside the frame are
//! here; lateral chromatic aberration ([`super::aberration`]) belongs to the same box but
//! runs on the white-balanced image, where the thesis put it (section 3.1.5).

use super::patch_mean;
use crate::raster::{gaussian_blur, RgbImage};
use serde::{Deserialize, Serialize};

/// Veiling glare (ISO 18844): stray light scattered inside the lens adds a share of the
/// scene's mean level to every region, lifting dark patches most; and a glow on part of the
/// chart, where a bright light beside it scatters more onto the regions near it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VeilingGlare {
    /// Each region's raw value gains this share of the mean raw value of the chart's
    /// patches (0 = none).
    pub share: f64,
    /// The glow on part of the chart.
    pub glow: ChartGlow,
}

impl VeilingGlare {
    /// Adds the glare to the raw region values in place; `patches` is the number of chart
    /// patches (the regions before the background) and `centres` each region's position.
    pub fn apply(&self, raw: &mut [[f32; 3]], patches: usize, centres: &[[f32; 2]]) {
        if self.share <= 0.0 && self.glow.level <= 0.0 {
            return;
        }
        let mean = patch_mean(raw, patches);
        for (v, &[x, y]) in raw.iter_mut().zip(centres) {
            let f = (self.share + self.glow.share_at([x as f64, y as f64])) as f32;
            *v = std::array::from_fn(|c| v[c] + f * mean[c]);
        }
    }
}

/// A glow on part of the chart: at `at` it adds `level` × the mean raw value of the chart's
/// patches, falling off as a Gaussian whose standard deviation is `width` (a share of the
/// chart's extent along each axis) — the local form of veiling glare (ISO 18844's glare
/// spread function in its simplest shape) that real photos of a semi-gloss chart under a
/// lamp beside it show as a bright region.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub struct ChartGlow {
    /// Share of the patches' mean raw value added at the centre (0 = off; sensible 0–0.8).
    pub level: f64,
    /// The centre in the chart's coordinates (−½ to ½ across and down the patch grid, as
    /// the lighting gradient's).
    pub at: [f64; 2],
    /// The fall-off's standard deviation, as a share of the chart's extent (sensible 0.1–1).
    pub width: f64,
}

impl ChartGlow {
    /// No glow.
    pub const OFF: ChartGlow = ChartGlow {
        level: 0.0,
        at: [0.0, 0.0],
        width: 0.0,
    };

    /// Whether it adds nothing.
    pub fn is_off(&self) -> bool {
        self.level == 0.0
    }

    /// The share of the patches' mean it adds at `point` (chart coordinates).
    pub fn share_at(&self, point: [f64; 2]) -> f64 {
        let glow = Glow {
            level: self.level,
            width: self.width,
        };
        glow.share_at(point, self.at, 1.0)
    }
}

/// Vignetting: light falls off towards the frame's corners, as the gain `1 − strength·r²`
/// with r the distance from the frame's centre relative to the half-diagonal (the leading
/// term of the cos⁴ law; Ray, *Applied Photographic Optics*, 3rd ed., §43.3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Vignetting {
    /// Light lost at the corners (0 = none, < 1).
    pub strength: f64,
}

impl Vignetting {
    /// The gain at point (x, y) of a `width × height` frame.
    pub fn gain(&self, [x, y]: [f64; 2], width: usize, height: usize) -> f64 {
        let (mx, my) = (width as f64 / 2.0, height as f64 / 2.0);
        1.0 - self.strength * ((x - mx).powi(2) + (y - my).powi(2)) / (mx * mx + my * my)
    }

    /// Multiplies every pixel of `image` by the gain at its centre.
    pub fn apply(&self, image: &mut RgbImage) {
        if self.strength == 0.0 {
            return;
        }
        let (w, h) = (image.width, image.height);
        for y in 0..h {
            for x in 0..w {
                let g = self.gain([x as f64 + 0.5, y as f64 + 0.5], w, h) as f32;
                for plane in image.planes.iter_mut() {
                    plane[y * w + x] *= g;
                }
            }
        }
    }
}

/// The lens's blur: a Gaussian point spread of `sigma` pixels (below 0.2 px, none).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LensBlur {
    /// Standard deviation of the point spread (pixels).
    pub sigma: f64,
}

impl LensBlur {
    /// Blurs every plane of `image` in place.
    pub fn apply(&self, image: &mut RgbImage) {
        if self.sigma < 0.2 {
            return;
        }
        let mut scratch = Vec::new();
        let (w, h) = (image.width, image.height);
        for plane in image.planes.iter_mut() {
            gaussian_blur(plane, w, h, self.sigma, &mut scratch);
        }
    }
}

/// Glow from a bright light just outside the frame, scattered by the lens onto part of the
/// image: light of the scene's colour added with a Gaussian fall-off from a point (a local
/// form of veiling glare, ISO 18844's glare spread function in its simplest shape).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Glow {
    /// At its centre the glow adds this share of the scene's mean level.
    pub level: f64,
    /// The fall-off's standard deviation, as a share of a reference length the caller
    /// gives (the chart's width for a scene photo).
    pub width: f64,
}

impl Glow {
    /// The share of the scene's mean level the glow centred at `centre` adds at `point`
    /// (pixels; `length` is the reference length in pixels).
    pub fn share_at(&self, point: [f64; 2], centre: [f64; 2], length: f64) -> f64 {
        let s = self.width * length;
        if self.level <= 0.0 || s <= 0.0 {
            return 0.0;
        }
        let d2 = (point[0] - centre[0]).powi(2) + (point[1] - centre[1]).powi(2);
        self.level * (-d2 / (2.0 * s * s)).exp()
    }

    /// Adds the glow centred at `centre` (pixels) to `image`; `mean` is the scene's mean
    /// raw value (R, G, B) and `length` the reference length in pixels.
    pub fn apply(&self, image: &mut RgbImage, centre: [f64; 2], mean: [f32; 3], length: f64) {
        if self.level <= 0.0 || self.width * length <= 0.0 {
            return;
        }
        let w = image.width;
        for y in 0..image.height {
            for x in 0..w {
                let g = self.share_at([x as f64 + 0.5, y as f64 + 0.5], centre, length) as f32;
                for (plane, m) in image.planes.iter_mut().zip(mean) {
                    plane[y * w + x] += g * m;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glare_adds_a_share_of_the_patch_mean_to_every_region() {
        // Two patches (mean 0.5, 1, 0.25) and the background.
        let mut raw = [[0.0f32, 1.0, 0.5], [1.0, 1.0, 0.0], [0.2, 0.2, 0.2]];
        let centres = [[-0.5, 0.0], [0.5, 0.0], [0.0, 0.0]];
        let glare = VeilingGlare {
            share: 0.5,
            glow: ChartGlow::OFF,
        };
        glare.apply(&mut raw, 2, &centres);
        assert_eq!(
            raw,
            [[0.25, 1.5, 0.625], [1.25, 1.5, 0.125], [0.45, 0.7, 0.325]]
        );
    }

    #[test]
    fn a_glow_on_the_chart_lifts_the_regions_near_its_centre_most() {
        // Two patches of the same value left and right, the glow on the left one.
        let mut raw = [[0.4f32; 3], [0.4; 3]];
        let centres = [[-0.5, 0.0], [0.5, 0.0]];
        let glare = VeilingGlare {
            share: 0.1,
            glow: ChartGlow {
                level: 0.5,
                at: [-0.5, 0.0],
                width: 0.5,
            },
        };
        glare.apply(&mut raw, 2, &centres);
        // Left: 0.4 + (0.1 + 0.5) × 0.4; right, one chart width (2σ) away: e^(−2) of it.
        assert!((raw[0][1] - 0.64).abs() < 1e-6, "{raw:?}");
        let right = 0.4 + (0.1 + 0.5 * (-2.0f64).exp()) * 0.4;
        assert!((raw[1][1] as f64 - right).abs() < 1e-6, "{raw:?}");
    }

    #[test]
    fn vignetting_is_one_at_the_centre_and_loses_strength_at_the_corners() {
        let v = Vignetting { strength: 0.25 };
        assert_eq!(v.gain([50.0, 30.0], 100, 60), 1.0);
        assert!((v.gain([0.0, 0.0], 100, 60) - 0.75).abs() < 1e-12);
        assert!((v.gain([100.0, 30.0], 100, 60) - (1.0 - 0.25 * 2500.0 / 3400.0)).abs() < 1e-12);
    }

    #[test]
    fn the_lens_blur_keeps_a_flat_image_and_the_sum_of_a_point() {
        let mut flat = RgbImage::new(9, 7);
        flat.planes.iter_mut().for_each(|p| p.fill(0.5));
        LensBlur { sigma: 1.0 }.apply(&mut flat);
        assert!(flat
            .planes
            .iter()
            .flatten()
            .all(|&v| (v - 0.5).abs() < 1e-6));
        let mut point = RgbImage::new(15, 15);
        point.planes[1][7 * 15 + 7] = 1.0;
        LensBlur { sigma: 1.0 }.apply(&mut point);
        let sum: f32 = point.planes[1].iter().sum();
        assert!((sum - 1.0).abs() < 1e-5, "{sum}");
        assert!(point.planes[1][7 * 15 + 7] < 0.2 && point.planes[1][7 * 15 + 8] > 0.05);
    }

    #[test]
    fn glow_adds_its_level_of_the_mean_at_its_centre_and_fades_with_distance() {
        let mut image = RgbImage::new(200, 10);
        Glow {
            level: 0.5,
            width: 0.1,
        }
        .apply(&mut image, [0.5, 0.5], [1.0, 2.0, 0.0], 100.0);
        assert!((image.planes[0][0] - 0.5).abs() < 1e-6);
        assert!((image.planes[1][0] - 1.0).abs() < 1e-6);
        assert_eq!(image.planes[2][0], 0.0);
        // 10 px (one σ) away: e^(−½) of the centre.
        let at_sigma = image.planes[0][10];
        assert!(
            (at_sigma - 0.5 * (-0.5f32).exp()).abs() < 1e-6,
            "{at_sigma}"
        );
        assert!(image.planes[0][199] < 1e-30);
    }
}
