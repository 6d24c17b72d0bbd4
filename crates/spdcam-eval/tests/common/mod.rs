//! What the measured-data tests of the protocols share: the second tier only
//! (`--features measured-data`).
#![cfg(feature = "measured-data")]

use std::path::PathBuf;

/// The measured data: `$SPDCAM_DATA`, else `../shared/data` beside the repository.
pub fn data_dir() -> PathBuf {
    let dir = spdcam_test_data::measured_data_dir();
    assert!(
        dir.join("lamps").is_dir() && dir.join("cameras").is_dir(),
        "measured data not found at {}: set SPDCAM_DATA",
        dir.display()
    );
    dir
}
