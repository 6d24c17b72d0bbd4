//! Pocket charts in synthetic photos: the ColorChecker Passport, a ColorChecker Classic 24
//! on one page of a folding plastic case of 125 × 90 mm pages, opened flat beside its other
//! page (X-Rite, "ColorChecker Passport User Guide"; R. D. Myers 2010, "ColorChecker
//! Passport Technical Review"). A photo of one shows the 24 patches inside the case's dark
//! frame, next to the other page's patches, which must never be taken for a second chart.
//! (The Mini and Nano are ColorChecker 24s of smaller size: a scene renders them by the
//! chart's share of the photo's width.)
//!
//! The other page is drawn in one of its two forms:
//! - the creative enhancement page: a row of eight saturated hues, two rows of warm and
//!   cool near-neutrals, and a grey ramp of four light patches ⅓ stop apart and four dark
//!   ones ⅓ stop apart ending ⅒ stop above the darkest, 32:1 in all (the user guide,
//!   "Enhancing images with the ColorChecker Creative Enhancement Target"). The printed
//!   page has five larger patches in each middle row; here every row has eight on one grid,
//!   which looks more like a chart's lattice than the printed page does, a harder test.
//! - the white balance page: one large spectrally flat light grey.
//!
//! The hues are the most saturated of the TM-30 colour evaluation samples in each eighth of
//! the hue circle (CIELAB under D65), the near-neutrals mixtures of a flat grey with the
//! orange and blue hue patches: modelled surfaces, not measurements of the printed page.

use super::geometry::Homography;
use super::scene::{pixel_bounds, Laid, Shadow};
use crate::builtin;
use crate::camera::colour::ColourConfig;
use crate::camera::sensor::Sensitivities;
use crate::camera::{Camera, CameraConfig};
use crate::chart::{Chart, Layout};
use crate::cie_illuminant::StandardIlluminant;
use crate::colorimetry::{xyz_to_lab, Observer};
use crate::error::{Error, Result};
use crate::raster::RgbImage;
use crate::spectral::{Grid, SpectralSet};
use nalgebra::Matrix3;

/// The Passport's page facing the ColorChecker 24 when opened flat.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PassportPage {
    /// Hues, warm and cool near-neutrals and a grey ramp on a 4 × 8 grid.
    CreativeEnhancement,
    /// One large light grey.
    WhiteBalance,
}

/// The case's frame around both pages, and the hinge between them, as shares of a page's
/// height.
const CASE_FRAME: f64 = 0.07;
const HINGE: f64 = 0.08;
/// Reflectance of the white balance page (a light grey, flat over the visible range).
const WHITE_BALANCE_REFLECTANCE: f64 = 0.6;
/// The creative page's grey ramp: its lightest patch, four patches ⅓ stop apart, and four
/// dark ones ending 1/32 of the lightest, the last two ⅒ stop apart (the user guide).
const RAMP_WHITE: f64 = 0.9;

impl PassportPage {
    /// Every page, in the order of their names.
    pub const ALL: [PassportPage; 2] = [
        PassportPage::CreativeEnhancement,
        PassportPage::WhiteBalance,
    ];

    /// The name a person gives it (`render --place … passport=NAME`).
    pub fn name(self) -> &'static str {
        match self {
            PassportPage::CreativeEnhancement => "creative",
            PassportPage::WhiteBalance => "white-balance",
        }
    }

    /// The page named `name`.
    pub fn from_name(name: &str) -> Option<PassportPage> {
        PassportPage::ALL.into_iter().find(|p| p.name() == name)
    }

    /// The page as a chart on `grid`, its canvas the size of `classic` (the ColorChecker
    /// 24's page as a scene lays it) with the same dark border.
    pub fn chart(self, classic: &Layout, grid: &Grid) -> Result<Chart> {
        let (rows, cols, reflectances) = match self {
            PassportPage::CreativeEnhancement => (4, 8, creative_reflectances(grid)?),
            PassportPage::WhiteBalance => (
                1,
                1,
                SpectralSet::on_grid(
                    grid,
                    vec!["white balance".into()],
                    vec![vec![WHITE_BALANCE_REFLECTANCE; grid.count]],
                )?,
            ),
        };
        let border = classic.margin_x.min(classic.margin_y);
        let pitch = ((classic.width - 2 * border) / cols).min((classic.height - 2 * border) / rows);
        let patch = if rows * cols == 1 {
            pitch
        } else {
            (pitch as f64 * 0.85).round() as usize
        };
        let gap = pitch - patch;
        let (grid_w, grid_h) = (cols * pitch - gap, rows * pitch - gap);
        let layout = Layout {
            rows,
            cols,
            patch_px: patch,
            gap_px: gap,
            margin_x: (classic.width - grid_w) / 2,
            margin_y: (classic.height - grid_h) / 2,
            width: classic.width,
            height: classic.height,
        };
        let mut chart = Chart::from_reflectances(
            &format!("passport {} page", self.name()),
            &reflectances,
            rows,
            cols,
            grid,
        )?;
        chart.layout = layout;
        Ok(chart)
    }
}

