//! What an estimate is and what it is made from: feature rows ([`FeatureRows`]), how photos
//! are analysed ([`PhotoOptions`], [`chart_templates`]), and the judged [`Estimate`] with its
//! colorimetry and its score against a truth. The [`crate::Estimator`] makes every estimate.
//!
//! ```text
//! photo ─► decode ─► detect chart ─► sample (spdcam-core::photo) ─┐
//! features CSV ─► FeatureRows ──────────────────────────────────────┴─► Estimator: model for
//!     the chart ─► SPD ─► judged ─► Estimate (SPD, colorimetry, metrics, verdict, bands)
//! ```

use crate::absolute::Absolute;
use crate::error::{InferError, Result};
use crate::shipped::ModelSet;
use crate::trust::Trust;
use serde::Serialize;
use spdcam_core::builtin::DataDir;
use spdcam_core::chart::{Chart, KnownChart};
use spdcam_core::colorimetry::{uv_to_cct_duv, xy_to_uv1960, Observer};
use spdcam_core::metrics;
use spdcam_core::photo::{ChartTemplate, PhotoAnalysis};
use spdcam_core::quality::LightingMetrics;
use spdcam_core::spectral::{Grid, Spd};
use std::path::{Path, PathBuf};

/// CCT is defined only this near the Planckian locus (|Duv| in CIE 1960 uv).
pub const MAX_CCT_DUV: f64 = 0.05;

/// Feature rows: column names and row-major values.
#[derive(Debug, Clone, PartialEq)]
pub struct FeatureRows {
    /// Column names (`p01_r, p01_g, …`).
    pub names: Vec<String>,
    /// Values, row-major.
    pub values: Vec<f64>,
    /// Number of rows.
    pub rows: usize,
}

impl FeatureRows {
    /// Reads a features CSV: a header naming the columns, then one numeric row per estimate.
    pub fn read_csv(path: &Path) -> Result<FeatureRows> {
        let file = std::fs::File::open(path)
            .map_err(|e| InferError::invalid(format!("reading {}: {e}", path.display())))?;
        FeatureRows::from_reader(std::io::BufReader::new(file), &path.display().to_string())
    }

    /// Parses features CSV text (see [`FeatureRows::read_csv`]); `shown` names it in errors.
    ///
    /// ```
    /// use spdcam_infer::FeatureRows;
    ///
    /// let rows = FeatureRows::from_csv_str("p01_r,p01_g\n12,34\n56,78\n", "f.csv")?;
    /// assert_eq!((rows.rows, rows.values.as_slice()), (2, [12.0, 34.0, 56.0, 78.0].as_slice()));
    /// let err = FeatureRows::from_csv_str("p01_r,p01_g\n12,x\n", "f.csv").unwrap_err();
    /// assert_eq!(err.to_string(), "f.csv line 2, column p01_g: 'x' is not a number");
    /// # Ok::<(), spdcam_infer::InferError>(())
    /// ```
    pub fn from_csv_str(text: &str, shown: &str) -> Result<FeatureRows> {
        FeatureRows::from_reader(text.as_bytes(), shown)
    }

    fn from_reader(input: impl std::io::Read, shown: &str) -> Result<FeatureRows> {
        let mut reader = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .flexible(true)
            .from_reader(input);
        let header = reader
            .headers()
            .map_err(|e| InferError::invalid(format!("{shown}: {e}")))?;
        spdcam_core::limits::check_csv_columns(header.len(), shown)?;
        let names: Vec<String> = header.iter().map(str::to_string).collect();
        let max_rows = spdcam_core::limits::CSV_ROWS.value()?;
        if names.iter().all(String::is_empty) {
            return Err(InferError::invalid(format!("{shown}: the file is empty")));
        }
        let mut values = Vec::new();
        let mut rows = 0;
        for record in reader.records() {
            let record = record.map_err(|e| InferError::invalid(format!("{shown}: {e}")))?;
            if rows as u64 >= max_rows {
                return Err(spdcam_core::limits::CSV_ROWS.exceeded(shown).into());
            }
            let line = record.position().map_or(0, |p| p.line());
            if record.iter().all(str::is_empty) {
                continue;
            }
            if record.len() != names.len() {
                return Err(InferError::invalid(format!(
                    "{shown} line {line}: {} values, the header names {} columns",
                    record.len(),
                    names.len()
                )));
            }
            for (cell, name) in record.iter().zip(&names) {
                let v: f64 = cell.parse().map_err(|_| {
                    InferError::invalid(format!(
                        "{shown} line {line}, column {name}: '{cell}' is not a number"
                    ))
                })?;
                if !v.is_finite() {
                    return Err(InferError::invalid(format!(
                        "{shown} line {line}, column {name}: {v} is not a finite number"
                    )));
                }
                values.push(v);
            }
            rows += 1;
        }
        if rows == 0 {
            return Err(InferError::invalid(format!(
                "{shown}: no rows of features below the header"
            )));
        }
        Ok(FeatureRows {
            names,
            values,
            rows,
        })
    }

