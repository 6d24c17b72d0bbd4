//! Datasets travel through pandas, pyarrow, polars and DuckDB and back (issue 15, item 8):
//! a dataset re-written by pandas/pyarrow (snappy, their default) could not be read, and a
//! plain pandas round trip failed on the `sample` column.
//!
//! The fixtures under `tests/fixtures/interop` were made by `tools/parquet_fixtures.py`
//! from a six-sample dataset spdcam wrote (`original/`): each other directory holds the same
//! table written by one tool (snappy, zstd and gzip pages, nullable columns, pandas' index
//! column, large strings). Each must read back to exactly the original's values.

use parquet::basic::Compression;
use parquet::file::reader::{FileReader, SerializedFileReader};
use spdcam_core::dataset::{Dataset, SampleBatch};
use std::path::{Path, PathBuf};

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/interop")
}

fn load(name: &str) -> SampleBatch {
    let dir = fixtures().join(name);
    Dataset::open(&dir)
        .and_then(|d| d.load())
        .unwrap_or_else(|e| panic!("{name}: {e}"))
}

#[test]
fn tables_written_by_other_tools_read_back_to_the_same_values() {
    let original = load("original");
    assert_eq!(original.len(), 6);
    let writers = [
        "pyarrow-snappy",
        "pyarrow-zstd",
        "pyarrow-gzip",
        "pandas-roundtrip",
        "pandas-index",
        "polars",
        "duckdb",
    ];
    for name in writers {
        assert_eq!(load(name), original, "{name}");
    }
}

/// The page compression of a fixture's sample file and whether it has pandas' index column.
fn codec_and_index(name: &str) -> (Compression, bool) {
    let path = fixtures().join(name).join("samples/part-00000.parquet");
    let reader = SerializedFileReader::new(std::fs::File::open(path).unwrap()).unwrap();
    let meta = reader.metadata();
    let codec = meta.row_group(0).column(0).compression();
    let schema = meta.file_metadata().schema_descr();
    let index = (0..schema.num_columns()).any(|i| schema.column(i).name() == "__index_level_0__");
    (codec, index)
}

#[test]
fn the_fixtures_hold_what_they_claim() {
    // Guards the test above against fixtures that lost their point.
    let snappy = |c: Compression| c == Compression::SNAPPY;
    let zstd = |c: Compression| matches!(c, Compression::ZSTD(_));
    let gzip = |c: Compression| matches!(c, Compression::GZIP(_));
    for (name, codec_ok, index) in [
        (
            "pyarrow-snappy",
            &snappy as &dyn Fn(Compression) -> bool,
            false,
        ),
        ("pyarrow-zstd", &zstd, false),
        ("pyarrow-gzip", &gzip, false),
        ("pandas-roundtrip", &snappy, false),
        ("pandas-index", &snappy, true),
        ("polars", &zstd, false),
        ("duckdb", &snappy, false),
    ] {
        let (codec, has_index) = codec_and_index(name);
        assert!(codec_ok(codec), "{name}: {codec:?}");
        assert_eq!(has_index, index, "{name}");
    }
}