/// The camera that photographs `page` of the Passport holding `classic`'s chart: the same
/// `sensitivities` and settings as `classic`, without its colour correction, for the page
/// is only exposed, never developed (the photo's first camera develops the scene) and a
/// page of one grey gives no colour matrix to fit.
pub fn page_camera(
    page: PassportPage,
    sensitivities: &Sensitivities,
    classic: &Camera,
) -> Result<Camera> {
    let grid = classic.grid();
    let config = CameraConfig {
        colour: ColourConfig {
            correction: false,
            ..classic.config().colour
        },
        ..*classic.config()
    };
    Camera::new(
        sensitivities,
        page.chart(&classic.chart().layout, grid)?,
        config,
        grid,
    )
}

/// The creative enhancement page's 32 reflectances, row by row.
fn creative_reflectances(grid: &Grid) -> Result<SpectralSet> {
    let hues = saturated_hues(grid)?;
    let flat = |r: f64| vec![r; grid.count];
    let mix = |grey: f64, tint: &[f64], share: f64| -> Vec<f64> {
        tint.iter()
            .map(|t| (1.0 - share) * grey + share * t)
            .collect()
    };
    // Orange (45°–90°) warms, blue (225°–270°) cools.
    let (warm, cool) = (&hues[1], &hues[5]);
    let mut values: Vec<Vec<f64>> = hues.clone();
    for grey in [0.35, 0.6] {
        values.extend((1..=4).map(|k| mix(grey, warm, 0.06 * k as f64)));
        values.extend((1..=4).rev().map(|k| mix(grey, cool, 0.06 * k as f64)));
    }
    let third = 2f64.powf(-1.0 / 3.0);
    let light: Vec<f64> = (0..4).map(|k| RAMP_WHITE * third.powi(k)).collect();
    let darkest = RAMP_WHITE / 32.0;
    let next = darkest * 2f64.powf(0.1);
    let dark = [next / third / third, next / third, next, darkest];
    values.extend(light.iter().chain(&dark).map(|&r| flat(r)));
    let names = (1..=values.len()).map(|k| format!("page{k:02}")).collect();
    SpectralSet::on_grid(grid, names, values)
}

/// Per eighth of the hue circle (0°–45°, 45°–90°, …), the TM-30 colour evaluation sample of
/// the highest CIELAB chroma under D65 (CIE 1931 2°), on `grid`.
fn saturated_hues(grid: &Grid) -> Result<Vec<Vec<f64>>> {
    let samples = builtin::TM30_CES99
        .load()?
        .resample(
            grid,
            crate::spectral::Interpolation::Auto,
            crate::spectral::Extrapolation::HoldEdge,
        )?
        .0;
    let d65 = StandardIlluminant::D65.spd(grid)?;
    let observer = Observer::cie1931(grid)?;
    let white = observer.reflectance_to_xyz(&vec![1.0; grid.count], d65.values());
    let mut best: Vec<Option<(f64, usize)>> = vec![None; 8];
    for (k, r) in samples.items().iter().enumerate() {
        let [_, a, b] = xyz_to_lab(observer.reflectance_to_xyz(r, d65.values()), white);
        let hue = b.atan2(a).to_degrees().rem_euclid(360.0);
        let bin = ((hue / 45.0) as usize).min(7);
        let chroma = a.hypot(b);
        if best[bin].is_none_or(|(c, _)| chroma > c) {
            best[bin] = Some((chroma, k));
        }
    }
    best.into_iter()
        .map(|b| {
            b.map(|(_, k)| samples.item(k).to_vec())
                .ok_or_else(|| Error::invalid("the TM-30 samples leave an eighth of hues empty"))
        })
        .collect()
}

/// The Passport laid around its ColorChecker 24 page `classic`: the other page's canvas
/// to its right in the chart's plane (past the hinge), and the case's outline.
pub(super) struct Case {
    /// The other page laid in the photo.
    pub(super) page: Laid,
    /// The case's outer outline in the photo: TL, TR, BR, BL.
    pub(super) outline: [[f64; 2]; 4],
    /// Photo → the classic page's canvas pixels.
    inverse: Homography,
    /// The case's extent in the classic page's canvas pixels: x0, y0, x1, y1.
    extent: [f64; 4],
}

