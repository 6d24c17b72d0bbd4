//! Writing files so that an interrupted or failed run never leaves a half-written one.

use crate::error::{Error, Result};
use crate::limits;
use std::io::{Read, Write};
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

/// Whether `path` names something that can be read as an input: a file, a pipe
/// (`/dev/stdin`, a shell's `<(…)`), a device — anything that exists and is not a directory
/// (symbolic links followed). Inputs are then read through [`read_limited`] or [`read_text`],
/// which bound what any of them may cost.
pub fn is_input(path: &Path) -> bool {
    std::fs::metadata(path).is_ok_and(|m| !m.is_dir())
}

/// Bytes of the start of an input looked at before the rest is read (see
/// [`read_limited_checked`]).
pub const HEAD_BYTES: usize = 4096;

/// The image format whose signature `head` (the first bytes of a file) starts with: JPEG
/// (`FF D8 FF`), PNG (`89 'PNG' 0D 0A 1A 0A`) or TIFF (`'II' 2A 00` or `'MM' 00 2A`), the
/// formats spdcam reads (signatures: ISO/IEC 10918-1 Annex B, ISO/IEC 15948 §5.2, TIFF 6.0
/// §2).
pub fn image_format(head: &[u8]) -> Option<&'static str> {
    if head.starts_with(&[0xFF, 0xD8, 0xFF]) {
        Some("JPEG")
    } else if head.starts_with(b"\x89PNG\r\n\x1a\n") {
        Some("PNG")
    } else if head.starts_with(b"II*\0") || head.starts_with(b"MM\0*") {
        Some("TIFF")
    } else {
        None
    }
}

/// Reads a whole text file whose size is within [`limits::TEXT_FILE_BYTES`] (a pipe or a
/// device too, through the same cap). Its first bytes are looked at before the rest is
/// read: an image or anything holding NUL bytes (a binary file, `/dev/zero`) is refused at
/// once, not after reading up to the limit.
pub fn read_text(path: &Path) -> Result<String> {
    let bytes = read_limited_checked(path, &limits::TEXT_FILE_BYTES, HEAD_BYTES, |head| {
        if let Some(format) = image_format(head) {
            return Err(Error::invalid(format!(
                "{} is a {format} image, not a text file; give the CSV (or JSON) file here",
                path.display()
            )));
        }
        if head.contains(&0) {
            return Err(Error::invalid(format!(
                "{} is not a text file (it holds NUL bytes: a binary file, UTF-16 text or \
                 a device such as /dev/zero); give the CSV (or JSON) file here",
                path.display()
            )));
        }
        Ok(())
    })?;
    String::from_utf8(bytes).map_err(|e| {
        Error::invalid(format!(
            "{} is not UTF-8 text (byte {} is not UTF-8); save it as UTF-8 text",
            path.display(),
            e.utf8_error().valid_up_to() + 1
        ))
    })
}

/// Reads all of `path` — a file, a pipe (`/dev/stdin`, `<(…)`) or a device — holding at
/// most `limit` bytes: a regular file larger than that is refused from its size, anything
/// else is read through a cap of `limit + 1` bytes and refused once it passes the limit, so
/// that an endless stream (`/dev/zero`) costs no more memory than the limit.
pub fn read_limited(path: &Path, limit: &limits::Limit) -> Result<Vec<u8>> {
    read_limited_checked(path, limit, 0, |_| Ok(()))
}

/// [`read_limited`], with `check` given the first `head` bytes (all of the input when it is
/// shorter) as soon as they are read: its error stops the reading, so that an input whose
/// first bytes show it is the wrong kind (`/dev/zero` for a photo) costs no more than them.
pub fn read_limited_checked(
    path: &Path,
    limit: &limits::Limit,
    head: usize,
    check: impl FnOnce(&[u8]) -> Result<()>,
) -> Result<Vec<u8>> {
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let meta = file.metadata().map_err(|e| Error::io(path, e))?;
    if meta.is_dir() {
        return Err(Error::invalid(format!(
            "{}: is a directory; name a file",
            path.display()
        )));
    }
    let max = limit.value()?;
    let context = path.display().to_string();
    if meta.is_file() {
        limit.check_against(meta.len(), max, &context)?;
    }
    let capped = max.saturating_add(1);
    let mut reader = file.take(capped);
    let hint = if meta.is_file() {
        meta.len() + 1
    } else {
        1 << 16
    };
    let mut bytes = Vec::with_capacity(hint.min(capped) as usize);
    let mut chunk = vec![0u8; 1 << 16];
    let mut check = Some(check);
    loop {
        if bytes.len() >= head {
            if let Some(check) = check.take() {
                check(&bytes)?;
            }
        }
        let n = match reader.read(&mut chunk) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(Error::io(path, e)),
        };
        if bytes.len() + n > bytes.capacity() {
            // Grow by doubling, never past the cap: a stream just over the limit must not
            // double the memory it takes.
            let target = (bytes.capacity() as u64 * 2)
                .max((bytes.len() + n) as u64)
                .min(capped) as usize;
            bytes.reserve_exact(target - bytes.len());
        }
        bytes.extend_from_slice(&chunk[..n]);
    }
    if let Some(check) = check {
        check(&bytes)?;
    }
    if bytes.len() as u64 > max {
        return Err(limit.exceeded(&context));
    }
    Ok(bytes)
}

