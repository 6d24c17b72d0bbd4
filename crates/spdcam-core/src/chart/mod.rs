//! Colour charts: patch reflectances, their layout on the image, and which patches feed the
//! features a model reads. The charts spdcam knows by name, and everything about each of
//! them, are in [`registry`] ([`KnownChart`]); any other chart is a reflectance CSV.

pub mod registry;

pub use registry::{feature_patch_name, patch_name, shown_chart_name, KnownChart, Reflectances};

use crate::builtin::{self, DataDir};
use crate::error::{Error, Result};
use crate::limits;
use crate::spectral::{Extrapolation, Grid, Interpolation, SpectralSet};
use serde::{Deserialize, Serialize};

/// Pixels spanned by `n` patches of `patch` px, `gap` px apart, with `border` px on each
/// side; saturates instead of overflowing, so that [`limits::RENDER_PIXELS`] refuses it.
fn span(n: usize, patch: usize, gap: usize, border: usize) -> usize {
    n.saturating_mul(patch)
        .saturating_add(n.saturating_sub(1).saturating_mul(gap))
        .saturating_add(border.saturating_mul(2))
}

/// Where the patches lie on the rendered image: a `rows × cols` grid of square patches of
/// `patch_px`, `gap_px` apart, its top-left corner at (`margin_x`, `margin_y`) of a
/// `width × height` canvas. Gaps, margins and the canvas show the chart's background.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Layout {
    /// Patch rows.
    pub rows: usize,
    /// Patch columns.
    pub cols: usize,
    /// Side of a square patch (pixels).
    pub patch_px: usize,
    /// Background between neighbouring patches (pixels).
    pub gap_px: usize,
    /// Left edge of the top-left patch (pixels).
    pub margin_x: usize,
    /// Top edge of the top-left patch (pixels).
    pub margin_y: usize,
    /// Canvas width (pixels).
    pub width: usize,
    /// Canvas height (pixels).
    pub height: usize,
}

impl Layout {
    /// A grid of patches with an even border around it.
    pub fn grid(
        rows: usize,
        cols: usize,
        patch_px: usize,
        gap_px: usize,
        border_px: usize,
    ) -> Layout {
        Layout {
            rows,
            cols,
            patch_px,
            gap_px,
            margin_x: border_px,
            margin_y: border_px,
            width: span(cols, patch_px, gap_px, border_px),
            height: span(rows, patch_px, gap_px, border_px),
        }
    }

    /// Pixels of the whole canvas.
    pub fn pixels(&self) -> u64 {
        limits::product(&[self.width as u64, self.height as u64])
    }

    /// The largest grid with gaps of `gap_fraction` of a patch that fits a `width × height`
    /// canvas with at least `border_fraction` of a patch around it, centred.
    pub fn fit(
        rows: usize,
        cols: usize,
        width: usize,
        height: usize,
        gap_fraction: f64,
        border_fraction: f64,
    ) -> Result<Layout> {
        let units_x = cols as f64 + (cols as f64 - 1.0) * gap_fraction + 2.0 * border_fraction;
        let units_y = rows as f64 + (rows as f64 - 1.0) * gap_fraction + 2.0 * border_fraction;
        let patch = (width as f64 / units_x)
            .min(height as f64 / units_y)
            .floor() as usize;
        if patch < 4 {
            return Err(Error::invalid(format!(
                "a {rows}×{cols} chart does not fit a {width}×{height} image with patches of 4 px or more"
            )));
        }
        let gap = (patch as f64 * gap_fraction).round() as usize;
        let grid_w = cols * patch + (cols - 1) * gap;
        let grid_h = rows * patch + (rows - 1) * gap;
        Ok(Layout {
            rows,
            cols,
            patch_px: patch,
            gap_px: gap,
            margin_x: (width - grid_w) / 2,
            margin_y: (height - grid_h) / 2,
            width,
            height,
        })
    }

    /// Number of patches.
    pub fn patch_count(&self) -> usize {
        self.rows * self.cols
    }

    /// Top-left pixel of patch `i` (row-major).
    pub fn patch_origin(&self, i: usize) -> (usize, usize) {
        let (r, c) = (i / self.cols, i % self.cols);
        (
            self.margin_x + c * (self.patch_px + self.gap_px),
            self.margin_y + r * (self.patch_px + self.gap_px),
        )
    }

