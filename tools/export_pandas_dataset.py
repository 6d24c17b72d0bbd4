"""Writes crates/spdcam-core/tests/reference/pandas-dataset: a dataset spdcam generated,
read by pandas and written back by pandas (pyarrow), one file with snappy (pandas' default)
and one with gzip, as a user who edits a dataset in Python would. The test
`files_written_by_pandas_read_back` checks that spdcam reads them and finds the numbers it
generated.

    spdcam generate --lighting gaussian:4 --count 12 --chunk-size 6 --seed 5 --fast \
        --spd-grid 400-700:50 -o /tmp/g
    pip install pandas pyarrow
    python tools/export_pandas_dataset.py /tmp/g
"""
import shutil
import sys
from pathlib import Path

import pandas as pd

src = Path(sys.argv[1])
dst = Path(__file__).resolve().parent.parent / "crates/spdcam-core/tests/reference/pandas-dataset"
(dst / "samples").mkdir(parents=True, exist_ok=True)
shutil.copy(src / "manifest.json", dst / "manifest.json")
for k, codec in [(0, "snappy"), (1, "gzip")]:
    name = f"samples/part-{k:05}.parquet"
    frame = pd.read_parquet(src / name)
    frame.to_parquet(dst / name, compression=codec, index=False)
print(f"wrote {dst}: pandas {pd.__version__}")
