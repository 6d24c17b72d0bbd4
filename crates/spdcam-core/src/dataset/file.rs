//! Writing one sample file: a Parquet file with one row group, flat and wide, so that
//! pandas, polars, DuckDB and Spark read it as it is (`file_read` reads it back).

use super::batch::{Columns, Precision, SampleBatch};
use crate::error::{Error, Result};
use parquet::basic::{ConvertedType, LogicalType, Repetition, Type as PhysicalType};
use parquet::data_type::{ByteArray, DoubleType, FloatType, Int32Type, Int64Type};
use parquet::file::properties::{EnabledStatistics, WriterProperties};
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::types::{ColumnPath, Type};
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