    /// Centre of every region across the patch grid, from −½ (left, top) to ½ (right,
    /// bottom): the patches row-major, then the background at (0, 0).
    pub fn region_centres(&self) -> Vec<[f32; 2]> {
        let mut centres: Vec<[f32; 2]> = (0..self.patch_count())
            .map(|i| {
                let (r, c) = (i / self.cols, i % self.cols);
                [
                    (c as f32 + 0.5) / self.cols as f32 - 0.5,
                    (r as f32 + 0.5) / self.rows as f32 - 0.5,
                ]
            })
            .collect();
        centres.push([0.0, 0.0]);
        centres
    }

    /// Whether any background (gap, border or canvas) shows.
    pub fn shows_background(&self) -> bool {
        self.gap_px > 0
            || self.margin_x > 0
            || self.margin_y > 0
            || self.width > self.cols * self.patch_px
            || self.height > self.rows * self.patch_px
    }

    /// For every pixel, the index of the patch it shows, or `patch_count()` for background.
    pub fn region_map(&self) -> Vec<u16> {
        let background = self.patch_count() as u16;
        let mut map = vec![background; self.width * self.height];
        for i in 0..self.patch_count() {
            let (x0, y0) = self.patch_origin(i);
            for y in y0..y0 + self.patch_px {
                map[y * self.width + x0..y * self.width + x0 + self.patch_px].fill(i as u16);
            }
        }
        map
    }

    /// The central sampling region of a patch: the thesis samples 14×14 px starting 5 px
    /// inside a 24×24 patch; other sizes keep the same proportion
    /// ([`crate::sampler::SAMPLING_FRACTION`]). Returns (x0, y0, side).
    pub fn sampling_region(&self, i: usize) -> (usize, usize, usize) {
        let side =
            ((self.patch_px as f64 * crate::sampler::SAMPLING_FRACTION).round() as usize).max(1);
        let inset = (self.patch_px - side) / 2;
        let (x0, y0) = self.patch_origin(i);
        (x0 + inset, y0 + inset, side)
    }
}

/// A colour chart: reflectances on the simulation grid (one per patch, row-major in the
/// layout), a flat background reflectance, and the patches whose colours are the features.
#[derive(Debug, Clone)]
pub struct Chart {
    /// The chart's name (`colorchecker24`) or its file.
    pub name: String,
    /// One reflectance (0…1, a little more for fluorescent patches) per patch, row-major
    /// in the layout, on the simulation grid.
    pub reflectances: SpectralSet,
    /// The flat reflectance of gaps, margins and the canvas.
    pub background_reflectance: f64,
    /// Where the patches lie on the rendered image.
    pub layout: Layout,
    /// Indices (row-major) of the feature patches, in feature order.
    pub feature_patches: Vec<usize>,
}

/// The thesis's patch size in pixels (m = 576 pixels per patch).
pub const THESIS_PATCH_PX: usize = 24;
/// The largest reflectance a chart patch may have: fluorescent patches exceed 1 a little;
/// a file in percent has values up to about 100.
const MAX_REFLECTANCE: f64 = 2.0;
/// Patches whose reflectance over 400–700 nm varies by less than this (standard deviation
/// / mean) are neutral ([`Chart::neutral_features`]).
pub const NEUTRAL_VARIATION: f64 = 0.1;
/// Reflectance of a chart's matte black body, shown in gaps and borders.
pub const DEFAULT_BACKGROUND: f64 = 0.04;

/// How a chart given as a reflectance CSV gets its layout, in every message that offers one:
/// `spdcam render` takes any as `--layout ROWSxCOLS`; `estimate` has no such option, so it
/// reads only the layouts it can guess, with a model trained on that chart.
pub(crate) const CSV_LAYOUT: &str =
    "24 patches are laid out 4×6 and 96 as 8×12; `spdcam render` takes \
     any other layout as --layout ROWSxCOLS; `spdcam estimate` reads a 24- or 96-patch chart \
     with a model trained on it (--model)";

impl Chart {
    /// Centre of each feature patch on the chart, in chart widths and heights from the
    /// chart's centre (−0.5…0.5 left to right and top to bottom), in feature order: where a
    /// patch sits for models of light varying across the chart (a gradient, two halves).
    pub fn feature_centres(&self) -> Vec<[f64; 2]> {
        let (rows, cols) = (self.layout.rows, self.layout.cols);
        self.feature_patches
            .iter()
            .map(|&p| {
                [
                    ((p % cols) as f64 + 0.5) / cols as f64 - 0.5,
                    ((p / cols) as f64 + 0.5) / rows as f64 - 0.5,
                ]
            })
            .collect()
    }

