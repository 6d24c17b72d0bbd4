//! One guard for a command's outputs, run before anything is written: no output may be one
//! of the inputs (the same path, a link to it, or a hard link of it), lie inside an input
//! directory (a dataset, a cameras directory), hold an input, or be another output.
//!
//! Files are compared twice: by canonical path (symbolic links and `..` resolved; an output
//! that does not exist yet by its nearest existing ancestor) and, where both exist, by file
//! identity (device and inode on Unix), which also catches hard links and bind mounts.

use crate::error::{Error, Result};
use crate::fsio;
use std::path::PathBuf;

/// What an output path names.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputKind {
    /// One file (or `-` for standard output, where the command allows it).
    File,
    /// A directory the command fills (a dataset, a report directory, stage images).
    Directory,
}

/// A path a command reads or writes, with the option that named it (for messages).
#[derive(Debug, Clone)]
pub struct NamedPath {
    /// The option or argument as the user typed it (`-o`, `--features`, `PHOTO`).
    pub option: String,
    /// The path given.
    pub path: PathBuf,
}

/// An output path and what it names.
#[derive(Debug, Clone)]
pub struct PlannedOutput {
    /// The option and its path.
    pub named: NamedPath,
    /// A file or a directory.
    pub kind: OutputKind,
}

/// Refuses, with both names, any output that would destroy an input or another output:
/// checked before the command reads or writes anything.
pub fn check_outputs(inputs: &[NamedPath], outputs: &[PlannedOutput]) -> Result<()> {
    let inputs: Vec<Resolved> = inputs
        .iter()
        .filter(|i| !fsio::is_stdout(&i.path))
        .filter_map(Resolved::existing)
        .collect();
    let mut seen: Vec<(Resolved, &PlannedOutput)> = Vec::new();
    let mut stdout: Option<&PlannedOutput> = None;
    for output in outputs {
        let named = &output.named;
        if fsio::is_stdout(&named.path) {
            if let Some(first) = stdout {
                return Err(Error::invalid(format!(
                    "both {} and {} are `-` (standard output): only one output can go \
                     there; name a file for the other",
                    first.named.option, named.option
                )));
            }
            stdout = Some(output);
            continue;
        }
        let out = Resolved::planned(named);
        for input in &inputs {
            if let Some(relation) = clash(&out, output.kind, input) {
                return Err(Error::invalid(format!(
                    "the output {} {} {relation} the input {} {}: writing it would destroy \
                     what is read; name an output apart from the inputs",
                    named.option,
                    named.path.display(),
                    input.named.option,
                    input.named.path.display()
                )));
            }
        }
        for (other, other_output) in &seen {
            if out.same_as(other) {
                return Err(Error::invalid(format!(
                    "the outputs {} {} and {} {} are the same file: one would overwrite \
                     the other; give each output a path of its own",
                    other_output.named.option,
                    other_output.named.path.display(),
                    named.option,
                    named.path.display()
                )));
            }
        }
        seen.push((out, output));
    }
    Ok(())
}

/// How an output meets an input, in words, or `None` where they are apart.
fn clash(out: &Resolved, kind: OutputKind, input: &Resolved) -> Option<&'static str> {
    if out.same_as(input) {
        return Some("is");
    }
    if out.canonical.starts_with(&input.canonical) && input.is_dir {
        return Some("lies inside");
    }
    if kind == OutputKind::Directory && input.canonical.starts_with(&out.canonical) {
        return Some("contains");
    }
    None
}

/// A path resolved for comparison.
struct Resolved {
    named: NamedPath,
    canonical: PathBuf,
    identity: Option<Identity>,
    is_dir: bool,
}

impl Resolved {
    /// An input that exists (inputs that do not are for the command to report).
    fn existing(named: &NamedPath) -> Option<Resolved> {
        let canonical = named.path.canonicalize().ok()?;
        let meta = std::fs::metadata(&canonical).ok()?;
        // Pipes and devices (`<(…)`, /dev/stdin) are read, never written over.
        if !meta.is_file() && !meta.is_dir() {
            return None;
        }
        Some(Resolved {
            named: named.clone(),
            canonical,
            identity: Identity::of(&meta),
            is_dir: meta.is_dir(),
        })
    }

    /// An output, which may not exist yet.
    fn planned(named: &NamedPath) -> Resolved {
        let meta = std::fs::metadata(&named.path).ok();
        Resolved {
            named: named.clone(),
            canonical: fsio::canonical_or_planned(&named.path),
            identity: meta.as_ref().and_then(Identity::of),
            is_dir: meta.is_some_and(|m| m.is_dir()),
        }
    }

