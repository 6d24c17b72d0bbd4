//! The spectral CSV parser: any text gives a set or a clear error; a set survives its own
//! CSV text unchanged and resamples onto the simulation grid.
#![no_main]

use libfuzzer_sys::fuzz_target;
use spdcam_core::spectral::{Extrapolation, Grid, Interpolation, SpectralSet};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(set) = SpectralSet::from_csv_str(text, "fuzz.csv") else {
        return;
    };
    let again = SpectralSet::from_csv_str(&set.to_csv_string(), "again.csv")
        .expect("a parsed set reads back from its own CSV");
    assert_eq!(set, again);
    for interpolation in [Interpolation::Auto, Interpolation::Linear] {
        let _ = set.resample(&Grid::SIMULATION, interpolation, Extrapolation::Zero);
    }
});
