//! Datasets: samples of (features, SPD, weights, family) generated with the virtual camera or
//! imported from CSV, stored as a directory that any Parquet reader understands.
//!
//! ```text
//! DIR/manifest.json                 every setting, the columns, counts, the files (last)
//! DIR/samples/part-00000.parquet    rows 0…4095: sample, family, p01_r…, spd_380…, w_…, attempts
//! DIR/samples/part-00001.parquet    …
//! DIR/images/sample-00000000.png    with `--images`
//! DIR/.spdcam-lock                  while a run writes the directory (pid, host)
//! ```
//!
//! `DIR/samples` holds nothing but the Parquet files, so it reads as one table:
//! `pandas.read_parquet("DIR/samples")`, `polars.read_parquet("DIR/samples/*.parquet")`,
//! `SELECT * FROM 'DIR/samples/*.parquet'` in DuckDB, `spark.read.parquet("DIR/samples")`.
//!
//! Sample `i` of a generated set depends only on (seed, i): its light is
//! `lighting.draw(seed, i)` and its camera noise is seeded with [`crate::seed::derive`]`(seed, i)`.
//! File `k` holds samples `[k·chunk, (k+1)·chunk)`, so shards, resumed runs and merged shards
//! give the same files as one uninterrupted run. Every file is written to a temporary name
//! and renamed, and the manifest comes last: an interrupted run leaves no damaged file and
//! resumes where it stopped. The manifest records each file's SHA-256, checked on every
//! read and on resume; one writer at a time holds the directory's lock.

mod batch;
mod csv_io;
mod file;
mod file_read;
mod generate;
mod identity;
mod lock;
mod manifest;
mod merge;
pub mod randomise;
mod reader;
mod spd_map;
mod split;
mod writer;

pub use batch::{Columns, Counts, Precision, SampleBatch, SampleRow};
pub use csv_io::{
    export_csv, import_csv, ExportOptions, ImportOptions, ImportReport, MeasuredPhotos,
    RealPhotoSet, REAL_PHOTO_SETS,
};
pub use file::{encode_parquet, encode_parquet_as, Compression, FileFormat, ZSTD_LEVEL};
pub use generate::{
    raw_features, GenerateEvent, GenerateOptions, GenerateRequest, Generator, Plan,
};
pub use identity::{sample_hash, SeenSamples};
pub use lock::{DirLock, LockOwner, LOCK_FILE};
pub use manifest::{
    sha256_hex, CameraInfo, ChartInfo, FileEntry, GenerateSettings, ImportSource, LightingInfo,
    Manifest, Origin, Pipeline, Shard, FEATURE_SCALE, FORMAT, FORMAT_VERSION, MANIFEST_FILE,
};
pub use merge::{merge, Duplicates, MergeReport};
pub use reader::{Dataset, Verification};
pub use split::{assign_parts, split};
pub use writer::SAMPLES_DIR;

/// Samples per file unless told otherwise.
pub const DEFAULT_CHUNK_SIZE: u64 = 4096;
