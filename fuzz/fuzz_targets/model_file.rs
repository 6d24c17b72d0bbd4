//! The model file parser: any bytes give a model or a clear error ("not a spdcam model",
//! "truncated", "damaged"), never a panic or an allocation the file's size does not justify;
//! a model that loads estimates an SPD from a row of features.
#![no_main]

use libfuzzer_sys::fuzz_target;
use spdcam_infer::Model;

fuzz_target!(|data: &[u8]| {
    let Ok(model) = Model::from_bytes(data) else {
        return;
    };
    let width = model.header().feature_names.len();
    let row: Vec<f64> = (0..width).map(|j| 40.0 + (j % 7) as f64 * 25.0).collect();
    let _ = model.estimate_rows(&row);
});
