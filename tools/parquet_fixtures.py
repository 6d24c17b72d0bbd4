"""Rewrites a small spdcam dataset the way other tools write Parquet, for the interop test.

    python tools/parquet_fixtures.py ORIGINAL_DATASET crates/spdcam-core/tests/fixtures/interop

ORIGINAL_DATASET is a dataset spdcam wrote with one sample file, e.g.

    spdcam generate --lighting gaussian:4 --count 6 --chunk-size 6 --fast --seed 4 -o orig

The output holds `original/` (the dataset as spdcam wrote it) and one directory per writer,
each a dataset whose sample file that writer produced from the original's table (the
manifest is the original's without checksums, since the bytes differ):

- `pyarrow-snappy`, `pyarrow-zstd`, `pyarrow-gzip`: pyarrow.parquet.write_table;
- `pandas-index`: pandas.read_parquet then DataFrame.to_parquet with a non-default index,
  stored as the extra column `__index_level_0__`;
- `pandas-roundtrip`: a plain pandas read and write (snappy, nullable columns);
- `polars`: polars.read_parquet then DataFrame.write_parquet (zstd, large strings);
- `duckdb`: DuckDB's COPY ... TO (snappy).

Needs pyarrow, pandas, polars and duckdb (pip install pyarrow pandas polars duckdb).
"""

import json
import shutil
import sys
from pathlib import Path

import duckdb
import pandas as pd
import polars as pl
import pyarrow.parquet as pq

PART = "samples/part-00000.parquet"


def dataset_like(original: Path, out: Path) -> Path:
    """A copy of the original's manifest without checksums; returns the sample file path."""
    (out / "samples").mkdir(parents=True, exist_ok=True)
    manifest = json.loads((original / "manifest.json").read_text())
    for entry in manifest["files"]:
        entry.pop("sha256", None)
    (out / "manifest.json").write_text(json.dumps(manifest, indent=2) + "\n")
    return out / PART


def main() -> None:
    original, out = Path(sys.argv[1]), Path(sys.argv[2])
    if out.exists():
        shutil.rmtree(out)
    shutil.copytree(original, out / "original")
    source = original / PART
    table = pq.read_table(source)

    for codec in ["snappy", "zstd", "gzip"]:
        pq.write_table(table, dataset_like(original, out / f"pyarrow-{codec}"), compression=codec)

    frame = pd.read_parquet(source)
    frame.to_parquet(dataset_like(original, out / "pandas-roundtrip"))
    indexed = frame.copy()
    indexed.index = indexed.index * 10 + 3
    indexed.to_parquet(dataset_like(original, out / "pandas-index"), index=True)

    pl.read_parquet(source).write_parquet(dataset_like(original, out / "polars"))

    target = dataset_like(original, out / "duckdb")
    duckdb.sql(f"COPY (SELECT * FROM read_parquet('{source}')) TO '{target}' (FORMAT parquet)")

    for path in sorted(out.glob(f"*/{PART}")):
        meta = pq.ParquetFile(path).metadata
        codecs = {meta.row_group(0).column(i).compression for i in range(meta.num_columns)}
        print(f"{path.parent.parent.name:18} {meta.num_columns:4} columns  {','.join(sorted(codecs))}")


if __name__ == "__main__":
    main()
