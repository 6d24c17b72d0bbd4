//! Writing one sample file: a Parquet file with one row group, flat and wide, so that
//! pandas, polars, DuckDB and Spark read it as it is (`file_read` reads it back).

use super::batch::{fields, Columns, Field, Precision, SampleBatch};
use crate::error::{Error, Result};
use parquet::basic::{
    Compression as ParquetCompression, ConvertedType, Encoding, LogicalType, Repetition,
    Type as PhysicalType, ZstdLevel,
};
use parquet::data_type::{ByteArray, DoubleType, FloatType, Int32Type, Int64Type};
use parquet::file::properties::{EnabledStatistics, WriterProperties};
use parquet::file::writer::{SerializedColumnWriter, SerializedFileWriter};
use parquet::schema::types::{ColumnPath, Type};
use std::sync::Arc;

/// How a sample file is encoded: its compression and the precision of its float columns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FileFormat {
    /// Page compression.
    pub compression: Compression,
    /// FLOAT or DOUBLE for the features.
    pub features: Precision,
    /// FLOAT or DOUBLE for the SPD and weight columns.
    pub values: Precision,
}

/// Page compression of a sample file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Compression {
    /// Uncompressed pages.
    None,
    /// Zstandard (RFC 8878) at the given level (1–22), which pandas, polars, DuckDB and Spark
    /// read.
    Zstd(i32),
}

/// The zstd level sample files are written at: on 20,000 `--fast` samples levels 3 and 9 make
/// the files only 0.6 % and 1.4 % smaller than level 1, at several times its cost (float
/// mantissas are close to random; what compresses is their sign and exponent bytes, which
/// byte-stream split puts side by side).
pub const ZSTD_LEVEL: i32 = 1;

impl FileFormat {
    /// The format spdcam writes for `columns`: zstd, every float column (features, SPDs,
    /// weights) in the dataset's precision, float pages byte-stream split.
    pub fn for_columns(columns: &Columns) -> FileFormat {
        FileFormat {
            compression: Compression::Zstd(ZSTD_LEVEL),
            features: columns.feature_precision,
            values: columns.feature_precision,
        }
    }

    /// The format of the first datasets (still read): uncompressed PLAIN pages, SPDs and
    /// weights as DOUBLE. Kept to compare the current format against.
    pub fn uncompressed_float64_values(columns: &Columns) -> FileFormat {
        FileFormat {
            compression: Compression::None,
            features: columns.feature_precision,
            values: Precision::Float64,
        }
    }

    fn physical_type(&self, field: Field) -> PhysicalType {
        let float = |p: Precision| match p {
            Precision::Float32 => PhysicalType::FLOAT,
            Precision::Float64 => PhysicalType::DOUBLE,
        };
        match field {
            Field::Sample => PhysicalType::INT64,
            Field::Family => PhysicalType::BYTE_ARRAY,
            Field::Feature(_) => float(self.features),
            Field::Spd(_) | Field::Weight(_) => float(self.values),
            Field::Attempts => PhysicalType::INT32,
        }
    }
}

