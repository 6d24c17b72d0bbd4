//! Colour charts: patch reflectances, their layout on the image, and which patches feed the
//! features a model reads.

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

/// The error for a known chart whose reflectances were not found in the data directory
/// (`error` says they were not): it names the chart as the user did, the charts available
/// without data, and how to set the data directory. Other errors (a damaged file) pass.
fn needs_data(chart: KnownChart, error: Error, data_dir: &DataDir) -> Error {
    if !matches!(error, Error::UnknownName { .. }) {
        return error;
    }
    let without_data: Vec<&str> = KnownChart::ALL
        .into_iter()
        .filter(|c| !c.needs_data_dir())
        .map(KnownChart::name)
        .collect();
    let place = match data_dir.root() {
        Some(root) => format!("the data directory {} does not hold them", root.display()),
        None => "no data directory is set".to_string(),
    };
    Error::invalid(format!(
        "chart {} needs its measured reflectances from the data directory, and {place}; \
         charts available without data: {} (or a reflectance CSV: {CSV_LAYOUT}); \
         set the data directory with --data-dir DIR or {}",
        chart.name(),
        without_data.join(", "),
        builtin::DATA_DIR_ENV
    ))
}

/// How a chart given as a reflectance CSV gets its layout, in every message that offers one:
/// `spdcam render` takes any as `--layout ROWSxCOLS`; `estimate` has no such option, so it
/// reads only the layouts it can guess, with a model trained on that chart.
const CSV_LAYOUT: &str = "24 patches are laid out 4×6 and 96 as 8×12; `spdcam render` takes \
     any other layout as --layout ROWSxCOLS; `spdcam estimate` reads a 24- or 96-patch chart \
     with a model trained on it (--model)";

/// The official names of the ColorChecker Classic 24's patches (X-Rite, "ColorChecker
/// Classic" product sheet), row by row from dark skin to black.
pub const COLORCHECKER24_PATCH_NAMES: [&str; 24] = [
    "dark skin",
    "light skin",
    "blue sky",
    "foliage",
    "blue flower",
    "bluish green",
    "orange",
    "purplish blue",
    "moderate red",
    "purple",
    "yellow green",
    "orange yellow",
    "blue",
    "green",
    "red",
    "yellow",
    "magenta",
    "cyan",
    "white 9.5",
    "neutral 8",
    "neutral 6.5",
    "neutral 5",
    "neutral 3.5",
    "black 2",
];

/// The ColorChecker Digital SG's printed name of the patch in column `col` and row `row`
/// (both 0-based): the column's letter A–N and the row's number 1–10, as X-Rite names them.
fn sg_patch_name(col: usize, row: usize) -> String {
    format!("{}{}", char::from(b'A' + col as u8), row + 1)
}

/// The name people know the chart called `name` by (see [`KnownChart::shown_name`]); any
/// other chart by its own name.
pub fn shown_chart_name(name: &str) -> String {
    KnownChart::from_name(name).map_or_else(|| name.to_string(), |c| c.shown_name().to_string())
}

/// The name of feature patch `k` (0-based) of the chart called `name`
/// ([`KnownChart::feature_patch_name`]); `patch N` (1-based) for other charts.
pub fn feature_patch_name(name: &str, k: usize) -> String {
    KnownChart::from_name(name)
        .and_then(|c| c.feature_patch_name(k))
        .unwrap_or_else(|| format!("patch {}", k + 1))
}

/// The name of patch `p` (0-based, row-major over the whole chart) of the chart called
/// `name` ([`KnownChart::patch_name`]); `patch N` (1-based) for other charts.
pub fn patch_name(name: &str, p: usize) -> String {
    KnownChart::from_name(name)
        .and_then(|c| c.patch_name(p))
        .unwrap_or_else(|| format!("patch {}", p + 1))
}

/// The charts [`Chart::resolve`] knows by name; any other chart is a reflectance CSV.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum KnownChart {
    /// The ColorChecker Classic 24 (built in).
    ColorChecker24,
    /// The Digital SG's 96 centre patches where they sit on the chart, row by row.
    Sg96,
    /// The same 96 patches in the thesis's file order.
    Sg96Thesis,
    /// The whole Digital SG, 140 patches.
    Sg140,
}

