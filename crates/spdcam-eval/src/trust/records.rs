//! The calibration photos one by one (`spdcam trust calibrate --records DIR`): what each
//! photo was, how its estimate fared and what the photo showed, so that the calibration's
//! choices can be studied and checked outside the program.

use crate::error::{EvalError, Result};
use crate::trust::judged::{difficulty, gfc, Judged};
use spdcam_core::fsio::write_atomic;
use std::path::Path;

/// One calibration photo.
#[derive(Debug, Clone, PartialEq)]
pub struct CalibrationRecord {
    /// `virtual`, `scene` or the real set's name.
    pub source: String,
    /// The light's type (the lamp library's; a real set's kind of light).
    pub light: String,
    /// The cross-validation group (a lamp's photos share one; each real photo has its own).
    pub group: usize,
    /// The estimate's GFC against the truth.
    pub gfc: f64,
    /// The expected GFC of the fitted calibration.
    pub expected_gfc: f64,
    /// ln(1 − GFC) minus its prediction made without the photo's own group.
    pub held_out_residual: f64,
    /// The mean spread of the perturbed copies.
    pub difficulty: f64,
    /// The self-check's mean residual, half-to-half residual and glare share, when made.
    pub self_check: Option<[f64; 3]>,
    /// The veil read on the dark patches (share of the chart's mean), when read.
    pub veil: Option<f64>,
    /// Clipped feature patches.
    pub clipped: usize,
    /// The estimate's CCT (K) and its absolute error (K), when defined.
    pub cct: Option<[f64; 2]>,
}

impl CalibrationRecord {
    /// The record of `judged`, photo of `source` lit by a light of type `light`.
    pub fn of(
        judged: &Judged,
        source: &str,
        light: &str,
        group: usize,
        expected_gfc: f64,
        held_out_residual: f64,
        clipped: usize,
    ) -> CalibrationRecord {
        let metric = |key: &str| -> Option<[f64; 2]> {
            Some([
                *judged.metric_value.get(key)?,
                *judged.metric_error.get(key)?,
            ])
        };
        CalibrationRecord {
            source: source.to_string(),
            light: light.to_string(),
            group,
            gfc: gfc(judged),
            expected_gfc,
            held_out_residual,
            difficulty: difficulty(judged),
            self_check: judged
                .self_check
                .as_ref()
                .map(|s| [s.mean, s.split, s.glare]),
            veil: judged
                .self_check
                .as_ref()
                .and_then(|s| s.veil.as_ref())
                .map(|v| v.share),
            clipped,
            cct: metric("cct_k"),
        }
    }
}

/// The CSV columns of [`records_csv`].
const HEADER: [&str; 14] = [
    "source",
    "light",
    "group",
    "gfc",
    "expected_gfc",
    "held_out_residual",
    "difficulty",
    "self_check_mean",
    "self_check_split",
    "self_check_glare",
    "veil",
    "clipped",
    "cct_k",
    "cct_error_k",
];

/// `records` as CSV, one row a photo, empty cells where a number was not measured.
pub fn records_csv(records: &[CalibrationRecord]) -> Result<Vec<u8>> {
    let mut out = csv::Writer::from_writer(Vec::new());
    let csv_error = |e: csv::Error| EvalError::invalid(format!("writing the records: {e}"));
    out.write_record(HEADER).map_err(csv_error)?;
    let cell = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.6}"));
    for r in records {
        let check = |k: usize| cell(r.self_check.map(|s| s[k]));
        out.write_record([
            r.source.clone(),
            r.light.clone(),
            r.group.to_string(),
            cell(Some(r.gfc)),
            cell(Some(r.expected_gfc)),
            cell(Some(r.held_out_residual)),
            cell(Some(r.difficulty)),
            check(0),
            check(1),
            check(2),
            cell(r.veil),
            r.clipped.to_string(),
            cell(r.cct.map(|c| c[0])),
            cell(r.cct.map(|c| c[1])),
        ])
        .map_err(csv_error)?;
    }
    out.into_inner()
        .map_err(|e| EvalError::invalid(format!("writing the records: {e}")))
}

/// Writes [`records_csv`] of `records` to `path`, whole or not at all.
pub fn write_records(path: &Path, records: &[CalibrationRecord]) -> Result<()> {
    Ok(write_atomic(path, &records_csv(records)?)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trust::judged::fixtures::judged;

    /// The CSV's rows, each split into cells.
    fn rows(records: &[CalibrationRecord]) -> Vec<Vec<String>> {
        let text = records_csv(records).unwrap();
        csv::ReaderBuilder::new()
            .has_headers(false)
            .from_reader(text.as_slice())
            .records()
            .map(|r| r.unwrap().iter().map(str::to_string).collect())
            .collect()
    }

    #[test]
    fn records_are_written_one_row_a_photo_with_empty_cells_for_what_was_not_measured() {
        let photo = judged(&[1.0, 0.5, 0.25], 0.97, 0.01);
        let record = CalibrationRecord::of(&photo, "scene", "Fluorescent", 3, 0.96, -0.2, 1);
        let rows = rows(&[record.clone(), record]);
        assert_eq!(rows.len(), 3);
        assert_eq!(rows[0], HEADER);
        assert_eq!(rows[1].len(), HEADER.len());
        assert_eq!(&rows[1][..3], ["scene", "Fluorescent", "3"]);
        assert!((rows[1][3].parse::<f64>().unwrap() - gfc(&photo)).abs() < 1e-6);
        assert_eq!(rows[1][4], "0.960000");
        assert_eq!(rows[1][5], "-0.200000");
        assert_eq!(rows[1][11], "1");
        assert_eq!(rows[1][12], "", "no CCT was measured without a truth");
    }

    #[test]
    fn a_set_name_with_a_comma_reads_back_as_one_cell() {
        let photo = judged(&[1.0, 0.5, 0.25], 0.97, 0.01);
        let record =
            CalibrationRecord::of(&photo, "Philips Hue, Canon", "MixedLed", 0, 0.9, 0.0, 0);
        let rows = rows(&[record]);
        assert_eq!(rows[1][0], "Philips Hue, Canon");
        assert_eq!(rows[1].len(), HEADER.len());
    }
}
