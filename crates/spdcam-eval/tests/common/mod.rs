//! What the measured-data tests of the protocols share: the second tier only
//! (`--features measured-data`).
#![cfg(feature = "measured-data")]

use std::path::PathBuf;

/// The measured data: `$SPDCAM_DATA`, else `../shared/data` beside the repository.
pub fn data_dir() -> PathBuf {
    let dir = std::env::var_os("SPDCAM_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"));
    assert!(
        dir.join("lamps").is_dir() && dir.join("cameras").is_dir(),
        "measured data not found at {}: set SPDCAM_DATA",
        dir.display()
    );
    dir
}
