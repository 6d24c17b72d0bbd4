//! Reading one sample file: spdcam's own, and the same table written back by pandas,
//! pyarrow, polars, DuckDB or Spark.
//!
//! Columns are found by name (their order, and extra columns such as pandas' index
//! `__index_level_0__`, do not matter); a column may be REQUIRED or OPTIONAL (as those tools
//! write them) as long as it holds no null; integers may be INT32 or INT64 and floats FLOAT or
//! DOUBLE; any number of row groups; the compressions the workspace enables. The decoded
//! size is checked against [`limits::CHUNK_BYTES`] before anything is allocated.

use super::batch::{fields, Columns, Field, SampleBatch};
use crate::error::{Error, Result};
use crate::limits;
use bytes::Bytes;
use parquet::column::reader::{ColumnReader, ColumnReaderImpl};
use parquet::data_type::DataType;
use parquet::file::reader::{FileReader, SerializedFileReader};
use std::collections::HashMap;

/// Decodes the sample file `bytes` (named `source` in errors) whose columns the manifest
/// describes as `columns`.
pub(crate) fn decode(bytes: Bytes, columns: &Columns, source: &str) -> Result<SampleBatch> {
    let bad = |msg: String| Error::parse(source, msg);
    let reader = SerializedFileReader::new(bytes)
        .map_err(|e| bad(format!("not a readable Parquet file: {e}")))?;
    let descr = reader.metadata().file_metadata().schema_descr_ptr();
    let mut by_name: HashMap<String, usize> = HashMap::new();
    for i in 0..descr.num_columns() {
        let c = descr.column(i);
        if c.path().parts().len() == 1 {
            by_name.insert(c.name().to_string(), i);
        }
    }
    check_feature_columns(&descr, columns).map_err(bad)?;
    let names = columns.column_names();
    let wanted = fields(columns);
    let mut index = Vec::with_capacity(names.len());
    for name in &names {
        let i = *by_name.get(name).ok_or_else(|| {
            let nested = (0..descr.num_columns()).any(|i| descr.column(i).name() == name);
            bad(if nested {
                format!("column '{name}' is nested (a list or struct); spdcam reads flat columns")
            } else {
                format!(
                    "column '{name}' is missing (the file has {} columns, the manifest describes {})",
                    descr.num_columns(),
                    names.len()
                )
            })
        })?;
        let c = descr.column(i);
        if c.max_rep_level() != 0 || c.max_def_level() > 1 {
            return Err(bad(format!(
                "column '{name}' is a repeated or nested column; spdcam reads flat columns"
            )));
        }
        index.push(i);
    }
    let rows = reader.metadata().file_metadata().num_rows();
    let rows = u64::try_from(rows).map_err(|_| bad(format!("{rows} rows declared")))?;
    let values_per_row =
        (columns.feature_count() + columns.spd_len() + columns.weight_count()) as u64 + 3;
    limits::CHUNK_BYTES.check(
        limits::product(&[rows, values_per_row, 8]),
        &format!("{source} ({rows} rows of {values_per_row} values)"),
    )?;
    let mut batch = columns.batch();
    for g in 0..reader.num_row_groups() {
        let group = reader.get_row_group(g).map_err(|e| bad(e.to_string()))?;
        let group_rows = group.metadata().num_rows();
        let group_rows = usize::try_from(group_rows)
            .ok()
            .filter(|&r| (batch.len() + r) as u64 <= rows)
            .ok_or_else(|| {
                bad(format!(
                    "row group {g} declares {group_rows} rows, the file {rows}"
                ))
            })?;
        let start = batch.len();
        batch
            .features
            .resize((start + group_rows) * batch.feature_count, 0.0);
        batch.spds.resize((start + group_rows) * batch.spd_len, 0.0);
        batch
            .weights
            .resize((start + group_rows) * batch.weight_count, 0.0);
        for ((&field, &i), name) in wanted.iter().zip(&index).zip(&names) {
            let column = group.get_column_reader(i).map_err(|e| bad(e.to_string()))?;
            let max_def = descr.column(i).max_def_level();
            let cell = Cell {
                rows: group_rows,
                max_def,
                name,
                source,
            };
            let (target, stride, j) = match field {
                Field::Sample => {
                    for v in cell.integers(column)? {
                        let s = u64::try_from(v).map_err(|_| {
                            bad(format!("column 'sample' holds the negative number {v}"))
                        })?;
                        batch.samples.push(s);
                    }
                    continue;
                }
                Field::Attempts => {
                    for v in cell.integers(column)? {
                        let a = u32::try_from(v).map_err(|_| {
                            bad(format!("column 'attempts' holds {v}, not a count"))
                        })?;
                        batch.attempts.push(a);
                    }
                    continue;
                }
                Field::Family => {
                    let ColumnReader::ByteArrayColumnReader(mut r) = column else {
                        return Err(bad(format!("column '{name}' does not hold text")));
                    };
                    for v in cell.read(&mut r)? {
                        let text = v
                            .as_utf8()
                            .map_err(|_| bad("a family name is not UTF-8".into()))?;
                        batch.families.push(text.to_string());
                    }
                    continue;
                }
                Field::Feature(j) => (&mut batch.features, batch.feature_count, j),
                Field::Spd(j) => (&mut batch.spds, batch.spd_len, j),
                Field::Weight(j) => (&mut batch.weights, batch.weight_count, j),
            };
            for (r, v) in cell.numbers(column)?.into_iter().enumerate() {
                if !v.is_finite() {
                    return Err(bad(format!(
                        "column '{name}', row {}: {v} is not a finite number",
                        start + r + 1
                    )));
                }
                target[(start + r) * stride + j] = v;
            }
        }
    }
    if batch.len() as u64 != rows {
        return Err(bad(format!(
            "the row groups hold {} rows, the file declares {rows}",
            batch.len()
        )));
    }
    Ok(batch)
}

