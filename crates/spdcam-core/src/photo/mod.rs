//! Real photos of a colour chart: decode ─► find the chart ─► rectify ─► sample the patches
//! ─► the feature row a model reads. Camera raw files ([`raw`]) take the same path, their
//! patches read on the sensor's mosaic.
//!
//! Coordinates: image points are continuous pixel coordinates (pixel `(i, j)` covers
//! `[i, i+1) × [j, j+1)`, its centre is `(i + 0.5, j + 0.5)`), x to the right, y down. Chart
//! points are in units of the patch pitch (centre-to-centre distance): patch (row `r`,
//! column `c`) covers `[c, c + f] × [r, r + f]` with `f` the template's
//! [`ChartTemplate::patch_fraction`], so the outer corners of the patch grid (the chart's
//! corners here) are `(0, 0)` and `(cols − 1 + f, rows − 1 + f)`.
//!
//! Orientation never comes from comparing colours with their daylight values (they change
//! with the light): it comes from the grid's shape and the lightness *order* of the
//! chart's neutral patches, which any light keeps.

mod batch;
mod detect;
pub mod detection_rate;
pub mod exposure;
mod geometry;
mod lateral_ca;
mod lattice;
mod load;
mod overlay;
pub mod pocket;
mod pyramid;
pub mod raw;
mod refine;
mod sample;
pub mod scene;
pub mod scene_places;
mod segment;

pub use batch::{
    analyse, analyse_photo, analyse_places_telling_debug, analyse_telling_debug, debug_path,
    debug_paths, features_csv, write_features_csv, AnalyseOptions, PhotoAnalysis, Place,
};
pub use detect::{
    detect, detect_all, detect_at, detect_traced, from_corners, from_corners_any, SearchTrace,
    DETECTION_SIZE,
};
pub use exposure::Exposure;
pub use geometry::{quad_centre, quads_near, sort_corners, Homography};
pub use lateral_ca::TYPICAL_CAMERA_TO_SRGB;
pub use load::{decode_photo, jpeg_end, load_photo, JpegEnd, Photo, MIN_PHOTO_SIDE};
pub use overlay::{
    analysis_overlay_jpeg, debug_factor, debug_overlay, debug_overlay_full, write_overlay, Found,
    DEBUG_MAX_PIXELS, OVERLAY_SIZE,
};
pub(crate) use sample::DARK_LEVEL;
pub use sample::{sample, PatchSample};

use crate::builtin::DataDir;
use crate::chart::{Chart, KnownChart};
use crate::error::{Error, Result};
use crate::spectral::Grid;

/// What detection and sampling need to know about a chart: its grid, its geometry, its
/// feature patches, and the neutral patches whose lightness order fixes its orientation.
/// Small and self-contained, so a model file can carry the template of its chart.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ChartTemplate {
    /// The chart's name (as [`Chart::name`]).
    pub name: String,
    /// Patch rows.
    pub rows: usize,
    /// Patch columns.
    pub cols: usize,
    /// Patch side as a fraction of the patch pitch; the rest is the dark gap between patches.
    pub patch_fraction: f64,
    /// Indices (row-major) of the feature patches, in feature order.
    pub feature_patches: Vec<usize>,
    /// Feature column names, `p01_r, p01_g, …`, as [`Chart::feature_names`].
    pub feature_names: Vec<String>,
    /// Spectrally flat patches (row-major index) with their mean reflectance.
    pub neutrals: Vec<(usize, f64)>,
}

pub use crate::chart::registry::{COLORCHECKER24_PATCH_FRACTION, COLORCHECKER_SG_PATCH_FRACTION};
/// Patch fraction of other charts whose layout has no gap.
pub const DEFAULT_PATCH_FRACTION: f64 = 0.85;

/// Wavelength range (nm) over which a patch must be flat to count as neutral.
const NEUTRAL_RANGE_NM: (f64, f64) = (420.0, 680.0);
/// Largest relative standard deviation of a neutral patch's reflectance over that range.
const NEUTRAL_MAX_REL_STD: f64 = 0.1;