    /// The spectrally flat (neutral) feature patches, as (feature index, mean reflectance
    /// over 400–700 nm): those whose reflectance varies by less than [`NEUTRAL_VARIATION`]
    /// (standard deviation / mean) there. They reflect every light alike, so a photo's
    /// neutral patches measure its exposure, flare and uneven lighting.
    pub fn neutral_features(&self) -> Vec<(usize, f64)> {
        let visible: Vec<usize> = self
            .reflectances
            .wavelengths()
            .iter()
            .enumerate()
            .filter(|(_, w)| (400.0..=700.0).contains(*w))
            .map(|(i, _)| i)
            .collect();
        self.feature_patches
            .iter()
            .enumerate()
            .filter_map(|(k, &p)| {
                let refl = self.reflectances.item(p);
                let n = visible.len() as f64;
                let mean = visible.iter().map(|&i| refl[i]).sum::<f64>() / n;
                let sd = (visible
                    .iter()
                    .map(|&i| (refl[i] - mean).powi(2))
                    .sum::<f64>()
                    / n)
                    .sqrt();
                (mean > 0.0 && sd / mean < NEUTRAL_VARIATION).then_some((k, mean))
            })
            .collect()
    }

    /// A chart whose every patch is a feature, laid out `rows × cols` with the thesis's
    /// 24 px patches and no gap, reflectances resampled onto `grid`.
    pub fn from_reflectances(
        name: &str,
        reflectances: &SpectralSet,
        rows: usize,
        cols: usize,
        grid: &Grid,
    ) -> Result<Chart> {
        if rows == 0 || cols == 0 || rows * cols != reflectances.len() {
            return Err(Error::invalid(format!(
                "chart '{name}' has {} reflectances, which do not fill a {rows}×{cols} layout",
                reflectances.len()
            )));
        }
        let peak = reflectances
            .items()
            .iter()
            .zip(reflectances.names())
            .flat_map(|(v, n)| v.iter().map(move |x| (*x, n)))
            .fold(
                (0.0f64, ""),
                |a, (x, n)| if x > a.0 { (x, n.as_str()) } else { a },
            );
        if peak.0 > MAX_REFLECTANCE {
            return Err(Error::invalid(format!(
                "chart '{name}': patch '{}' reflects {} of the light; reflectances are \
                 fractions 0–1 (a file in percent? divide it by 100)",
                peak.1, peak.0
            )));
        }
        let (resampled, _) = reflectances
            .clone()
            .require_non_negative("reflectance", 0.01)?
            .resample(grid, Interpolation::Auto, Extrapolation::HoldEdge)?;
        Ok(Chart {
            name: name.to_string(),
            reflectances: resampled,
            background_reflectance: DEFAULT_BACKGROUND,
            layout: Layout::grid(rows, cols, THESIS_PATCH_PX, 0, 0),
            feature_patches: (0..rows * cols).collect(),
        })
    }

    /// The built-in ColorChecker 24 on `grid` ([`KnownChart::ColorChecker24`]).
    pub fn colorchecker24(grid: &Grid) -> Result<Chart> {
        KnownChart::ColorChecker24.chart(&DataDir::new(None), grid)
    }

    /// The full 140-patch ColorChecker Digital SG ([`KnownChart::Sg140`]) from a set named
    /// in X-Rite style (`A1`…`N10`: letter = column A–N, number = row 1–10); the 96 patches
    /// inside the outer ring are the features, row-major.
    pub fn colorchecker_sg140(reflectances: &SpectralSet, grid: &Grid) -> Result<Chart> {
        KnownChart::Sg140.arrange(reflectances, grid)
    }