    /// Rows from values in memory (row-major, one column per name; e.g. a numpy array),
    /// checked like a CSV's: whole rows, at least one, every value finite. `source` names
    /// them in messages.
    ///
    /// ```
    /// use spdcam_infer::FeatureRows;
    ///
    /// let names = vec!["p01_r".to_string(), "p01_g".to_string(), "p01_b".to_string()];
    /// let rows = FeatureRows::from_values(names.clone(), vec![0.5; 6], "array")?;
    /// assert_eq!(rows.rows, 2);
    /// assert!(FeatureRows::from_values(names, vec![0.5; 4], "array").is_err());
    /// # Ok::<(), spdcam_infer::InferError>(())
    /// ```
    pub fn from_values(names: Vec<String>, values: Vec<f64>, source: &str) -> Result<FeatureRows> {
        let columns = names.len();
        if columns == 0 || values.is_empty() || values.len() % columns != 0 {
            return Err(InferError::invalid(format!(
                "{source}: {} values do not make rows of {columns} features",
                values.len()
            )));
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(InferError::invalid(format!(
                "{source} row {}, column {}: {} is not a finite number",
                i / columns + 1,
                names[i % columns],
                values[i]
            )));
        }
        Ok(FeatureRows {
            rows: values.len() / columns,
            names,
            values,
        })
    }

    /// The rows of analysed photos that all show the same chart.
    pub fn of_analyses(analyses: &[&PhotoAnalysis]) -> Result<FeatureRows> {
        let Some(first) = analyses.first() else {
            return Err(InferError::invalid("no photo analysed"));
        };
        if let Some(other) = analyses
            .iter()
            .find(|a| a.feature_names != first.feature_names)
        {
            return Err(InferError::invalid(format!(
                "{} shows chart {} and {} chart {}",
                first.source, first.chart, other.source, other.chart
            )));
        }
        Ok(FeatureRows {
            names: first.feature_names.clone(),
            values: analyses
                .iter()
                .flat_map(|a| a.features.iter().map(|&v| f64::from(v)))
                .collect(),
            rows: analyses.len(),
        })
    }
}

/// CIE 1931 xy, and CCT and Duv where the chromaticity is near enough the Planckian locus.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Colorimetry {
    /// CIE 1931 chromaticity.
    pub xy: [f64; 2],
    /// Correlated colour temperature (K); `None` farther than |Duv| 0.05 from the locus.
    pub cct: Option<f64>,
    /// Distance from the Planckian locus in CIE 1960 uv.
    pub duv: Option<f64>,
}

impl Colorimetry {
    /// The colorimetry of `spd` (CIE 1931 2° observer; CCT and Duv by Ohno 2014).
    ///
    /// ```
    /// use spdcam_core::illuminant::StandardIlluminant;
    /// use spdcam_core::spectral::Grid;
    /// use spdcam_infer::estimate::Colorimetry;
    ///
    /// let d65 = StandardIlluminant::D65.spd(&Grid::ESTIMATION)?;
    /// let c = Colorimetry::of(&d65)?;
    /// assert!((c.cct.unwrap() - 6504.0).abs() < 30.0);
    /// assert!(c.label().starts_with("xy (0.31"));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn of(spd: &Spd) -> Result<Colorimetry> {
        let xy = Observer::cie1931(spd.grid())?.spd_to_xy(spd);
        let (cct, duv) = match uv_to_cct_duv(xy_to_uv1960(xy)) {
            Ok((cct, duv)) if duv.abs() <= MAX_CCT_DUV => (Some(cct), Some(duv)),
            _ => (None, None),
        };
        Ok(Colorimetry { xy, cct, duv })
    }

    /// `xy (0.3127, 0.3290), CCT 6504 K, Duv +0.0032`.
    pub fn label(&self) -> String {
        let mut s = format!("xy ({:.4}, {:.4})", self.xy[0], self.xy[1]);
        match (self.cct, self.duv) {
            (Some(cct), Some(duv)) => s.push_str(&format!(", CCT {cct:.0} K, Duv {duv:+.4}")),
            _ => s.push_str(", no CCT (far from the Planckian locus)"),
        }
        s
    }
}