impl ChartTemplate {
    /// The template of `chart`: its grid and features; the patch fraction of the chart as
    /// printed for a known printed chart ([`KnownChart::patch_fraction`]), else of the
    /// chart's layout (or
    /// [`DEFAULT_PATCH_FRACTION`] when its layout has no gap); its neutral patches found
    /// from the reflectances. Fails when fewer than three neutral patches of clearly
    /// different lightness exist, since then nothing fixes the orientation.
    pub fn from_chart(chart: &Chart) -> Result<ChartTemplate> {
        let layout = &chart.layout;
        // A chart as printed has its own patch fraction; its features alone, no photo's.
        let printed = KnownChart::from_name(&chart.name)
            .filter(|known| known.physical() == Some(*known))
            .and_then(KnownChart::patch_fraction);
        let patch_fraction = match printed {
            Some(fraction) => fraction,
            None if layout.gap_px > 0 => {
                layout.patch_px as f64 / (layout.patch_px + layout.gap_px) as f64
            }
            None => DEFAULT_PATCH_FRACTION,
        };
        let wavelengths = chart.reflectances.wavelengths();
        let band: Vec<usize> = (0..wavelengths.len())
            .filter(|&i| (NEUTRAL_RANGE_NM.0..=NEUTRAL_RANGE_NM.1).contains(&wavelengths[i]))
            .collect();
        let neutrals: Vec<(usize, f64)> = (0..chart.reflectances.len())
            .filter_map(|p| {
                let r = chart.reflectances.item(p);
                let n = band.len() as f64;
                let mean = band.iter().map(|&i| r[i]).sum::<f64>() / n;
                let var = band.iter().map(|&i| (r[i] - mean).powi(2)).sum::<f64>() / n;
                (mean > 0.0 && var.sqrt() / mean <= NEUTRAL_MAX_REL_STD).then_some((p, mean))
            })
            .collect();
        let lightest = neutrals.iter().map(|n| n.1).fold(0.0, f64::max);
        let darkest = neutrals.iter().map(|n| n.1).fold(f64::INFINITY, f64::min);
        if neutrals.len() < 3 || lightest < 3.0 * darkest {
            return Err(Error::invalid(format!(
                "chart '{}' has {} neutral patches; at least three of clearly different \
                 lightness are needed to tell its orientation in a photo",
                chart.name,
                neutrals.len()
            )));
        }
        Ok(ChartTemplate {
            name: chart.name.clone(),
            rows: layout.rows,
            cols: layout.cols,
            patch_fraction,
            feature_patches: chart.feature_patches.clone(),
            feature_names: chart.feature_names(),
            neutrals,
        })
    }

    /// The detection template of the physical chart a photo of `known` shows
    /// ([`KnownChart::physical`]: the full Digital SG for its 96 centre patches): what photos
    /// are searched for. `None` for a chart no photo shows, or whose reflectances are not at
    /// hand.
    pub fn of_known(known: KnownChart, data_dir: &DataDir, grid: &Grid) -> Option<ChartTemplate> {
        let chart = known.physical()?.chart(data_dir, grid).ok()?;
        ChartTemplate::from_chart(&chart).ok()
    }

    /// The physical chart to look for in photos when features come from the chart named
    /// `chart`: a [`KnownChart`]'s ([`ChartTemplate::of_known`]), any other chart as itself.
    /// `None` for a chart no photo shows in that order (the thesis's file order) or that has
    /// no template.
    pub fn for_chart(chart: &str, data_dir: &DataDir, grid: &Grid) -> Option<ChartTemplate> {
        if let Some(known) = KnownChart::from_name(chart) {
            return ChartTemplate::of_known(known, data_dir, grid);
        }
        let chart = Chart::resolve(chart, None, data_dir, grid).ok()?;
        ChartTemplate::from_chart(&chart).ok()
    }

    /// Number of patches.
    pub fn patch_count(&self) -> usize {
        self.rows * self.cols
    }

    /// Outer corners of the patch grid in chart coordinates: TL, TR, BR, BL.
    pub fn corners(&self) -> [[f64; 2]; 4] {
        let (w, h) = self.size();
        [[0.0, 0.0], [w, 0.0], [w, h], [0.0, h]]
    }

    /// Width and height of the patch grid in chart coordinates.
    pub fn size(&self) -> (f64, f64) {
        let f = self.patch_fraction;
        (self.cols as f64 - 1.0 + f, self.rows as f64 - 1.0 + f)
    }

    /// Centre of patch `i` (row-major) in chart coordinates.
    pub fn patch_centre(&self, i: usize) -> [f64; 2] {
        let half = self.patch_fraction / 2.0;
        [(i % self.cols) as f64 + half, (i / self.cols) as f64 + half]
    }

    /// The centre half (`patch_square(i, 0.5)`) of every patch, row-major: where a patch
    /// is flat even when blurred.
    pub fn patch_squares(&self) -> Vec<[[f64; 2]; 4]> {
        (0..self.patch_count())
            .map(|i| self.patch_square(i, 0.5))
            .collect()
    }

    /// Corners (TL, TR, BR, BL) of the centred square of side `fraction` × the patch side
    /// in patch `i`, in chart coordinates.
    pub fn patch_square(&self, i: usize, fraction: f64) -> [[f64; 2]; 4] {
        let [cx, cy] = self.patch_centre(i);
        let h = self.patch_fraction * fraction / 2.0;
        [
            [cx - h, cy - h],
            [cx + h, cy - h],
            [cx + h, cy + h],
            [cx - h, cy + h],
        ]
    }
}

/// A chart found in a photo.
#[derive(Debug, Clone, PartialEq)]
pub struct Detection {
    /// The template's name.
    pub chart: String,
    /// Outer corners of the patch grid in image coordinates: TL, TR, BR, BL in the chart's
    /// own orientation (TL is the corner of patch 1, wherever it lies in the image).
    pub corners: [[f64; 2]; 4],
    /// Chart coordinates → image coordinates (row-major, `h[2][2] = 1`).
    pub homography: [[f64; 3]; 3],
    /// 0…1: how sure the result is, from the neutral patches' lightness order, the share of
    /// patches found and how well they fit the grid.
    pub confidence: f64,
}

impl Detection {
    /// Chart → image coordinates as a map.
    pub fn map(&self) -> Homography {
        Homography::from_rows(&self.homography)
    }
}

/// Lowest confidence [`detect`] accepts; below it the photo shows no chart it can trust.
pub const MIN_CONFIDENCE: f64 = 0.5;
