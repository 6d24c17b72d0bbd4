//! Charts are named in one place, the chart registry: no program source outside it spells a
//! known chart's name (`spdcam_core::chart::KnownChart`). Documentation (comments, Rust doc
//! comments, Python doc text in backticks) and test code may.

use spdcam_core::chart::KnownChart;
use std::path::{Path, PathBuf};

/// The repository's root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The files that hold chart names: the registry, and the table of the shipped models
/// (whose files are named after their charts).
const REGISTRY: [&str; 2] = [
    "crates/spdcam-core/src/chart/registry.rs",
    "crates/spdcam-infer/src/shipped.rs",
];

/// The program's source files under `dir`, test folders left out.
fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            if path.file_name().is_some_and(|n| n != "tests") {
                sources(&path, out);
            }
        } else if path
            .extension()
            .is_some_and(|e| ["rs", "py", "pyi", "js", "html"].iter().any(|x| e == *x))
        {
            out.push(path);
        }
    }
}

/// Whether `line` (trimmed) is documentation or a comment, not program text.
fn is_comment(line: &str) -> bool {
    ["//", "/*", "* ", "#:", "# ", "<!--"]
        .iter()
        .any(|start| line.starts_with(start))
        || line == "*"
        || line == "#"
}

/// Whether a byte may be part of a name (an identifier's byte).
fn is_name_byte(b: u8) -> bool {
    b.is_ascii_alphanumeric() || b == b'_'
}

/// The chart names `line` spells as a name of its own: not inside a longer identifier, not
/// a Rust path's or method's part (`Chart::colorchecker24(`, `fn colorchecker24`), not in
/// backticks (documentation).
fn names_in(line: &str) -> Vec<&'static str> {
    let bytes = line.as_bytes();
    let mut found = Vec::new();
    for name in KnownChart::ALL.map(KnownChart::name) {
        for (at, _) in line.match_indices(name) {
            let end = at + name.len();
            let before = at.checked_sub(1).map(|i| bytes[i]);
            let after = bytes.get(end).copied();
            let part = before.is_some_and(is_name_byte) || after.is_some_and(is_name_byte);
            let code = matches!(before, Some(b':' | b'.' | b'`')) || line[..at].ends_with("fn ");
            if !part && !code {
                found.push(name);
            }
        }
    }
    found
}

#[test]
fn no_chart_name_is_spelled_outside_the_registry() {
    let root = root();
    let mut files = Vec::new();
    for dir in ["crates", "python/src", "python/spdcam"] {
        let dir = root.join(dir);
        if dir.ends_with("crates") {
            for krate in std::fs::read_dir(&dir).unwrap().flatten() {
                sources(&krate.path().join("src"), &mut files);
            }
        } else {
            sources(&dir, &mut files);
        }
    }
    assert!(files.len() > 100, "{} source files", files.len());
    let mut spelled = Vec::new();
    for file in &files {
        let relative = file.strip_prefix(&root).unwrap().to_string_lossy();
        // The registry, and modules that are tests on their own (`mod tests;` in a file).
        let test_module = file
            .file_name()
            .is_some_and(|n| n == "tests.rs" || n == "test_support.rs");
        if test_module || REGISTRY.iter().any(|r| relative == *r) {
            continue;
        }
        let text = std::fs::read_to_string(file).unwrap();
        for (n, line) in text.lines().enumerate() {
            let line = line.trim();
            // A Rust file's tests come last.
            if line.starts_with("#[cfg(test)]") {
                break;
            }
            if is_comment(line) {
                continue;
            }
            for name in names_in(line) {
                spelled.push(format!("{relative}:{}: {name}", n + 1));
            }
        }
    }
    assert!(
        spelled.is_empty(),
        "chart names outside the chart registry (use KnownChart):\n{}",
        spelled.join("\n")
    );
}

#[test]
fn the_scan_finds_a_name_in_code_and_passes_documentation() {
    assert_eq!(
        names_in(r#"default_value = "colorchecker24,colorchecker_sg140""#),
        ["colorchecker24", "colorchecker_sg140"]
    );
    assert_eq!(
        names_in("chart: str = 'colorchecker_sg96_thesis',"),
        ["colorchecker_sg96_thesis"]
    );
    for passed in [
        "let chart = Chart::colorchecker24(&grid)?;",
        "pub fn colorchecker_sg140(reflectances: &SpectralSet) {",
        "fn colorchecker24_row(spd: &Spd) -> FeatureRows {",
        "``colorchecker24``, ``colorchecker_sg140``, …) → the",
        "let name = \"colorchecker24_ohta\";",
    ] {
        assert!(names_in(passed).is_empty(), "{passed}");
    }
    assert!(is_comment("/// `colorchecker24`") && is_comment("#: The chart found"));
}
