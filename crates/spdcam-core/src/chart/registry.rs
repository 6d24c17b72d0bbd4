//! The chart registry: every chart spdcam knows by name ([`KnownChart`]), and all it knows
//! of each in one place: the names it is given on the command line and in model files
//! ([`KnownChart::name`]), the one name people read ([`KnownChart::shown_name`]), its
//! patches' layout and names, where its reflectances come from ([`Reflectances`]), the
//! physical chart a photo of it shows and how that chart is found in photos
//! ([`KnownChart::physical`], [`KnownChart::patch_fraction`]), and which chart's shipped model reads it
//! ([`KnownChart::model_chart`]; the models themselves are `spdcam_infer`'s, looked up by
//! this enum). Other code names a chart by its variant, never by a string; any other chart
//! is a reflectance CSV.

use super::{Chart, CSV_LAYOUT};
use crate::builtin::{self, BuiltinTable, DataDir};
use crate::error::{Error, Result};
use crate::spectral::{Grid, SpectralSet};

/// The ColorChecker 24 reflectances (Ohta), p01 dark skin … p24 black.
pub const COLORCHECKER24_TABLE: BuiltinTable = BuiltinTable {
    name: KnownChart::ColorChecker24.name(),
    description: "X-Rite ColorChecker Classic 24 (N. Ohta), 4×6",
    csv: include_str!("../../../../data/colorchecker24.csv"),
};

/// Patch side over patch pitch of a physical ColorChecker Classic 24.
pub const COLORCHECKER24_PATCH_FRACTION: f64 = 0.84;
/// Patch side over patch pitch of a physical ColorChecker Digital SG.
pub const COLORCHECKER_SG_PATCH_FRACTION: f64 = 0.88;

/// Where a known chart's reflectances come from.
#[derive(Debug, Clone, Copy)]
pub enum Reflectances {
    /// A table built into the program.
    BuiltIn(BuiltinTable),
    /// A measured file of the data directory (`--data-dir`), `folder/stem.csv`.
    DataFile {
        /// The folder of the data directory that holds it.
        folder: &'static str,
        /// The file's name without `.csv`.
        stem: &'static str,
    },
}

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

