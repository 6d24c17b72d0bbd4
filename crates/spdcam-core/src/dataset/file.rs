//! One sample file: a Parquet file with one row group, flat and wide, so that pandas,
//! polars, DuckDB and Spark read it as it is.

use super::batch::{Columns, Precision, SampleBatch};
use crate::error::{Error, Result};
use parquet::basic::{ConvertedType, LogicalType, Repetition, Type as PhysicalType};
use parquet::column::reader::{ColumnReader, ColumnReaderImpl};
use parquet::data_type::{ByteArray, DataType, DoubleType, FloatType, Int32Type, Int64Type};
use parquet::file::properties::{EnabledStatistics, WriterProperties};
use parquet::file::reader::{FileReader, SerializedFileReader};
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::types::{ColumnPath, Type};
use std::path::Path;
use std::sync::Arc;

/// What each column holds, in file order.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Field {
    Sample,
    Family,
    Feature(usize),
    Spd(usize),
    Weight(usize),
    Attempts,
}

fn fields(columns: &Columns) -> Vec<Field> {
    let mut f = vec![Field::Sample, Field::Family];
    f.extend((0..columns.feature_count()).map(Field::Feature));
    f.extend((0..columns.spd_len()).map(Field::Spd));
    f.extend((0..columns.weight_count()).map(Field::Weight));
    f.push(Field::Attempts);
    f
}

fn physical_type(field: Field, columns: &Columns) -> PhysicalType {
    match field {
        Field::Sample => PhysicalType::INT64,
        Field::Family => PhysicalType::BYTE_ARRAY,
        Field::Feature(_) if columns.feature_precision == Precision::Float32 => PhysicalType::FLOAT,
        Field::Feature(_) | Field::Spd(_) | Field::Weight(_) => PhysicalType::DOUBLE,
        Field::Attempts => PhysicalType::INT32,
    }
}

fn schema(columns: &Columns) -> Result<Type> {
    let names = columns.column_names();
    let fields = fields(columns)
        .into_iter()
        .zip(&names)
        .map(|(field, name)| {
            let mut builder = Type::primitive_type_builder(name, physical_type(field, columns))
                .with_repetition(Repetition::REQUIRED);
            if field == Field::Family {
                builder = builder
                    .with_logical_type(Some(LogicalType::String))
                    .with_converted_type(ConvertedType::UTF8);
            }
            builder.build().map(Arc::new)
        })
        .collect::<Result<Vec<_>, _>>()
        .map_err(parquet_error("building the Parquet schema"))?;
    Type::group_type_builder("spdcam_samples")
        .with_fields(fields)
        .build()
        .map_err(parquet_error("building the Parquet schema"))
}

fn parquet_error(context: &str) -> impl Fn(parquet::errors::ParquetError) -> Error + '_ {
    move |e| Error::invalid(format!("{context}: {e}"))
}

/// The bytes of one sample file holding `batch`: Parquet with one row group, uncompressed
/// PLAIN floats, dictionary encoding only for `family`, min/max statistics only for
/// `sample`, `family` and `attempts` (statistics of the float columns would cost a third
/// of the encoding time and help no reader of random samples).
pub fn encode_parquet(columns: &Columns, batch: &SampleBatch) -> Result<Vec<u8>> {
    let err = parquet_error("writing Parquet");
    let mut properties = WriterProperties::builder()
        .set_dictionary_enabled(false)
        .set_column_dictionary_enabled(ColumnPath::from("family"), true)
        .set_statistics_enabled(EnabledStatistics::None);
    for name in ["sample", "family", "attempts"] {
        properties = properties
            .set_column_statistics_enabled(ColumnPath::from(name), EnabledStatistics::Chunk);
    }
    let feature_bytes = match columns.feature_precision {
        Precision::Float32 => 4,
        Precision::Float64 => 8,
    };
    let row_bytes = 16
        + batch.families.first().map_or(0, String::len)
        + feature_bytes * columns.feature_count()
        + 8 * (columns.spd_len() + columns.weight_count());
    let buffer = Vec::with_capacity(batch.len() * row_bytes + (1 << 16));
    let mut writer = SerializedFileWriter::new(
        buffer,
        Arc::new(schema(columns)?),
        Arc::new(properties.build()),
    )
    .map_err(&err)?;
    let mut group = writer.next_row_group().map_err(&err)?;
    let n = batch.len();
    let strided = |values: &[f64], stride: usize, j: usize| -> Vec<f64> {
        (0..n).map(|r| values[r * stride + j]).collect()
    };
    for field in fields(columns) {
        let mut column = group
            .next_column()
            .map_err(&err)?
            .ok_or_else(|| Error::invalid("writing Parquet: fewer columns than the schema"))?;
        let written = match field {
            Field::Sample => {
                let v: Vec<i64> = batch.samples.iter().map(|&s| s as i64).collect();
                column.typed::<Int64Type>().write_batch(&v, None, None)
            }
            Field::Family => {
                let v: Vec<ByteArray> = batch.families.iter().map(|f| f.as_str().into()).collect();
                column
                    .typed::<parquet::data_type::ByteArrayType>()
                    .write_batch(&v, None, None)
            }
            Field::Feature(j) if columns.feature_precision == Precision::Float32 => {
                let v: Vec<f32> = (0..n)
                    .map(|r| batch.features[r * batch.feature_count + j] as f32)
                    .collect();
                column.typed::<FloatType>().write_batch(&v, None, None)
            }
            Field::Feature(j) => column.typed::<DoubleType>().write_batch(
                &strided(&batch.features, batch.feature_count, j),
                None,
                None,
            ),
            Field::Spd(j) => column.typed::<DoubleType>().write_batch(
                &strided(&batch.spds, batch.spd_len, j),
                None,
                None,
            ),
            Field::Weight(j) => column.typed::<DoubleType>().write_batch(
                &strided(&batch.weights, batch.weight_count, j),
                None,
                None,
            ),
            Field::Attempts => {
                let v: Vec<i32> = batch.attempts.iter().map(|&a| a as i32).collect();
                column.typed::<Int32Type>().write_batch(&v, None, None)
            }
        };
        written.map_err(&err)?;
        column.close().map_err(&err)?;
    }
    group.close().map_err(&err)?;
    writer.into_inner().map_err(&err)
}