impl Case {
    /// The case around `classic` (laid), holding `page`'s chart on its other page.
    pub(super) fn around(classic: &Laid, page: &Chart) -> Case {
        let (cw, ch) = (classic.canvas.0 as f64, classic.canvas.1 as f64);
        let hinge = HINGE * ch;
        let frame = CASE_FRAME * ch;
        let shift = Matrix3::new(1.0, 0.0, cw + hinge, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
        let homography = Homography(classic.homography.0 * shift);
        let inverse = homography
            .inverse()
            .expect("a translation keeps the classic page's map invertible");
        let (pw, ph) = (page.layout.width, page.layout.height);
        let page_laid = Laid {
            homography,
            inverse,
            corners: classic.corners,
            patch_px: classic.patch_px,
            canvas: (pw, ph),
            outline: Laid::canvas_outline(&homography, (pw, ph)),
        };
        let extent = [-frame, -frame, cw + hinge + pw as f64 + frame, ch + frame];
        let outline = [
            [extent[0], extent[1]],
            [extent[2], extent[1]],
            [extent[2], extent[3]],
            [extent[0], extent[3]],
        ]
        .map(|p| classic.homography.apply(p));
        Case {
            page: page_laid,
            outline,
            inverse: classic.inverse,
            extent,
        }
    }

    /// Paints the case's frame and hinge flat at `dark` (the raw value of its plastic under
    /// the light) into `scene`; the pages are painted over it afterwards.
    pub(super) fn paint_frame(&self, scene: &mut RgbImage, dark: [f32; 3]) {
        let (w, h) = (scene.width, scene.height);
        let (xs, ys) = pixel_bounds(&self.outline, w, h);
        let [x0, y0, x1, y1] = self.extent;
        for y in ys {
            for x in xs.clone() {
                let [u, v] = self.inverse.apply([x as f64 + 0.5, y as f64 + 0.5]);
                if u >= x0 && u <= x1 && v >= y0 && v <= y1 {
                    for (plane, value) in scene.planes.iter_mut().zip(dark) {
                        plane[y * w + x] = value;
                    }
                }
            }
        }
    }
}

/// Refuses a shadow on a chart in a case: the shadow is drawn over the chart's own canvas,
/// not over the case and its other page.
pub(super) fn check_case_shadow(shadow: Option<Shadow>, place: usize) -> Result<()> {
    match shadow {
        Some(_) => Err(Error::invalid(format!(
            "chart {place}: a chart in a Passport's case takes no shadow; give the light's level \
             instead"
        ))),
        None => Ok(()),
    }
}

/// The raw value of `page`'s dark background under its light (`exposed`, its regions):
/// the case's plastic.
pub(super) fn case_dark(page: &Camera, exposed: &[[f32; 3]]) -> [f32; 3] {
    exposed[page.chart().reflectances.len()]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::chart::Layout;

    #[test]
    fn the_grey_ramp_spans_32_to_1_in_thirds_of_a_stop() {
        let grid = Grid::SIMULATION;
        let set = creative_reflectances(&grid).unwrap();
        assert_eq!(set.len(), 32);
        let ramp: Vec<f64> = (24..32).map(|k| set.item(k)[0]).collect();
        assert!((ramp[0] / ramp[7] - 32.0).abs() < 1e-9, "{ramp:?}");
        // Light and dark groups ⅓ stop apart, the darkest two ⅒ stop.
        for k in [0, 1, 2, 4, 5] {
            let stops = (ramp[k] / ramp[k + 1]).log2();
            assert!((stops - 1.0 / 3.0).abs() < 1e-9, "patch {k}: {stops}");
        }
        assert!(((ramp[6] / ramp[7]).log2() - 0.1).abs() < 1e-9);
        // Every ramp patch is flat.
        for k in 24..32 {
            let r = set.item(k);
            assert!(r.iter().all(|v| (v - r[0]).abs() < 1e-12));
        }
    }

    #[test]
    fn the_hues_go_round_the_circle_and_the_near_neutrals_stay_near_grey() {
        let grid = Grid::SIMULATION;
        let d65 = StandardIlluminant::D65.spd(&grid).unwrap();
        let observer = Observer::cie1931(&grid).unwrap();
        let white = observer.reflectance_to_xyz(&vec![1.0; grid.count], d65.values());
        let lab = |r: &[f64]| xyz_to_lab(observer.reflectance_to_xyz(r, d65.values()), white);
        let set = creative_reflectances(&grid).unwrap();
        for (bin, k) in (0..8).enumerate() {
            let [_, a, b] = lab(set.item(k));
            let hue = b.atan2(a).to_degrees().rem_euclid(360.0);
            assert!(
                (45.0 * bin as f64..45.0 * (bin + 1) as f64).contains(&hue),
                "{k}: {hue}"
            );
            assert!(a.hypot(b) > 20.0, "hue patch {k} is saturated");
        }
        // Four warm then four cool near-neutrals in each middle row.
        for k in 8..24 {
            let [_, a, b] = lab(set.item(k));
            assert!(a.hypot(b) < 25.0, "patch {k} is near grey: {a}, {b}");
            let warm = (k - 8) % 8 < 4;
            assert_eq!(b > 0.0, warm, "patch {k}: b* {b}");
        }
    }

    #[test]
    fn a_page_faces_the_classic_page_at_its_size() {
        let grid = Grid::SIMULATION;
        let classic = Layout::grid(4, 6, 42, 8, 16);
        for page in PassportPage::ALL {
            let chart = page.chart(&classic, &grid).unwrap();
            let l = chart.layout;
            assert_eq!((l.width, l.height), (classic.width, classic.height));
            assert!(l.margin_x >= 16 && l.margin_y >= 16, "{page:?}: {l:?}");
            assert_eq!(PassportPage::from_name(page.name()), Some(page));
        }
        assert_eq!(PassportPage::from_name("cover"), None);
    }
}