/// An estimate compared with its true SPD (both peak-normalised, thesis section 4.3).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Score {
    /// Goodness-of-fit coefficient (1 = same shape).
    pub gfc: f64,
    /// Root-mean-square error.
    pub rmse: f64,
}

impl Score {
    /// The score of `estimate` against `truth`, bare values of one grid: the row-level form
    /// for rows of model output; [`Score::of_spd`] is the typed form that checks the grids.
    ///
    /// ```
    /// use spdcam_infer::estimate::Score;
    ///
    /// // Peak-normalised first: a brighter copy of the same shape scores perfectly.
    /// let score = Score::of(&[0.5, 1.0, 0.25], &[1.0, 2.0, 0.5])?;
    /// assert_eq!((score.gfc, score.rmse), (1.0, 0.0));
    /// # Ok::<(), spdcam_infer::InferError>(())
    /// ```
    pub fn of(truth: &[f64], estimate: &[f64]) -> Result<Score> {
        let t = metrics::normalise_by_max(truth);
        let e = metrics::normalise_by_max(estimate);
        Ok(Score {
            gfc: metrics::gfc(&t, &e)?,
            rmse: metrics::rmse(&t, &e)?,
        })
    }

    /// The score of `estimate` against `truth`; an error when they are on different grids.
    ///
    /// ```
    /// use spdcam_core::spectral::{Grid, Spd};
    /// use spdcam_infer::estimate::Score;
    ///
    /// let grid = Grid::parse("400-600:100")?;
    /// let truth = Spd::new(grid, vec![0.5, 1.0, 0.25])?;
    /// let score = Score::of_spd(&truth, &Spd::new(grid, vec![1.0, 2.0, 0.5])?)?;
    /// assert_eq!((score.gfc, score.rmse), (1.0, 0.0));
    /// let elsewhere = Spd::new(Grid::parse("500-700:100")?, vec![0.5, 1.0, 0.25])?;
    /// assert!(Score::of_spd(&truth, &elsewhere).is_err());
    /// # Ok::<(), spdcam_infer::InferError>(())
    /// ```
    pub fn of_spd(truth: &Spd, estimate: &Spd) -> Result<Score> {
        let (t, e) = (truth.normalised_by_max(), estimate.normalised_by_max());
        Ok(Score {
            gfc: metrics::gfc_spd(&t, &e)?,
            rmse: metrics::rmse_spd(&t, &e)?,
        })
    }
}

/// One estimate of the light: its SPD, what it means, and where it came from.
#[derive(Debug, Clone)]
pub struct Estimate {
    /// The photo's file name, or `estimate_N` for feature rows.
    pub name: String,
    /// The model that made it.
    pub model: String,
    /// The relative SPD, peak 1, on the estimator's wavelengths.
    pub spd: Spd,
    /// xy, CCT, Duv of the model's whole estimate (on the model's wavelengths, whatever
    /// part of them [`Estimate::spd`] shows).
    pub colorimetry: Colorimetry,
    /// The lighting-quality metrics (CRI, TM-30, α-opic, S/P, PPF, blue-light hazard;
    /// `spdcam_core::quality`) of the model's whole estimate, computed on the model's
    /// wavelengths only.
    pub metrics: LightingMetrics,
    /// The score against a true SPD, when one was given.
    pub truth: Option<Score>,
    /// The analysis of the photo, for estimates from photos.
    pub photo: Option<PhotoAnalysis>,
    /// How far the estimate can be trusted (verdict, reasons, self-check, bands), when
    /// judged.
    pub trust: Option<Trust>,
    /// For photos: the approximate absolute levels from the EXIF exposure, or why there are
    /// none.
    pub absolute: Option<Absolute>,
}