fn schema(columns: &Columns, format: &FileFormat) -> Result<Type> {
    let names = columns.column_names();
    let fields = fields(columns)
        .into_iter()
        .zip(&names)
        .map(|(field, name)| {
            let mut builder = Type::primitive_type_builder(name, format.physical_type(field))
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

/// The bytes of one sample file holding `batch` in spdcam's format
/// ([`FileFormat::for_columns`]).
pub fn encode_parquet(columns: &Columns, batch: &SampleBatch) -> Result<Vec<u8>> {
    encode_parquet_as(columns, batch, &FileFormat::for_columns(columns))
}

/// The bytes of one sample file holding `batch` in `format`: Parquet with one row group,
/// dictionary encoding only for `family`, when compressed `sample` delta-encoded and float
/// columns byte-stream split
/// (the sign and exponent bytes of neighbouring values then lie together, which zstd packs
/// to almost nothing), min/max statistics only for `sample`, `family` and `attempts`
/// (statistics of the float columns would cost a third of the encoding time and help no
/// reader of random samples).
pub fn encode_parquet_as(
    columns: &Columns,
    batch: &SampleBatch,
    format: &FileFormat,
) -> Result<Vec<u8>> {
    let err = parquet_error("writing Parquet");
    let (compression, float_encoding) = match format.compression {
        Compression::None => (ParquetCompression::UNCOMPRESSED, Encoding::PLAIN),
        Compression::Zstd(level) => (
            ParquetCompression::ZSTD(ZstdLevel::try_new(level).map_err(&err)?),
            Encoding::BYTE_STREAM_SPLIT,
        ),
    };
    let mut properties = WriterProperties::builder()
        .set_compression(compression)
        .set_dictionary_enabled(false)
        .set_column_dictionary_enabled(ColumnPath::from("family"), true)
        .set_statistics_enabled(EnabledStatistics::None);
    for name in ["sample", "family", "attempts"] {
        properties = properties
            .set_column_statistics_enabled(ColumnPath::from(name), EnabledStatistics::Chunk);
    }
    let names = columns.column_names();
    for (field, name) in fields(columns).into_iter().zip(&names) {
        if matches!(field, Field::Feature(_) | Field::Spd(_) | Field::Weight(_)) {
            properties =
                properties.set_column_encoding(ColumnPath::from(name.as_str()), float_encoding);
        }
    }
    if format.compression != Compression::None {
        // Consecutive sample numbers: one delta and a bit width per block.
        properties = properties
            .set_column_encoding(ColumnPath::from("sample"), Encoding::DELTA_BINARY_PACKED);
    }
    let bytes = |p: Precision| match p {
        Precision::Float32 => 4,
        Precision::Float64 => 8,
    };
    let row_bytes = 16
        + batch.families.first().map_or(0, String::len)
        + bytes(format.features) * columns.feature_count()
        + bytes(format.values) * (columns.spd_len() + columns.weight_count());
    let capacity = match format.compression {
        Compression::None => batch.len() * row_bytes + (1 << 16),
        Compression::Zstd(_) => batch.len() * row_bytes / 3 + (1 << 16),
    };
    let mut writer = SerializedFileWriter::new(
        Vec::with_capacity(capacity),
        Arc::new(schema(columns, format)?),
        Arc::new(properties.build()),
    )
    .map_err(&err)?;
    let mut group = writer.next_row_group().map_err(&err)?;
    let n = batch.len();
    let mut scratch = (Vec::with_capacity(n), Vec::with_capacity(n));
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
            Field::Attempts => {
                let v: Vec<i32> = batch.attempts.iter().map(|&a| a as i32).collect();
                column.typed::<Int32Type>().write_batch(&v, None, None)
            }
            Field::Feature(j) => {
                let values = (0..n).map(|r| batch.features[r * batch.feature_count + j]);
                write_floats(&mut column, values, format.features, &mut scratch)
            }
            Field::Spd(j) => {
                let values = (0..n).map(|r| batch.spds[r * batch.spd_len + j]);
                write_floats(&mut column, values, format.values, &mut scratch)
            }
            Field::Weight(j) => {
                let values = (0..n).map(|r| batch.weights[r * batch.weight_count + j]);
                write_floats(&mut column, values, format.values, &mut scratch)
            }
        };
        written.map_err(&err)?;
        column.close().map_err(&err)?;
    }
    group.close().map_err(&err)?;
    writer.into_inner().map_err(&err)
}

/// Writes one float column in `precision`, through the scratch vectors (FLOAT, DOUBLE).
fn write_floats(
    column: &mut SerializedColumnWriter<'_>,
    values: impl Iterator<Item = f64>,
    precision: Precision,
    (singles, doubles): &mut (Vec<f32>, Vec<f64>),
) -> parquet::errors::Result<usize> {
    match precision {
        Precision::Float32 => {
            singles.clear();
            singles.extend(values.map(|v| v as f32));
            column.typed::<FloatType>().write_batch(singles, None, None)
        }
        Precision::Float64 => {
            doubles.clear();
            doubles.extend(values);
            column
                .typed::<DoubleType>()
                .write_batch(doubles, None, None)
        }
    }
}