    /// Resolves a chart by name or file: a [`KnownChart`]'s name (with its own layout), or
    /// a reflectance CSV (path or data-directory name) with `layout` rows × cols (needed
    /// unless the file has 24, 96 or 140 patches, whose layouts are known).
    pub fn resolve(
        spec: &str,
        layout: Option<(usize, usize)>,
        data_dir: &DataDir,
        grid: &Grid,
    ) -> Result<Chart> {
        if let Some(known) = KnownChart::from_name(spec) {
            return known.chart(data_dir, grid);
        }
        let (name, set) = builtin::resolve_table(
            spec,
            "chart",
            &[],
            data_dir,
            &["charts", "reflectances", "thesis"],
        )
        .map_err(|e| match e {
            Error::UnknownName { name, .. } => Error::UnknownName {
                kind: "chart",
                name,
                valid: KnownChart::ALL.map(KnownChart::name).join(", ")
                    + &format!(", or a reflectance CSV ({CSV_LAYOUT})"),
            },
            other => other,
        })?;
        let sg_named = set.position("A1").is_some() && set.position("N10").is_some();
        if set.len() == 140 && sg_named && layout.is_none() {
            return Chart::colorchecker_sg140(&set, grid);
        }
        let (rows, cols) = match (layout, set.len()) {
            (Some(l), _) => l,
            (None, 24) => (4, 6),
            (None, 96) => (8, 12),
            (None, n) => {
                return Err(Error::invalid(format!(
                    "chart '{name}' has {n} patches, not 24 or 96, so its layout cannot be \
                     guessed: {CSV_LAYOUT}"
                )))
            }
        };
        Chart::from_reflectances(&name, &set, rows, cols, grid)
    }

    /// The same chart with another layout geometry (patch size, gap, border) kept at
    /// the same rows × cols.
    pub fn with_layout(mut self, layout: Layout) -> Result<Chart> {
        if (layout.rows, layout.cols) != (self.layout.rows, self.layout.cols) {
            return Err(Error::invalid(format!(
                "layout {}×{} does not match chart '{}' ({}×{})",
                layout.rows, layout.cols, self.name, self.layout.rows, self.layout.cols
            )));
        }
        if layout.patch_px < 4 {
            return Err(Error::invalid("patches must be at least 4 px wide"));
        }
        limits::RENDER_PIXELS.check(
            layout.pixels(),
            &format!(
                "chart '{}' of {}×{} patches of {} px ({}×{} px)",
                self.name, layout.rows, layout.cols, layout.patch_px, layout.width, layout.height
            ),
        )?;
        self.layout = layout;
        Ok(self)
    }

    /// Feature column names: `p01_r,p01_g,p01_b,p02_r,…` in feature order.
    pub fn feature_names(&self) -> Vec<String> {
        feature_names_of(self.feature_patches.len())
    }
}

/// The feature column names a chart of `patches` feature patches gives: `p01_r,p01_g,
/// p01_b,p02_r,…` (three digits from 100 patches on), three a patch.
pub fn feature_names_of(patches: usize) -> Vec<String> {
    let width = if patches >= 100 { 3 } else { 2 };
    (1..=patches)
        .flat_map(|k| ["r", "g", "b"].map(|c| format!("p{k:0width$}_{c}")))
        .collect()
}

