//! Where spdcam's own tests and benchmarks find the measured data of the second test tier:
//! `$SPDCAM_DATA` (the data directory the program itself reads, `spdcam_core::builtin`),
//! else the `shared/data` the project's layout puts beside the repository's checkout.
//!
//! A dev-dependency only, so that the program and its libraries hold no path of the
//! checkout: the program reads a data directory only when it is given one. The checkout is
//! found when the tests run, not when they are built, so that a target directory shared by
//! several checkouts never sends one checkout's tests to another's data.

use std::path::{Path, PathBuf};

/// The measured data directory for tests and benchmarks. Whether it exists is the caller's
/// question (the second test tier requires it; benchmarks fall back to built-in data).
pub fn measured_data_dir() -> PathBuf {
    std::env::var_os("SPDCAM_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| checkout_root().join("../shared/data"))
}

/// The checkout running the tests: the nearest folder holding `Cargo.lock` above the
/// package cargo runs them in (`CARGO_MANIFEST_DIR`, set by `cargo test` and `cargo
/// bench`), else above the working directory; that folder itself when none holds it.
fn checkout_root() -> PathBuf {
    let start = std::env::var_os("CARGO_MANIFEST_DIR")
        .map(PathBuf::from)
        .or_else(|| std::env::current_dir().ok())
        .unwrap_or_default();
    start
        .ancestors()
        .find(|folder| folder.join("Cargo.lock").is_file())
        .map_or_else(|| start.clone(), Path::to_path_buf)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_checkout_is_the_workspace_that_runs_the_tests() {
        let root = checkout_root();
        assert!(root.join("Cargo.lock").is_file(), "{}", root.display());
        assert!(
            root.join("crates/spdcam-test-data").is_dir(),
            "{}",
            root.display()
        );
    }
}