impl Estimate {
    /// The estimate as JSON: `name`, `model`, `wavelength_nm`, `spd`, `colorimetry`,
    /// `metrics` (every [`LightingMetrics`] key), `truth`, and for photos `photo` (chart, method, confidence, corners, homography, features and
    /// `features_by_name`, every patch with its statistics and flags, warnings). Judged
    /// estimates add `verdict`, `reasons`, `self_check` ({mean, worst, worst_patches} or
    /// null), `expected_gfc`, `band_widening` (≥ 1: how much the bands were widened for a
    /// photo the estimate explains worse than the calibration photos), `band68` and `band95`
    /// ({lower, upper} on the SPD's wavelengths) and `metric_uncertainty` ({key: {half68,
    /// half95}} for the single-number metrics), the last five null without a calibration. Photo estimates add
    /// `absolute` (approximate illuminance, PPFD, melanopic EDI and spectral irradiance from
    /// the EXIF exposure, see [`crate::absolute`]) or, when there is none, `absolute: null`
    /// and `absolute_reason`.
    pub fn to_json(&self) -> Result<serde_json::Value> {
        let mut v = serde_json::json!({
            "name": self.name,
            "model": self.model,
            "wavelength_nm": self.spd.grid().wavelengths(),
            "spd": self.spd.values(),
            "colorimetry": self.colorimetry,
            "metrics": self.metrics,
            "truth": self.truth,
        });
        if let Some(a) = &self.photo {
            v["photo"] = analysis_json(a)?;
        }
        match &self.absolute {
            Some(Ok(level)) => v["absolute"] = serde_json::json!(level),
            Some(Err(reason)) => {
                v["absolute"] = serde_json::Value::Null;
                v["absolute_reason"] = serde_json::json!(reason);
            }
            None => {}
        }
        if let Some(t) = &self.trust {
            let u = t.uncertainty.as_ref();
            v["verdict"] = serde_json::json!(t.verdict);
            v["reasons"] = serde_json::json!(t.reasons);
            v["self_check"] = serde_json::json!(t.self_check);
            v["expected_gfc"] = serde_json::json!(u.map(|u| u.expected_gfc));
            v["band_widening"] = serde_json::json!(u.map(|u| u.widening));
            v["band68"] = serde_json::json!(u.map(|u| &u.band68));
            v["band95"] = serde_json::json!(u.map(|u| &u.band95));
            // Intervals of metrics the estimate defines only.
            v["metric_uncertainty"] = serde_json::json!(u.map(|u| u
                .metrics
                .iter()
                .filter(|(key, _)| self.metrics.scalar(key).is_some())
                .collect::<std::collections::BTreeMap<_, _>>()));
        }
        Ok(v)
    }

    /// Compares the estimate with `truth` (on the estimate's grid; an error otherwise) and
    /// keeps the score.
    pub fn score_against(&mut self, truth: &Spd) -> Result<()> {
        self.truth = Some(Score::of_spd(truth, &self.spd)?);
        Ok(())
    }
}

/// One photo analysis as JSON, with the features also keyed by column name.
pub fn analysis_json(analysis: &PhotoAnalysis) -> Result<serde_json::Value> {
    let mut v = serde_json::to_value(analysis)
        .map_err(|e| InferError::invalid(format!("encoding the analysis: {e}")))?;
    let named: serde_json::Map<String, serde_json::Value> = analysis
        .feature_names
        .iter()
        .zip(&analysis.features)
        .map(|(n, f)| (n.clone(), serde_json::json!(f)))
        .collect();
    if let Some(obj) = v.as_object_mut() {
        obj.insert("features_by_name".into(), serde_json::Value::Object(named));
    }
    Ok(v)
}

/// How photos are analysed: which charts to look for, and optional corners or debug image.
#[derive(Debug, Clone, Default)]
pub struct PhotoOptions {
    /// Look only for this chart (a name or a reflectance CSV); default: every chart a model
    /// of the set was trained for.
    pub chart: Option<String>,
    /// The chart's four outer corners in pixels, any order (one photo only).
    pub corners: Option<Vec<[f64; 2]>>,
    /// Where to write a debug image of each photo (see `spdcam_core::photo::debug_path`).
    pub debug: Option<PathBuf>,
    /// Also draw the chart found on each photo, reduced to at most this many pixels wide
    /// (a JPEG for a report; [`crate::estimator::AnalysedPhoto::overlay`]), while the
    /// photo is decoded anyway.
    pub overlay_width: Option<u32>,
}