/// Refuses an output directory that is, contains or lies inside one of `inputs` (files or
/// directories), before anything is written or removed: replacing the output would
/// destroy the input it is read from. Paths are compared canonicalised (symbolic links
/// and `..` resolved; an output that does not exist yet by its nearest existing ancestor).
pub fn check_output_apart(output: &Path, inputs: &[&Path]) -> Result<()> {
    let out = canonical_or_planned(output);
    for input in inputs {
        let Ok(input_path) = input.canonicalize() else {
            continue;
        };
        let relation = if out == input_path {
            "is"
        } else if input_path.starts_with(&out) {
            "contains"
        } else if out.starts_with(&input_path) {
            "lies inside"
        } else {
            continue;
        };
        return Err(Error::invalid(format!(
            "the output {} {relation} the input {}: writing it would destroy what is read; \
             choose an output directory apart from the inputs",
            output.display(),
            input.display()
        )));
    }
    Ok(())
}

/// `path` canonicalised; when it does not exist yet, its nearest existing ancestor
/// canonicalised with the rest of the path appended (`new/../ds` is `ds`).
pub(crate) fn canonical_or_planned(path: &Path) -> PathBuf {
    use std::path::Component;
    let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let parts: Vec<Component> = absolute.components().collect();
    for found in (1..=parts.len()).rev() {
        let Ok(mut planned) = parts[..found].iter().collect::<PathBuf>().canonicalize() else {
            continue;
        };
        // The missing part holds no links: its `..` are resolved by name.
        for part in &parts[found..] {
            match part {
                Component::ParentDir => {
                    planned.pop();
                }
                Component::CurDir => {}
                other => planned.push(other),
            }
        }
        return planned;
    }
    absolute
}

/// Checks, before long work, that a file can later be written at `path`: its directory
/// exists, `path` is not a directory, and a file can be created beside it (the check file
/// is removed at once). Catches an unwritable path before hours of training, not after.
/// A device or a pipe is written in place: it is only checked to be one.
pub fn check_writable(path: &Path) -> Result<()> {
    let file = match OutputTarget::resolve(path)? {
        OutputTarget::InPlace(_) => return Ok(()),
        OutputTarget::Replace(file) => file,
    };
    check_parent_dir(&file)?;
    let probe = temporary_path(&file);
    std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
        .map_err(|e| Error::io(path, e))?;
    std::fs::remove_file(&probe).map_err(|e| Error::io(&probe, e))
}

/// Where the bytes for an output path go.
#[derive(Debug, Clone, PartialEq, Eq)]
enum OutputTarget {
    /// A regular file (or none yet): written beside it, then renamed over it. A symbolic
    /// link is followed, so the link stays and its target gets the new content.
    Replace(PathBuf),
    /// A character device or a named pipe (`/dev/null`, a FIFO, `/dev/stdout`): opened and
    /// written as it is, never replaced by a regular file.
    InPlace(PathBuf),
}

impl OutputTarget {
    /// Resolves `path` (through symbolic links, even to a target not made yet) and refuses
    /// what cannot take a file's bytes: a directory, a block device, a socket.
    fn resolve(path: &Path) -> Result<OutputTarget> {
        let target = follow_links(path)?;
        let meta = match std::fs::metadata(&target) {
            Ok(meta) => meta,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return Ok(OutputTarget::Replace(target))
            }
            Err(e) => return Err(Error::io(path, e)),
        };
        if meta.is_file() {
            return Ok(OutputTarget::Replace(target));
        }
        let what = if meta.is_dir() {
            "a directory"
        } else if is_stream(&meta) {
            return Ok(OutputTarget::InPlace(target));
        } else {
            "neither a file, a character device nor a pipe (a block device or a socket)"
        };
        Err(Error::invalid(format!(
            "cannot write {}: it is {what}; name a file",
            path.display()
        )))
    }
}

/// Whether `meta` is a character device or a named pipe: outputs written in place.
#[cfg(unix)]
fn is_stream(meta: &std::fs::Metadata) -> bool {
    use std::os::unix::fs::FileTypeExt;
    let kind = meta.file_type();
    kind.is_char_device() || kind.is_fifo()
}

