//! Feature rows, the input every estimate is made from: column names and row-major values,
//! read from a features CSV, given as values, or taken from photo analyses.

use crate::error::{InferError, Result};
use spdcam_core::photo::PhotoAnalysis;
use std::path::Path;

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
        if columns == 0 || values.is_empty() || !values.len().is_multiple_of(columns) {
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
}