/// Opens a sample file and checks its columns against `columns`; returns the reader.
fn open(path: &Path, columns: &Columns) -> Result<SerializedFileReader<std::fs::File>> {
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let bad = |msg: String| Error::parse(path.display().to_string(), msg);
    let reader = SerializedFileReader::new(file)
        .map_err(|e| bad(format!("not a readable Parquet file: {e}")))?;
    let descr = reader.metadata().file_metadata().schema_descr_ptr();
    let names = columns.column_names();
    if descr.num_columns() != names.len() {
        return Err(bad(format!(
            "{} columns, the manifest describes {}",
            descr.num_columns(),
            names.len()
        )));
    }
    for (i, (field, name)) in fields(columns).into_iter().zip(&names).enumerate() {
        let c = descr.column(i);
        if c.name() != name || c.physical_type() != physical_type(field, columns) {
            return Err(bad(format!(
                "column {} is '{}' ({}), the manifest expects '{name}' ({})",
                i + 1,
                c.name(),
                c.physical_type(),
                physical_type(field, columns)
            )));
        }
        if c.max_def_level() != 0 || c.max_rep_level() != 0 {
            return Err(bad(format!(
                "column '{name}' is not a required flat column"
            )));
        }
    }
    Ok(reader)
}

/// The number of rows of a sample file whose columns match `columns`.
pub(crate) fn row_count(path: &Path, columns: &Columns) -> Result<u64> {
    Ok(open(path, columns)?.metadata().file_metadata().num_rows() as u64)
}

fn read_values<T: DataType>(
    reader: &mut ColumnReaderImpl<T>,
    rows: usize,
    path: &Path,
) -> Result<Vec<T::T>> {
    let mut values = Vec::with_capacity(rows);
    let (records, _, _) = reader
        .read_records(rows, None, None, &mut values)
        .map_err(|e| Error::parse(path.display().to_string(), e.to_string()))?;
    if records != rows || values.len() != rows {
        return Err(Error::parse(
            path.display().to_string(),
            format!("a column holds {records} values where the row group has {rows}"),
        ));
    }
    Ok(values)
}

/// Reads a whole sample file whose columns must match `columns`.
pub(crate) fn decode(path: &Path, columns: &Columns) -> Result<SampleBatch> {
    let reader = open(path, columns)?;
    let bad = |msg: String| Error::parse(path.display().to_string(), msg);
    let mut batch = columns.batch();
    for g in 0..reader.num_row_groups() {
        let group = reader.get_row_group(g).map_err(|e| bad(e.to_string()))?;
        let rows = group.metadata().num_rows() as usize;
        let start = batch.len();
        batch
            .features
            .resize((start + rows) * batch.feature_count, 0.0);
        batch.spds.resize((start + rows) * batch.spd_len, 0.0);
        batch
            .weights
            .resize((start + rows) * batch.weight_count, 0.0);
        let scatter = |target: &mut Vec<f64>, stride: usize, j: usize, values: Vec<f64>| {
            for (r, v) in values.into_iter().enumerate() {
                target[(start + r) * stride + j] = v;
            }
        };
        for (i, field) in fields(columns).into_iter().enumerate() {
            let column = group.get_column_reader(i).map_err(|e| bad(e.to_string()))?;
            match (field, column) {
                (Field::Sample, ColumnReader::Int64ColumnReader(mut r)) => batch.samples.extend(
                    read_values(&mut r, rows, path)?
                        .into_iter()
                        .map(|v| v as u64),
                ),
                (Field::Family, ColumnReader::ByteArrayColumnReader(mut r)) => {
                    for v in read_values(&mut r, rows, path)? {
                        let text = v
                            .as_utf8()
                            .map_err(|_| bad("a family name is not UTF-8".into()))?;
                        batch.families.push(text.to_string());
                    }
                }
                (Field::Feature(j), ColumnReader::FloatColumnReader(mut r)) => {
                    let values = read_values(&mut r, rows, path)?;
                    let values = values.into_iter().map(f64::from).collect();
                    scatter(&mut batch.features, batch.feature_count, j, values)
                }
                (Field::Feature(j), ColumnReader::DoubleColumnReader(mut r)) => {
                    let values = read_values(&mut r, rows, path)?;
                    scatter(&mut batch.features, batch.feature_count, j, values)
                }
                (Field::Spd(j), ColumnReader::DoubleColumnReader(mut r)) => {
                    let values = read_values(&mut r, rows, path)?;
                    scatter(&mut batch.spds, batch.spd_len, j, values)
                }
                (Field::Weight(j), ColumnReader::DoubleColumnReader(mut r)) => {
                    let values = read_values(&mut r, rows, path)?;
                    scatter(&mut batch.weights, batch.weight_count, j, values)
                }
                (Field::Attempts, ColumnReader::Int32ColumnReader(mut r)) => batch.attempts.extend(
                    read_values(&mut r, rows, path)?
                        .into_iter()
                        .map(|v| v as u32),
                ),
                (field, _) => {
                    return Err(bad(format!(
                        "column {} ({field:?}) has an unexpected type",
                        i + 1
                    )))
                }
            }
        }
    }
    Ok(batch)
}