/// Whether `name` has the form of a feature column name ([`feature_names_of`]):
/// `p`, digits, `_` and `r`, `g` or `b`.
pub fn is_feature_name(name: &str) -> bool {
    name.strip_prefix('p')
        .and_then(|rest| rest.strip_suffix(['r', 'g', 'b']))
        .and_then(|rest| rest.strip_suffix('_'))
        .is_some_and(|digits| !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patches_are_named_as_the_charts_print_them() {
        assert_eq!(feature_patch_name("colorchecker24", 0), "dark skin");
        assert_eq!(feature_patch_name("colorchecker24", 23), "black 2");
        assert_eq!(patch_name("colorchecker24", 2), "blue sky");
        // The SG's features run row by row from B2; its file order column by column.
        assert_eq!(feature_patch_name("colorchecker_sg96", 0), "B2");
        assert_eq!(feature_patch_name("colorchecker_sg96", 13), "C3");
        assert_eq!(feature_patch_name("colorchecker_sg96", 95), "M9");
        assert_eq!(feature_patch_name("colorchecker_sg140", 13), "C3");
        assert_eq!(feature_patch_name("colorchecker_sg96_thesis", 9), "C3");
        // The whole SG, row-major over its 14 columns.
        assert_eq!(patch_name("colorchecker_sg140", 0), "A1");
        assert_eq!(patch_name("colorchecker_sg140", 15), "B2");
        assert_eq!(patch_name("colorchecker_sg140", 139), "N10");
        // Other charts, and patches past the last, by number.
        assert_eq!(feature_patch_name("my_chart.csv", 6), "patch 7");
        assert_eq!(feature_patch_name("colorchecker24", 24), "patch 25");
        assert_eq!(
            shown_chart_name("colorchecker_sg96"),
            "ColorChecker Digital SG"
        );
        assert_eq!(shown_chart_name("colorchecker24"), "ColorChecker 24");
    }

    #[test]
    fn feature_names_have_the_form_they_are_recognised_by() {
        for patches in [1, 24, 140] {
            let names = feature_names_of(patches);
            assert_eq!(names.len(), 3 * patches);
            assert!(names.iter().all(|n| is_feature_name(n)), "{names:?}");
        }
        assert_eq!(feature_names_of(140)[0], "p001_r");
        for other in [
            "p_r",
            "p01_x",
            "p01r",
            "q01_r",
            "p1a_g",
            "spd_380",
            "__index_level_0__",
        ] {
            assert!(!is_feature_name(other), "{other}");
        }
    }

    #[test]
    fn known_charts_round_trip_their_names_and_map_to_the_chart_photographed() {
        for chart in KnownChart::ALL {
            assert_eq!(KnownChart::from_name(chart.name()), Some(chart));
            assert!(!chart.description().is_empty());
        }
        assert_eq!(KnownChart::from_name("ColorChecker24"), None);
        assert_eq!(KnownChart::Sg96.physical(), Some(KnownChart::Sg140));
        assert_eq!(KnownChart::Sg96Thesis.physical(), None);
        let cc = Chart::resolve(
            "colorchecker24",
            None,
            &DataDir::new(None),
            &Grid::SIMULATION,
        );
        assert_eq!(cc.unwrap().name, KnownChart::ColorChecker24.name());
    }

    #[test]
    fn colorchecker24_thesis_layout() {
        let chart = Chart::colorchecker24(&Grid::SIMULATION).unwrap();
        assert_eq!((chart.layout.width, chart.layout.height), (144, 96));
        assert!(!chart.layout.shows_background());
        assert_eq!(chart.layout.sampling_region(0), (5, 5, 14));
        assert_eq!(chart.layout.sampling_region(7), (24 + 5, 24 + 5, 14));
        let names = chart.feature_names();
        assert_eq!(&names[..4], ["p01_r", "p01_g", "p01_b", "p02_r"]);
        assert_eq!(names.len(), 72);
    }

    #[test]
    fn region_map_marks_patches_and_gaps() {
        let l = Layout::grid(2, 3, 4, 2, 1);
        assert_eq!((l.width, l.height), (18, 12));
        let map = l.region_map();
        assert_eq!(map[0], 6);
        assert_eq!(map[l.width + 1], 0);
        assert_eq!(map[l.width + 5], 6);
        assert_eq!(map[l.width + 7], 1);
        assert_eq!(map[7 * l.width + 13], 5);
    }

    #[test]
    fn fit_centres_the_grid() {
        let l = Layout::fit(4, 6, 1709, 1212, 0.1, 0.3).unwrap();
        assert_eq!((l.width, l.height), (1709, 1212));
        let (x_end, _) = l.patch_origin(5);
        assert!(x_end + l.patch_px <= 1709);
        let (_, y_end) = l.patch_origin(23);
        assert!(y_end + l.patch_px <= 1212);
        assert!(Layout::fit(4, 6, 10, 10, 0.0, 0.0).is_err());
    }

    #[test]
    fn reflectances_in_percent_and_giant_layouts_are_refused() {
        // Issue 15: a chart in percent was accepted; `--patch-px 100000` aborted.
        let set = registry::COLORCHECKER24_TABLE.load().unwrap();
        let percent = SpectralSet::new(
            set.wavelengths().to_vec(),
            set.names().to_vec(),
            set.items()
                .iter()
                .map(|v| v.iter().map(|x| x * 100.0).collect())
                .collect(),
        )
        .unwrap();
        let e = Chart::from_reflectances("pct", &percent, 4, 6, &Grid::SIMULATION)
            .unwrap_err()
            .to_string();
        assert!(e.contains("percent"), "{e}");
        let chart = Chart::colorchecker24(&Grid::SIMULATION).unwrap();
        for layout in [
            Layout::grid(4, 6, 100_000, 0, 0),
            Layout::grid(4, 6, usize::MAX / 2, 7, 9),
        ] {
            let e = chart.clone().with_layout(layout).unwrap_err().to_string();
            assert!(e.contains("SPDCAM_MAX_RENDER_PIXELS"), "{e}");
        }
        assert!(chart.with_layout(Layout::grid(4, 6, 200, 10, 10)).is_ok());
    }

    #[test]
    fn wrong_patch_count_is_an_error() {
        let set = registry::COLORCHECKER24_TABLE.load().unwrap();
        let e = Chart::from_reflectances("x", &set, 5, 5, &Grid::SIMULATION).unwrap_err();
        assert!(e.to_string().contains("5×5"), "{e}");
    }
}
