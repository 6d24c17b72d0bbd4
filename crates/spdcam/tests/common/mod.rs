//! What the command-line tests share: running the built `spdcam` as a user on a fresh clone
//! would (no data directory unless a test gives one), and scratch directories. Each test
//! binary uses a part of it.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// spdcam with no data directory: what it does here works on a fresh clone.
pub fn spdcam(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_spdcam"))
        .args(args)
        .env_remove("SPDCAM_DATA")
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("spdcam runs")
}

/// Runs spdcam, which must succeed; its standard output.
pub fn ok(args: &[&str]) -> String {
    let out = spdcam(args);
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "spdcam {args:?} failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

/// Runs spdcam, which must fail; its standard error.
pub fn fails(args: &[&str]) -> String {
    let out = spdcam(args);
    assert!(!out.status.success(), "spdcam {args:?} should fail");
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// An empty scratch directory of this test binary named `name`.
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("spdcam-{}-{name}", env!("CARGO_CRATE_NAME")));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A path as a command-line argument.
pub fn s(p: &Path) -> String {
    p.to_string_lossy().into_owned()
}