/// Whether `meta` is a character device or a named pipe: outputs written in place.
#[cfg(not(unix))]
fn is_stream(_meta: &std::fs::Metadata) -> bool {
    false
}

/// `path` with every symbolic link along its last component followed (a link to a link
/// too), even where the final target does not exist yet; at most 40 links, as Linux allows.
fn follow_links(path: &Path) -> Result<PathBuf> {
    let mut current = path.to_path_buf();
    for _ in 0..40 {
        match std::fs::symlink_metadata(&current) {
            Ok(meta) if meta.file_type().is_symlink() => {
                let link = std::fs::read_link(&current).map_err(|e| Error::io(&current, e))?;
                current = match current.parent() {
                    Some(dir) if link.is_relative() => dir.join(link),
                    _ => link,
                };
            }
            _ => return Ok(current),
        }
    }
    Err(Error::invalid(format!(
        "cannot write {}: too many symbolic links (a loop?)",
        path.display()
    )))
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
/// A symbolic link is followed (the link stays, its target is replaced); a character
/// device or a named pipe is written in place, never replaced by a file.
pub fn write_atomic_with(
    path: &Path,
    write: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> std::io::Result<()>,
) -> Result<()> {
    let file = match OutputTarget::resolve(path)? {
        OutputTarget::InPlace(stream) => return write_in_place(path, &stream, write),
        OutputTarget::Replace(file) => file,
    };
    check_parent_dir(&file)?;
    let tmp = temporary_path(&file);
    let result = (|| {
        let created = std::fs::File::create(&tmp)?;
        let mut writer = std::io::BufWriter::new(created);
        write(&mut writer)?;
        let created = writer.into_inner().map_err(|e| e.into_error())?;
        created.sync_all()?;
        std::fs::rename(&tmp, &file)
    })();
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(Error::io(path, e));
    }
    Ok(())
}

/// Writes to a device or a pipe as it is (opened for writing, not created or replaced).
fn write_in_place(
    path: &Path,
    stream: &Path,
    write: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> std::io::Result<()>,
) -> Result<()> {
    let result = (|| {
        let opened = std::fs::OpenOptions::new().write(true).open(stream)?;
        let mut writer = std::io::BufWriter::new(opened);
        write(&mut writer)?;
        writer.flush()
    })();
    result.map_err(|e| Error::io(path, e))
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

    #[cfg(unix)]
    #[test]
    fn a_link_is_followed_and_a_device_or_pipe_written_in_place() {
        // Issue 39, defect 2: `-o` naming a link, a FIFO or a device replaced it with a file.
        use std::os::unix::fs::FileTypeExt;
        let dir = std::env::temp_dir().join(format!("spdcam-fsio-kinds-{}", std::process::id()));
        std::fs::remove_dir_all(&dir).ok();
        std::fs::create_dir_all(&dir).unwrap();
        let target = dir.join("target.csv");
        std::fs::write(&target, b"old").unwrap();
        let link = dir.join("link.csv");
        std::os::unix::fs::symlink("target.csv", &link).unwrap();
        write_atomic(&link, b"new").unwrap();
        assert!(std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(std::fs::read(&target).unwrap(), b"new");
        // A dangling link gets its target made, as a shell's `>` does.
        let dangling = dir.join("dangling.csv");
        std::os::unix::fs::symlink("made.csv", &dangling).unwrap();
        write_atomic(&dangling, b"made").unwrap();
        assert_eq!(std::fs::read(dir.join("made.csv")).unwrap(), b"made");

        write_atomic(Path::new("/dev/null"), b"gone").unwrap();
        assert!(std::fs::metadata("/dev/null")
            .unwrap()
            .file_type()
            .is_char_device());
        let e = write_atomic(Path::new("/dev/full"), &[0u8; 1 << 17])
            .unwrap_err()
            .to_string();
        assert!(e.contains("/dev/full") && e.contains("space"), "{e}");
        assert!(std::fs::metadata("/dev/full")
            .unwrap()
            .file_type()
            .is_char_device());

        let fifo = dir.join("fifo");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        assert!(made.unwrap().success(), "mkfifo");
        let reader = {
            let fifo = fifo.clone();
            std::thread::spawn(move || std::fs::read(&fifo).unwrap())
        };
        write_atomic(&fifo, b"through the pipe").unwrap();
        assert_eq!(reader.join().unwrap(), b"through the pipe");
        assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
        check_writable(&fifo).unwrap();
        let e = write_atomic(&dir, b"x").unwrap_err().to_string();
        assert!(e.contains("is a directory"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