impl KnownChart {
    /// Every known chart.
    pub const ALL: [KnownChart; 4] = [
        KnownChart::ColorChecker24,
        KnownChart::Sg96,
        KnownChart::Sg96Thesis,
        KnownChart::Sg140,
    ];

    /// The name on the command line, in model files and in [`Chart::name`].
    pub const fn name(self) -> &'static str {
        match self {
            KnownChart::ColorChecker24 => "colorchecker24",
            KnownChart::Sg96 => "colorchecker_sg96",
            KnownChart::Sg96Thesis => "colorchecker_sg96_thesis",
            KnownChart::Sg140 => "colorchecker_sg140",
        }
    }

    /// Whether the chart's reflectances come from the data directory (all but the built-in
    /// ColorChecker 24).
    pub const fn needs_data_dir(self) -> bool {
        !matches!(self, KnownChart::ColorChecker24)
    }

    /// What the chart is and where its reflectances come from.
    pub fn description(self) -> &'static str {
        match self {
            KnownChart::ColorChecker24 => "ColorChecker Classic 24, 4×6, built in",
            KnownChart::Sg96 => {
                "ColorChecker Digital SG, the 96 centre patches (the thesis's i1Pro2 set) where \
                 they sit on the chart, 8×12, features row by row as in photos; data directory"
            }
            KnownChart::Sg96Thesis => {
                "the same 96 patches in file order, 12 per row, as the thesis rendered them; \
                 data directory"
            }
            KnownChart::Sg140 => {
                "ColorChecker Digital SG, all 140 patches, 10×14, the 96 centre patches are \
                 features; data directory"
            }
        }
    }

    /// The known chart called `name` (exactly), if any.
    pub fn from_name(name: &str) -> Option<KnownChart> {
        KnownChart::ALL.into_iter().find(|c| c.name() == name)
    }

    /// The chart's name as people know it and as messages for them name it:
    /// `ColorChecker 24` or `ColorChecker Digital SG`.
    pub const fn shown_name(self) -> &'static str {
        match self {
            KnownChart::ColorChecker24 => "ColorChecker 24",
            KnownChart::Sg96 | KnownChart::Sg96Thesis | KnownChart::Sg140 => {
                "ColorChecker Digital SG"
            }
        }
    }

    /// The name of feature patch `k` (0-based, in this chart's feature order) as the chart
    /// prints it or its maker names it: the ColorChecker 24's official names (`dark skin`,
    /// `blue sky`), the Digital SG's column letter and row number (`E4`). `None` past the
    /// last feature.
    pub fn feature_patch_name(self, k: usize) -> Option<String> {
        match self {
            KnownChart::ColorChecker24 => COLORCHECKER24_PATCH_NAMES.get(k).map(|n| n.to_string()),
            // Features run row by row over the 96 centre patches (B2…M9).
            KnownChart::Sg96 | KnownChart::Sg140 => {
                (k < 96).then(|| sg_patch_name(1 + k % 12, 1 + k / 12))
            }
            // The file order runs column by column, 8 patches down each column.
            KnownChart::Sg96Thesis => (k < 96).then(|| sg_patch_name(1 + k / 8, 1 + k % 8)),
        }
    }

    /// The name of patch `p` (row-major among all the physical chart's patches, as a photo
    /// is sampled) as the chart prints it: for the ColorChecker 24 as
    /// [`KnownChart::feature_patch_name`], for the whole Digital SG its column letter and
    /// row number (`A1`…`N10`). `None` for a chart no photo shows, or past the last patch.
    pub fn patch_name(self, p: usize) -> Option<String> {
        match self {
            KnownChart::ColorChecker24 => self.feature_patch_name(p),
            KnownChart::Sg140 => (p < 140).then(|| sg_patch_name(p % 14, p / 14)),
            KnownChart::Sg96 | KnownChart::Sg96Thesis => None,
        }
    }

    /// The patches of the physical chart a photo shows ([`KnownChart::physical`]), rows ×
    /// columns as printed: what a person counts to tell the charts apart.
    pub fn printed_layout(self) -> Option<(usize, usize)> {
        match self.physical()? {
            KnownChart::ColorChecker24 => Some((4, 6)),
            KnownChart::Sg96 | KnownChart::Sg96Thesis | KnownChart::Sg140 => Some((10, 14)),
        }
    }

    /// The physical chart a photo shows when features come from this one: the whole SG for
    /// its 96 centre patches; `None` for the thesis's file order, which no photo shows.
    pub fn physical(self) -> Option<KnownChart> {
        match self {
            KnownChart::ColorChecker24 => Some(KnownChart::ColorChecker24),
            KnownChart::Sg96 | KnownChart::Sg140 => Some(KnownChart::Sg140),
            KnownChart::Sg96Thesis => None,
        }
    }
}

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

    /// The built-in ColorChecker 24 on `grid`.
    pub fn colorchecker24(grid: &Grid) -> Result<Chart> {
        Chart::from_reflectances(
            KnownChart::ColorChecker24.name(),
            &builtin::COLORCHECKER24.load()?,
            4,
            6,
            grid,
        )
    }

    /// The full 140-patch ColorChecker Digital SG from a set named in X-Rite style
    /// (`A1`…`N10`: letter = column A–N, number = row 1–10); the 96 patches inside the outer
    /// ring are the features, row-major.
    pub fn colorchecker_sg140(reflectances: &SpectralSet, grid: &Grid) -> Result<Chart> {
        let mut order = Vec::with_capacity(140);
        for row in 1..=10 {
            for col in b'A'..=b'N' {
                let name = format!("{}{row}", col as char);
                order.push(reflectances.position(&name).ok_or_else(|| {
                    Error::invalid(format!(
                        "ColorChecker SG reflectances lack patch '{name}' (expected A1…N10)"
                    ))
                })?);
            }
        }
        let mut chart = Chart::from_reflectances(
            KnownChart::Sg140.name(),
            &reflectances.select(&order),
            10,
            14,
            grid,
        )?;
        chart.feature_patches = (1..9)
            .flat_map(|r| (1..13).map(move |c| r * 14 + c))
            .collect();
        Ok(chart)
    }

    /// Resolves a chart by name or file: a [`KnownChart`]'s name, or a reflectance CSV
    /// (path or data-directory name) with `layout` rows × cols (needed unless the file has
    /// 24, 96 or 140 patches, whose layouts are known).
    pub fn resolve(
        spec: &str,
        layout: Option<(usize, usize)>,
        data_dir: &DataDir,
        grid: &Grid,
    ) -> Result<Chart> {
        let (name, set) = match KnownChart::from_name(spec) {
            Some(KnownChart::ColorChecker24) => return Chart::colorchecker24(grid),
            Some(known @ (KnownChart::Sg96 | KnownChart::Sg96Thesis)) => {
                let (_, set) = builtin::resolve_table(
                    "colorchecker_digital_sg_96_i1pro2",
                    "chart",
                    &[],
                    data_dir,
                    &["thesis"],
                )
                .map_err(|e| needs_data(known, e, data_dir))?;
                if known == KnownChart::Sg96 {
                    // The file lists the SG's centre patches column by column (B2…B9,
                    // C2…C9, …, M2…M9): position (row r, column c) holds file patch c·8 + r.
                    let order: Vec<usize> = (0..8)
                        .flat_map(|r| (0..12).map(move |c| c * 8 + r))
                        .collect();
                    return Chart::from_reflectances(spec, &set.select(&order), 8, 12, grid);
                }
                (spec.to_string(), set)
            }
            Some(known @ KnownChart::Sg140) => (
                spec.to_string(),
                builtin::resolve_table("colorchecker_sg", "chart", &[], data_dir, &["charts"])
                    .map_err(|e| needs_data(known, e, data_dir))?
                    .1,
            ),
            None => builtin::resolve_table(
                spec,
                "chart",
                &[builtin::COLORCHECKER24],
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
            })?,
        };
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
        let set = builtin::COLORCHECKER24.load().unwrap();
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
        let set = builtin::COLORCHECKER24.load().unwrap();
        let e = Chart::from_reflectances("x", &set, 5, 5, &Grid::SIMULATION).unwrap_err();
        assert!(e.to_string().contains("5×5"), "{e}");
    }
}
