//! Writing files so that an interrupted or failed run never leaves a half-written one.

use crate::error::{Error, Result};
use crate::limits;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Checks that the directory that will hold `path` exists, naming it if not.
pub fn check_parent_dir(path: &Path) -> Result<()> {
    let parent = path.parent().filter(|p| !p.as_os_str().is_empty());
    if let Some(dir) = parent {
        if !dir.is_dir() {
            return Err(Error::invalid(format!(
                "cannot write {}: directory {} does not exist",
                path.display(),
                dir.display()
            )));
        }
    }
    Ok(())
}

/// Reads a whole text file whose size is within [`limits::TEXT_FILE_BYTES`].
pub fn read_text(path: &Path) -> Result<String> {
    let size = std::fs::metadata(path)
        .map_err(|e| Error::io(path, e))?
        .len();
    limits::TEXT_FILE_BYTES.check(size, &path.display().to_string())?;
    std::fs::read_to_string(path).map_err(|e| Error::io(path, e))
}

/// Checks, before long work, that a file can later be written at `path`: its directory
/// exists, `path` is not a directory, and a file can be created beside it (the check file
/// is removed at once). Catches an unwritable path before hours of training, not after.
pub fn check_writable(path: &Path) -> Result<()> {
    check_parent_dir(path)?;
    if path.is_dir() {
        return Err(Error::invalid(format!(
            "cannot write {}: it is a directory; name a file",
            path.display()
        )));
    }
    let probe = temporary_path(path);
    std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
        .map_err(|e| Error::io(path, e))?;
    std::fs::remove_file(&probe).map_err(|e| Error::io(&probe, e))
}

/// Whether `path` names standard output (`-`, as Unix tools read it).
pub fn is_stdout(path: &Path) -> bool {
    path.as_os_str() == "-"
}

/// Writes `bytes` to standard output when `path` is `-`, else to the file atomically.
pub fn write_output(path: &Path, bytes: &[u8]) -> Result<()> {
    if is_stdout(path) {
        let mut out = std::io::stdout().lock();
        return out
            .write_all(bytes)
            .and_then(|()| out.flush())
            .map_err(|e| Error::io("standard output", e));
    }
    write_atomic(path, bytes)
}

/// The temporary sibling a file is written to before it is renamed into place.
fn temporary_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.partial", std::process::id()))
}

/// Writes `bytes` to `path` atomically: to a temporary sibling first, then renamed.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomic_with(path, |w| w.write_all(bytes))
}

/// Writes to `path` atomically with a writer callback; on any error nothing is left behind.
pub fn write_atomic_with(
    path: &Path,
    write: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> std::io::Result<()>,
) -> Result<()> {
    check_parent_dir(path)?;
    let tmp = temporary_path(path);
    let result = (|| {
        let file = std::fs::File::create(&tmp)?;
        let mut writer = std::io::BufWriter::new(file);
        write(&mut writer)?;
        let file = writer.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(Error::io(path, e));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn missing_directory_is_named_and_nothing_written() {
        let dir = std::env::temp_dir().join(format!("spdcam-fsio-{}", std::process::id()));
        let target = dir.join("missing").join("out.csv");
        let err = write_atomic(&target, b"x").unwrap_err().to_string();
        assert!(err.contains("does not exist"), "{err}");
        assert!(!target.exists());
    }

    #[test]
    fn unwritable_targets_are_found_before_the_work() {
        // Issue 15: `train -o DIR` failed only after training.
        let dir = std::env::temp_dir().join(format!("spdcam-fsio-check-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let e = check_writable(&dir).unwrap_err().to_string();
        assert!(e.contains("is a directory"), "{e}");
        let e = check_writable(&dir.join("no/such/m.spdm"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("does not exist"), "{e}");
        check_writable(&dir.join("m.spdm")).unwrap();
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0);
        assert!(is_stdout(Path::new("-")) && !is_stdout(Path::new("./-x")));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn failed_writer_leaves_no_file() {
        let dir = std::env::temp_dir().join(format!("spdcam-fsio-fail-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let target = dir.join("out.csv");
        let res = write_atomic_with(&target, |w| {
            w.write_all(b"partial")?;
            Err(std::io::Error::other("boom"))
        });
        assert!(res.is_err());
        assert!(!target.exists());
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
