//! Where spdcam's own tests and benchmarks find the measured data of the second test tier:
//! `$SPDCAM_DATA` (the data directory the program itself reads, `spdcam_core::builtin`),
//! else the `shared/data` the project's layout puts beside the repository's checkout.
//!
//! A dev-dependency only, so that the program and its libraries hold no path of the
//! checkout: the program reads a data directory only when it is given one.

use std::path::{Path, PathBuf};

/// The measured data directory for tests and benchmarks. Whether it exists is the caller's
/// question (the second test tier requires it; benchmarks fall back to built-in data).
pub fn measured_data_dir() -> PathBuf {
    std::env::var_os("SPDCAM_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"))
}