/// The charts spdcam knows by name (see the [module](self)); any other chart is a
/// reflectance CSV.
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

    /// The name on the command line, in model files, in [`Chart::name`] and in JSON: a
    /// machine name, one per feature layout (the Digital SG has three). People read
    /// [`KnownChart::shown_name`].
    pub const fn name(self) -> &'static str {
        match self {
            KnownChart::ColorChecker24 => "colorchecker24",
            KnownChart::Sg96 => "colorchecker_sg96",
            KnownChart::Sg96Thesis => "colorchecker_sg96_thesis",
            KnownChart::Sg140 => "colorchecker_sg140",
        }
    }

    /// The known chart called `name` (exactly), if any.
    pub fn from_name(name: &str) -> Option<KnownChart> {
        KnownChart::ALL.into_iter().find(|c| c.name() == name)
    }

    /// The chart's name as people know it and as everything they read names it, one per
    /// physical chart: `ColorChecker 24` or `ColorChecker Digital SG`.
    pub const fn shown_name(self) -> &'static str {
        match self {
            KnownChart::ColorChecker24 => "ColorChecker 24",
            KnownChart::Sg96 | KnownChart::Sg96Thesis | KnownChart::Sg140 => {
                "ColorChecker Digital SG"
            }
        }
    }

    /// What the chart is and where its reflectances come from, the chart named by its
    /// [`KnownChart::shown_name`].
    pub fn description(self) -> String {
        let shown = self.shown_name();
        match self {
            KnownChart::ColorChecker24 => format!("{shown} (Classic), 4×6, built in"),
            KnownChart::Sg96 => format!(
                "{shown}, the 96 centre patches (the thesis's i1Pro2 set) where they sit on \
                 the chart, 8×12, features row by row as in photos; data directory"
            ),
            KnownChart::Sg96Thesis => format!(
                "{shown}, the same 96 patches in file order, 12 per row, as the thesis \
                 rendered them; data directory"
            ),
            KnownChart::Sg140 => format!(
                "{shown}, all 140 patches, 10×14, the 96 centre patches are features; data \
                 directory"
            ),
        }
    }

    /// Where the chart's reflectances come from: built in for the ColorChecker 24; the
    /// measured files of the data directory for the Digital SG (the thesis's i1Pro2
    /// measurement of its 96 centre patches, or the whole chart's).
    pub const fn reflectances(self) -> Reflectances {
        match self {
            KnownChart::ColorChecker24 => Reflectances::BuiltIn(COLORCHECKER24_TABLE),
            KnownChart::Sg96 | KnownChart::Sg96Thesis => Reflectances::DataFile {
                folder: "thesis",
                stem: "colorchecker_digital_sg_96_i1pro2",
            },
            KnownChart::Sg140 => Reflectances::DataFile {
                folder: "charts",
                stem: "colorchecker_sg",
            },
        }
    }

    /// Whether the chart's reflectances come from the data directory (all but the built-in
    /// ColorChecker 24).
    pub const fn needs_data_dir(self) -> bool {
        matches!(self.reflectances(), Reflectances::DataFile { .. })
    }

    /// The data directory's file of the chart's reflectances (`folder/stem.csv`), for
    /// messages that say what is missing; `None` for a built-in chart.
    pub fn data_file(self) -> Option<String> {
        match self.reflectances() {
            Reflectances::BuiltIn(_) => None,
            Reflectances::DataFile { folder, stem } => Some(format!("{folder}/{stem}.csv")),
        }
    }

    /// The chart's patches as rendered and as its features are laid out, rows × columns.
    pub const fn layout(self) -> (usize, usize) {
        match self {
            KnownChart::ColorChecker24 => (4, 6),
            KnownChart::Sg96 | KnownChart::Sg96Thesis => (8, 12),
            KnownChart::Sg140 => (10, 14),
        }
    }

    /// The chart's reflectances on `grid` (from the data directory when
    /// [`KnownChart::needs_data_dir`]), laid out as [`KnownChart::arrange`] lays them.
    pub fn chart(self, data_dir: &DataDir, grid: &Grid) -> Result<Chart> {
        let set = match self.reflectances() {
            Reflectances::BuiltIn(table) => table.load()?,
            Reflectances::DataFile { folder, stem } => {
                builtin::resolve_table(stem, "chart", &[], data_dir, &[folder])
                    .map_err(|e| needs_data(self, e, data_dir))?
                    .1
            }
        };
        self.arrange(&set, grid)
    }

    /// The chart of `reflectances` (this chart's, as [`KnownChart::reflectances`] gives
    /// them) on `grid`: its patches in [`KnownChart::layout`], with its feature patches.
    pub fn arrange(self, reflectances: &SpectralSet, grid: &Grid) -> Result<Chart> {
        let (rows, cols) = self.layout();
        match self {
            KnownChart::ColorChecker24 | KnownChart::Sg96Thesis => {
                Chart::from_reflectances(self.name(), reflectances, rows, cols, grid)
            }
            KnownChart::Sg96 => {
                // The file lists the SG's centre patches column by column (B2…B9,
                // C2…C9, …, M2…M9): position (row r, column c) holds file patch c·8 + r.
                let order: Vec<usize> = (0..rows)
                    .flat_map(|r| (0..cols).map(move |c| c * rows + r))
                    .collect();
                Chart::from_reflectances(
                    self.name(),
                    &reflectances.select(&order),
                    rows,
                    cols,
                    grid,
                )
            }
            KnownChart::Sg140 => {
                // Named in X-Rite style (`A1`…`N10`: letter = column, number = row); the 96
                // patches inside the outer ring are the features, row-major.
                let order = (0..rows * cols)
                    .map(|p| {
                        let name = sg_patch_name(p % cols, p / cols);
                        reflectances.position(&name).ok_or_else(|| {
                            Error::invalid(format!(
                                "{} reflectances lack patch '{name}' (expected A1…N10)",
                                self.shown_name()
                            ))
                        })
                    })
                    .collect::<Result<Vec<usize>>>()?;
                let mut chart = Chart::from_reflectances(
                    self.name(),
                    &reflectances.select(&order),
                    rows,
                    cols,
                    grid,
                )?;
                chart.feature_patches = (1..rows - 1)
                    .flat_map(|r| (1..cols - 1).map(move |c| r * cols + c))
                    .collect();
                Ok(chart)
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
        Some(self.physical()?.layout())
    }

    /// The physical chart a photo shows when features come from this one: the whole SG for
    /// its 96 centre patches; `None` for the thesis's file order, which no photo shows.
    pub const fn physical(self) -> Option<KnownChart> {
        match self {
            KnownChart::ColorChecker24 => Some(KnownChart::ColorChecker24),
            KnownChart::Sg96 | KnownChart::Sg140 => Some(KnownChart::Sg140),
            KnownChart::Sg96Thesis => None,
        }
    }

    /// Patch side over patch pitch of the chart as printed, for finding it in photos;
    /// `None` for a chart no photo shows ([`KnownChart::physical`]).
    pub const fn patch_fraction(self) -> Option<f64> {
        match self.physical() {
            Some(KnownChart::ColorChecker24) => Some(COLORCHECKER24_PATCH_FRACTION),
            Some(_) => Some(COLORCHECKER_SG_PATCH_FRACTION),
            None => None,
        }
    }

    /// The chart whose shipped model reads a photo of this one: the ColorChecker 24's own,
    /// the Digital SG's 96-patch model for the whole SG and its centre patches; `None` for
    /// the thesis's file order, which no shipped model reads.
    pub const fn model_chart(self) -> Option<KnownChart> {
        match self {
            KnownChart::ColorChecker24 => Some(KnownChart::ColorChecker24),
            KnownChart::Sg96 | KnownChart::Sg140 => Some(KnownChart::Sg96),
            KnownChart::Sg96Thesis => None,
        }
    }

    /// The charts a shipped model is trained on, in [`KnownChart::ALL`]'s order: those a
    /// person may name for a photo's chart.
    pub fn with_shipped_model() -> Vec<KnownChart> {
        KnownChart::ALL
            .into_iter()
            .filter(|c| c.model_chart() == Some(*c))
            .collect()
    }

    /// The physical charts a shipped model reads photos of, in [`KnownChart::ALL`]'s order:
    /// the charts photos are searched for, one per chart a person owns.
    pub fn photographed() -> Vec<KnownChart> {
        KnownChart::ALL
            .into_iter()
            .filter(|c| c.physical() == Some(*c) && c.model_chart().is_some())
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_chart_has_one_shown_name_and_its_photo_is_read_by_one_shipped_model() {
        for chart in KnownChart::ALL {
            assert_eq!(KnownChart::from_name(chart.name()), Some(chart));
            // The physical chart a photo shows is named as the chart is, and is read by
            // the same shipped model.
            if let Some(physical) = chart.physical() {
                assert_eq!(physical.shown_name(), chart.shown_name());
                assert_eq!(physical.model_chart(), chart.model_chart());
                assert_eq!(chart.printed_layout(), Some(physical.layout()));
                assert!(chart.patch_fraction().is_some());
            }
            // Every shipped model reads its own chart.
            if let Some(model) = chart.model_chart() {
                assert_eq!(model.model_chart(), Some(model));
            }
            assert_eq!(chart.needs_data_dir(), chart.data_file().is_some());
        }
        assert_eq!(
            KnownChart::with_shipped_model(),
            [KnownChart::ColorChecker24, KnownChart::Sg96]
        );
        assert_eq!(
            KnownChart::photographed(),
            [KnownChart::ColorChecker24, KnownChart::Sg140]
        );
        assert_eq!(KnownChart::Sg140.model_chart(), Some(KnownChart::Sg96));
        assert_eq!(KnownChart::Sg96Thesis.physical(), None);
    }

    #[test]
    fn the_built_in_chart_is_laid_out_and_a_measured_one_says_where_its_data_is() {
        let grid = Grid::SIMULATION;
        let none = DataDir::new(None);
        let cc = KnownChart::ColorChecker24.chart(&none, &grid).unwrap();
        assert_eq!(
            (cc.layout.rows, cc.layout.cols),
            KnownChart::ColorChecker24.layout()
        );
        assert_eq!(cc.name, KnownChart::ColorChecker24.name());
        assert_eq!(COLORCHECKER24_TABLE.load().unwrap().len(), 24);
        for chart in [KnownChart::Sg96, KnownChart::Sg140] {
            let e = chart.chart(&none, &grid).unwrap_err().to_string();
            assert!(e.contains(chart.name()) && e.contains("--data-dir"), "{e}");
        }
    }
}
