//! What the command-line tests share: running the built `spdcam` as a user on a fresh clone
//! would (no data directory unless a test gives one), and scratch directories. Each test
//! binary uses a part of it.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

/// The built spdcam as a fresh clone runs it: in the crate's directory, with the data
/// directory's variable removed from its environment (never read), so a first-tier test
/// cannot depend on the measured data.
pub fn fresh_clone_command(args: &[&str]) -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_spdcam"));
    command
        .args(args)
        .env_remove(spdcam_core::builtin::DATA_DIR_ENV)
        .current_dir(env!("CARGO_MANIFEST_DIR"));
    command
}

/// spdcam with no data directory: what it does here works on a fresh clone.
pub fn spdcam(args: &[&str]) -> Output {
    fresh_clone_command(args).output().expect("spdcam runs")
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

/// Runs spdcam, which must fail with a message and no panic; its standard error.
pub fn fails(args: &[&str]) -> String {
    let out = spdcam(args);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success(), "spdcam {args:?} should fail");
    assert!(!stderr.contains("panicked"), "{stderr}");
    stderr
}

/// Checks that `out` is a refusal that came within `seconds` of `started` — exit 1 (the
/// work was refused) or 2 (an option's value was, clap's convention), an `error:` line,
/// no panic — and returns its standard error; `what` names the run in messages.
pub fn refusal(out: &Output, started: Instant, seconds: u64, what: &str) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success(), "{what} succeeded");
    assert!(
        matches!(out.status.code(), Some(1 | 2)),
        "{what} died: {stderr}"
    );
    assert!(
        started.elapsed() < Duration::from_secs(seconds),
        "{what} took {:?}",
        started.elapsed()
    );
    assert!(stderr.lines().any(|l| l.starts_with("error: ")), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    stderr
}

/// Runs spdcam, expects a refusal within 20 s, and returns its standard error.
pub fn fails_fast(args: &[&str]) -> String {
    let started = Instant::now();
    refusal(&spdcam(args), started, 20, &format!("spdcam {args:?}"))
}

/// An empty scratch directory of this test binary named `name`.
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "spdcam-{}-{name}-{}",
        env!("CARGO_CRATE_NAME"),
        std::process::id()
    ));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A path as a command-line argument.
pub fn s(p: &Path) -> String {
    p.to_string_lossy().into_owned()
}

/// The measured data directory (second tier): `$SPDCAM_DATA`, else `../shared/data` beside
/// the repository. Only the second tier (`--features spdcam/measured-data`) has it.
#[cfg(feature = "measured-data")]
pub fn data_dir() -> PathBuf {
    let root = spdcam_test_data::measured_data_dir();
    assert!(root.is_dir(), "shared data not found at {}", root.display());
    root
}
