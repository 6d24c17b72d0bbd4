//! Locating the measured data that tests read (never shipped): `$SPDCAM_DATA`, else
//! `../shared/data` beside the repository. Second tier only: the tests that use it declare
//! it under `#[cfg(feature = "measured-data")]`, and it compiles to nothing without it.
#![cfg(feature = "measured-data")]

use std::path::PathBuf;

/// The measured-data directory; panics with instructions when it is missing, so a test
/// that needs it fails loudly instead of passing without checking anything.
pub fn data_dir() -> PathBuf {
    let dir = spdcam_test_data::measured_data_dir();
    assert!(
        dir.join("thesis").is_dir(),
        "measured data not found at {}: put the shared data beside the repository or set SPDCAM_DATA",
        dir.display()
    );
    dir
}
