//! The feature CSV parser of `spdcam estimate --features`: any text gives rows or a clear
//! error, and rows that parse go through the shipped model or a clear error.
#![no_main]

use libfuzzer_sys::fuzz_target;
use spdcam_core::builtin::DataDir;
use spdcam_core::spectral::Grid;
use spdcam_infer::{Estimator, FeatureRows};
use std::sync::OnceLock;

fn estimator() -> &'static Estimator {
    static ESTIMATOR: OnceLock<Estimator> = OnceLock::new();
    ESTIMATOR.get_or_init(|| {
        Estimator::shipped(DataDir::new(None), Grid::ESTIMATION)
            .expect("the shipped models load")
    })
}

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(rows) = FeatureRows::from_csv_str(text, "fuzz.csv") else {
        return;
    };
    assert_eq!(rows.values.len(), rows.rows * rows.names.len());
    let _ = estimator().estimate_rows(&rows, "fuzz.csv");
});