/// The charts to look for in photos. With `chart`: that chart as photos show it (from a
/// model's file when a model was trained for it) and as `spdcam render` draws it. Without:
/// every model's chart, the same two ways; when no model carries its chart's template, the
/// ColorChecker 24 and, when the data directory holds it, the Digital SG.
pub fn chart_templates(
    models: &ModelSet,
    chart: Option<&str>,
    data_dir: &DataDir,
) -> Result<Vec<ChartTemplate>> {
    let grid = Grid::SIMULATION;
    let names: Vec<String> = match chart {
        Some(name) => vec![name.to_string()],
        None => models
            .models()
            .iter()
            .filter_map(|m| m.model.header().chart.clone())
            .collect(),
    };
    if names.is_empty() {
        let mut out = vec![ChartTemplate::from_chart(&Chart::colorchecker24(&grid)?)?];
        if let Ok(sg) = Chart::resolve(KnownChart::Sg140.name(), None, data_dir, &grid) {
            out.push(ChartTemplate::from_chart(&sg)?);
        }
        return Ok(out);
    }
    let mut out: Vec<ChartTemplate> = Vec::new();
    let mut push = |t: ChartTemplate| {
        if out.iter().all(|o| o.name != t.name) {
            out.push(t);
        }
    };
    for name in &names {
        let physical = match models.for_chart(name).and_then(|m| m.model.photo_chart()) {
            Some(t) => Some(t.clone()),
            None => ChartTemplate::for_chart(name, data_dir, &grid),
        };
        physical.into_iter().for_each(&mut push);
        if let Some(rendered) = Chart::resolve(name, None, data_dir, &grid)
            .ok()
            .and_then(|c| ChartTemplate::from_chart(&c).ok())
        {
            push(rendered);
        }
    }
    if out.is_empty() {
        // Name the reason: an unknown chart, or one with too few neutral patches.
        let name = &names[0];
        let chart = Chart::resolve(name, None, data_dir, &grid)?;
        ChartTemplate::from_chart(&chart)?;
        return Err(InferError::invalid(format!(
            "chart '{name}' cannot be found in photos"
        )));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_from_values_are_checked_like_a_csv() {
        let names = vec!["a".to_string(), "b".to_string()];
        let rows = FeatureRows::from_values(names.clone(), vec![1.0, 2.0, 3.0, 4.0], "x").unwrap();
        assert_eq!(rows.rows, 2);
        let err = FeatureRows::from_values(names.clone(), vec![1.0, 2.0, 3.0], "x").unwrap_err();
        assert_eq!(
            err.to_string(),
            "x: 3 values do not make rows of 2 features"
        );
        let err = FeatureRows::from_values(names, vec![1.0, 2.0, 3.0, f64::NAN], "x").unwrap_err();
        assert_eq!(
            err.to_string(),
            "x row 2, column b: NaN is not a finite number"
        );
    }

    #[test]
    fn the_typed_score_equals_the_row_level_one_and_checks_the_grids() {
        let grid = Grid::ESTIMATION;
        let bump = |mu: f64| -> Vec<f64> {
            grid.wavelengths()
                .iter()
                .map(|l| (-((l - mu) / 50.0).powi(2)).exp())
                .collect()
        };
        let (t, e) = (bump(520.0), bump(560.0));
        let typed = Score::of_spd(
            &Spd::new(grid, t.clone()).unwrap(),
            &Spd::new(grid, e.clone()).unwrap(),
        )
        .unwrap();
        assert_eq!(typed, Score::of(&t, &e).unwrap());
        assert!(typed.gfc < 1.0 && typed.rmse > 0.0);
        let shifted = Grid::from_parts(405.0, 5.0, grid.count).unwrap();
        let err =
            Score::of_spd(&Spd::new(grid, t).unwrap(), &Spd::new(shifted, e).unwrap()).unwrap_err();
        assert!(err.to_string().contains("different grids"), "{err}");
    }
}