    fn same_as(&self, other: &Resolved) -> bool {
        self.canonical == other.canonical
            || matches!((self.identity, other.identity), (Some(a), Some(b)) if a == b)
    }
}

/// A file's identity on its file system: the same for every path and hard link to it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Identity {
    device: u64,
    inode: u64,
}

impl Identity {
    #[cfg(unix)]
    fn of(meta: &std::fs::Metadata) -> Option<Identity> {
        use std::os::unix::fs::MetadataExt;
        Some(Identity {
            device: meta.dev(),
            inode: meta.ino(),
        })
    }

    #[cfg(not(unix))]
    fn of(_meta: &std::fs::Metadata) -> Option<Identity> {
        None
    }
}

/// `path` as a [`NamedPath`] of `option`.
pub fn named(option: &str, path: impl Into<PathBuf>) -> NamedPath {
    NamedPath {
        option: option.to_string(),
        path: path.into(),
    }
}

/// `path` as a file output of `option`.
pub fn file_output(option: &str, path: impl Into<PathBuf>) -> PlannedOutput {
    PlannedOutput {
        named: named(option, path),
        kind: OutputKind::File,
    }
}

/// `path` as a directory output of `option`.
pub fn directory_output(option: &str, path: impl Into<PathBuf>) -> PlannedOutput {
    PlannedOutput {
        named: named(option, path),
        kind: OutputKind::Directory,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn scratch(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("spdcam-output-guard-{name}-{}", std::process::id()));
        std::fs::remove_dir_all(&dir).ok();
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn an_output_onto_an_input_is_refused_with_both_names() {
        let dir = scratch("same");
        let photo = dir.join("p.jpg");
        std::fs::write(&photo, b"photo").unwrap();
        let dotted = dir.join(".").join("p.jpg");
        let e = check_outputs(&[named("PHOTO", &photo)], &[file_output("-o", &dotted)])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("-o") && e.contains("PHOTO") && e.contains(" is "),
            "{e}"
        );
        check_outputs(
            &[named("PHOTO", &photo)],
            &[file_output("-o", dir.join("q.csv"))],
        )
        .unwrap();
        assert_eq!(std::fs::read(&photo).unwrap(), b"photo");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn links_to_an_input_are_the_input() {
        let dir = scratch("links");
        let photo = dir.join("p.jpg");
        std::fs::write(&photo, b"photo").unwrap();
        let soft = dir.join("soft.jpg");
        std::os::unix::fs::symlink(&photo, &soft).unwrap();
        let hard = dir.join("hard.jpg");
        std::fs::hard_link(&photo, &hard).unwrap();
        for out in [&soft, &hard] {
            let e = check_outputs(&[named("PHOTO", &photo)], &[file_output("--report", out)]);
            assert!(e.is_err(), "{}", out.display());
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn outputs_inside_an_input_directory_and_directories_holding_inputs_are_refused() {
        let dir = scratch("dirs");
        let dataset = dir.join("ds");
        std::fs::create_dir_all(dataset.join("samples")).unwrap();
        std::fs::write(dataset.join("manifest.json"), b"{}").unwrap();
        let inputs = [named("--data", &dataset)];
        for out in [
            dataset.join("manifest.json"),
            dataset.join("samples/new.parquet"),
        ] {
            let e = check_outputs(&inputs, &[file_output("--plot", &out)])
                .unwrap_err()
                .to_string();
            assert!(e.contains("lies inside") || e.contains(" is "), "{e}");
        }
        let e = check_outputs(&inputs, &[directory_output("-o", &dir)])
            .unwrap_err()
            .to_string();
        assert!(e.contains("contains"), "{e}");
        check_outputs(&inputs, &[directory_output("-o", dir.join("other"))]).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn two_outputs_on_one_file_or_both_on_standard_output_are_refused() {
        let dir = scratch("outputs");
        let png = dir.join("a.png");
        let e = check_outputs(
            &[],
            &[file_output("-o", &png), file_output("--features", &png)],
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("-o") && e.contains("--features"), "{e}");
        let e = check_outputs(
            &[],
            &[file_output("-o", "-"), file_output("--spd-out", "-")],
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("standard output"), "{e}");
        check_outputs(
            &[],
            &[file_output("-o", &png), file_output("--features", "-")],
        )
        .unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// The spellings of one place in [`tree`]: the path itself, through `.` and `..`,
    /// through a symbolic link to it, and through a hard link of it.
    #[cfg(unix)]
    fn spellings(root: &Path, place: usize) -> Vec<PathBuf> {
        let name = ["a.csv", "b.csv", "d/c.csv", "d/e.csv", "d"][place];
        let mut all = vec![
            root.join(name),
            root.join("d/..").join(name),
            root.join(".").join(name),
        ];
        if place < 4 {
            all.push(root.join(format!("link{place}")));
        }
        if place < 2 {
            all.push(root.join(format!("hard{place}")));
        }
        all
    }

    /// A small file tree: files a, b, a directory d holding c and e, a symbolic link to
    /// each file and a hard link of a and b; each file holds its own name.
    #[cfg(unix)]
    fn tree(root: &Path) {
        std::fs::remove_dir_all(root).ok();
        std::fs::create_dir_all(root.join("d")).unwrap();
        for (k, name) in ["a.csv", "b.csv", "d/c.csv", "d/e.csv"].iter().enumerate() {
            std::fs::write(root.join(name), name).unwrap();
            std::os::unix::fs::symlink(root.join(name), root.join(format!("link{k}"))).unwrap();
        }
        for (k, name) in ["a.csv", "b.csv"].iter().enumerate() {
            std::fs::hard_link(root.join(name), root.join(format!("hard{k}"))).unwrap();
        }
    }

    /// Every file under `root` with its bytes, followed through no links.
    #[cfg(unix)]
    fn snapshot(root: &Path) -> Vec<(PathBuf, Vec<u8>)> {
        let mut all = Vec::new();
        let mut stack = vec![root.to_path_buf()];
        while let Some(dir) = stack.pop() {
            for entry in std::fs::read_dir(&dir).unwrap() {
                let path = entry.unwrap().path();
                let meta = std::fs::symlink_metadata(&path).unwrap();
                if meta.is_dir() {
                    stack.push(path);
                } else if meta.is_file() {
                    all.push((path.clone(), std::fs::read(&path).unwrap()));
                }
            }
        }
        all.sort();
        all
    }

    #[cfg(unix)]
    proptest::proptest! {
        #![proptest_config(proptest::test_runner::Config::with_cases(96))]
        /// Issue 39: no output can alias an input or another output. Whatever places the
        /// inputs and file outputs name, and however they are spelt, the guard passes
        /// exactly when writing every output in place leaves every input as it was and
        /// each output holds what was written to it.
        #[test]
        fn the_guard_passes_exactly_when_writing_the_outputs_harms_nothing(
            input_places in proptest::collection::vec((0usize..5, 0usize..5), 1..3),
            output_places in proptest::collection::vec((0usize..4, 0usize..5), 1..3),
        ) {
            let root = std::env::temp_dir().join(format!(
                "spdcam-output-guard-property-{}",
                std::process::id()
            ));
            tree(&root);
            let pick = |(place, spelling): (usize, usize)| {
                let all = spellings(&root, place);
                all[spelling % all.len()].clone()
            };
            let inputs: Vec<NamedPath> = input_places
                .iter()
                .map(|&p| named("--in", pick(p)))
                .collect();
            let outputs: Vec<PlannedOutput> = output_places
                .iter()
                .map(|&p| file_output("-o", pick(p)))
                .collect();
            let passed = check_outputs(&inputs, &outputs).is_ok();

            let input_bytes = |all: &[(PathBuf, Vec<u8>)]| -> Vec<Vec<u8>> {
                inputs
                    .iter()
                    .flat_map(|i| {
                        let canonical = i.path.canonicalize().unwrap();
                        all.iter()
                            .filter(|(p, _)| p.canonicalize().unwrap().starts_with(&canonical))
                            .map(|(_, b)| b.clone())
                            .collect::<Vec<_>>()
                    })
                    .collect()
            };
            let before = input_bytes(&snapshot(&root));
            // Written in place, as any program writes (a shell's `>`): through links, into
            // the file a hard link shares.
            for (k, output) in outputs.iter().enumerate() {
                std::fs::write(&output.named.path, format!("out{k}")).unwrap();
            }
            let after = input_bytes(&snapshot(&root));
            let outputs_kept = outputs.iter().enumerate().all(|(k, output)| {
                std::fs::read(&output.named.path).unwrap() == format!("out{k}").as_bytes()
            });
            let harmless = before == after && outputs_kept;
            std::fs::remove_dir_all(&root).unwrap();
            proptest::prop_assert_eq!(
                passed,
                harmless,
                "inputs {:?} outputs {:?}",
                inputs,
                outputs
            );
        }
    }
}