/// Refuses a file holding feature columns (named as charts name them,
/// [`crate::chart::is_feature_name`]) that the manifest does not describe: a manifest naming
/// some of a file's features would read, train on and export only those.
fn check_feature_columns(
    descr: &parquet::schema::types::SchemaDescriptor,
    columns: &Columns,
) -> std::result::Result<(), String> {
    let in_file: Vec<String> = (0..descr.num_columns())
        .map(|i| descr.column(i))
        .filter(|c| c.path().parts().len() == 1)
        .map(|c| c.name().to_string())
        .filter(|n| crate::chart::is_feature_name(n) || columns.feature_names.contains(n))
        .collect();
    if in_file.iter().all(|n| columns.feature_names.contains(n)) {
        return Ok(());
    }
    Err(format!(
        "the file holds {} feature columns ({}) but the manifest names {} ({}): the manifest \
         was edited or damaged; restore the one spdcam wrote",
        in_file.len(),
        super::manifest::name_range(&in_file),
        columns.feature_count(),
        super::manifest::name_range(&columns.feature_names)
    ))
}

/// One column chunk to read: its rows, whether it may hold nulls, and names for errors.
struct Cell<'a> {
    rows: usize,
    max_def: i16,
    name: &'a str,
    source: &'a str,
}

impl Cell<'_> {
    fn error(&self, message: String) -> Error {
        Error::parse(self.source, format!("column '{}': {message}", self.name))
    }

    /// Every value of the chunk; a null is an error.
    fn read<T: DataType>(&self, reader: &mut ColumnReaderImpl<T>) -> Result<Vec<T::T>> {
        let mut values = Vec::with_capacity(self.rows);
        let mut levels = Vec::with_capacity(if self.max_def > 0 { self.rows } else { 0 });
        let (records, _, _) = reader
            .read_records(
                self.rows,
                (self.max_def > 0).then_some(&mut levels),
                None,
                &mut values,
            )
            .map_err(|e| self.error(e.to_string()))?;
        if records != self.rows {
            return Err(self.error(format!(
                "{records} values where the row group has {}",
                self.rows
            )));
        }
        if values.len() != self.rows {
            let row = levels.iter().position(|&l| l < self.max_def).unwrap_or(0);
            return Err(self.error(format!(
                "row {} is empty (null); spdcam needs every value",
                row + 1
            )));
        }
        Ok(values)
    }

    fn numbers(&self, column: ColumnReader) -> Result<Vec<f64>> {
        Ok(match column {
            ColumnReader::FloatColumnReader(mut r) => {
                self.read(&mut r)?.into_iter().map(f64::from).collect()
            }
            ColumnReader::DoubleColumnReader(mut r) => self.read(&mut r)?,
            ColumnReader::Int32ColumnReader(mut r) => {
                self.read(&mut r)?.into_iter().map(f64::from).collect()
            }
            ColumnReader::Int64ColumnReader(mut r) => {
                self.read(&mut r)?.into_iter().map(|v| v as f64).collect()
            }
            _ => return Err(self.error("does not hold numbers".into())),
        })
    }

    fn integers(&self, column: ColumnReader) -> Result<Vec<i64>> {
        Ok(match column {
            ColumnReader::Int32ColumnReader(mut r) => {
                self.read(&mut r)?.into_iter().map(i64::from).collect()
            }
            ColumnReader::Int64ColumnReader(mut r) => self.read(&mut r)?,
            _ => return Err(self.error("does not hold whole numbers".into())),
        })
    }
}
