//! Writing dataset directories: output preparation, sample files and the closing manifest.

use super::batch::{Columns, Counts, SampleBatch, SampleRow};
use super::file;
use super::lock::{DirLock, LOCK_FILE};
use super::manifest::{FileEntry, Manifest, Origin, MANIFEST_FILE};
use crate::error::{Error, Result};
use crate::fsio;
use std::path::{Path, PathBuf};

/// The record of an unfinished `spdcam generate` run, removed when its manifest is written.
pub(crate) const RUN_FILE: &str = ".spdcam-run.json";
/// The journal of the sample files an unfinished run wrote (one JSON entry a line, with
/// checksums), removed with the run record.
pub(crate) const RUN_PARTS: &str = ".spdcam-run-parts.jsonl";
/// Where `--images` puts the rendered charts.
pub(crate) const IMAGES_DIR: &str = "images";
/// Where the sample files are: a folder of Parquet files and nothing else, which pandas,
/// polars, DuckDB and Spark read as one table.
pub const SAMPLES_DIR: &str = "samples";
/// Sub-directories `split` writes.
pub(crate) const SPLIT_PARTS: [&str; 3] = ["train", "val", "test"];
/// Files `export` writes.
pub(crate) const EXPORT_FILES: [&str; 4] =
    ["features.csv", "spds.csv", "weights.csv", "samples.csv"];

/// The path of sample file `k` inside a dataset directory: `samples/part-00000.parquet`, ….
pub(crate) fn sample_file_name(k: u64) -> String {
    format!("{SAMPLES_DIR}/part-{k:05}.parquet")
}

/// Writes `batch` as sample file `name` (see [`sample_file_name`]) in `dir`, atomically.
pub(crate) fn write_sample_file(
    dir: &Path,
    name: String,
    columns: &Columns,
    batch: &SampleBatch,
) -> Result<FileEntry> {
    let bytes = file::encode_parquet(columns, batch)?;
    fsio::write_atomic(&dir.join(&name), &bytes)?;
    Ok(FileEntry::of_bytes(name, batch.len() as u64, &bytes))
}

/// Whether spdcam writes a file of this name into a dataset or export directory.
fn is_ours(name: &str) -> bool {
    name == MANIFEST_FILE
        || name == RUN_FILE
        || name == RUN_PARTS
        || EXPORT_FILES.contains(&name)
        || (name.starts_with("part-") && name.ends_with(".parquet"))
        || (name.starts_with("sample-") && name.ends_with(".png"))
        || (name.starts_with('.') && name.ends_with(".partial"))
}

/// Removes what spdcam wrote into `dir` (datasets, split parts, images, exports,
/// leftovers of interrupted writes); other files stay.
fn remove_ours(dir: &Path) -> Result<()> {
    let entries = std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))?;
    for entry in entries {
        let entry = entry.map_err(|e| Error::io(dir, e))?;
        let path = entry.path();
        let name = entry.file_name().to_string_lossy().into_owned();
        if path.is_dir() {
            if [IMAGES_DIR, SAMPLES_DIR].contains(&name.as_str())
                || SPLIT_PARTS.contains(&name.as_str())
            {
                remove_ours(&path)?;
                if is_empty_dir(&path)? {
                    std::fs::remove_dir(&path).map_err(|e| Error::io(&path, e))?;
                }
            }
        } else if is_ours(&name) {
            std::fs::remove_file(&path).map_err(|e| Error::io(&path, e))?;
        }
    }
    Ok(())
}

/// Removes the temporary files interrupted writes left in `dir`.
pub(crate) fn remove_partials(dir: &Path) -> Result<()> {
    let entries = std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))?;
    for entry in entries {
        let entry = entry.map_err(|e| Error::io(dir, e))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        if name.starts_with('.') && name.ends_with(".partial") {
            std::fs::remove_file(entry.path()).map_err(|e| Error::io(entry.path(), e))?;
        }
    }
    Ok(())
}

/// Creates `dir` and its parents.
pub(crate) fn create_dir(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))
}

/// Whether `dir` holds nothing (its lock file aside).
pub(crate) fn is_empty_dir(dir: &Path) -> Result<bool> {
    for entry in std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))? {
        let entry = entry.map_err(|e| Error::io(dir, e))?;
        if entry.file_name() != LOCK_FILE {
            return Ok(false);
        }
    }
    Ok(true)
}

/// Makes the existing directory `dir` ready for new output: when it holds files, refuses
/// unless `overwrite`, which removes what spdcam wrote there before.
pub(crate) fn clear_output(dir: &Path, overwrite: bool) -> Result<()> {
    if !dir.is_dir() {
        return Err(Error::invalid(format!(
            "output {} exists and is not a directory",
            dir.display()
        )));
    }
    if is_empty_dir(dir)? {
        return Ok(());
    }
    if !overwrite {
        return Err(Error::invalid(format!(
            "output directory {} is not empty; use --force to replace what is in it, or choose another directory",
            dir.display()
        )));
    }
    remove_ours(dir)
}

/// Creates `dir` (and its parents) unless it exists; says whether it did.
pub(crate) fn ensure_dir(dir: &Path) -> Result<bool> {
    if dir.exists() {
        if !dir.is_dir() {
            return Err(Error::invalid(format!(
                "output {} exists and is not a directory",
                dir.display()
            )));
        }
        return Ok(false);
    }
    create_dir(dir)?;
    Ok(true)
}

/// An output directory being written: locked against other writers, and, should the
/// writing fail, left as it was found: what spdcam wrote is removed, and the directory too
/// when this run created it.
#[must_use = "call finish() once the output is complete"]
pub(crate) struct Output {
    dir: PathBuf,
    lock: Option<DirLock>,
    created: bool,
    complete: bool,
}

impl Output {
    /// The output is complete: keep it, release the lock.
    pub(crate) fn finish(mut self) {
        self.complete = true;
    }
}

impl Drop for Output {
    fn drop(&mut self) {
        if !self.complete {
            let _ = remove_ours(&self.dir);
        }
        drop(self.lock.take());
        if !self.complete && self.created && is_empty_dir(&self.dir).unwrap_or(false) {
            let _ = std::fs::remove_dir(&self.dir);
        }
    }
}

/// Makes `dir` ready for new output and locks it: refuses it when it is, holds or lies
/// inside one of `inputs` ([`fsio::check_output_apart`]), before anything is touched;
/// creates it, or, when it holds files, refuses unless `overwrite`, which removes what
/// spdcam wrote there before.
pub(crate) fn prepare_output(dir: &Path, inputs: &[&Path], overwrite: bool) -> Result<Output> {
    fsio::check_output_apart(dir, inputs)?;
    let created = ensure_dir(dir)?;
    let lock = DirLock::acquire(dir)?;
    clear_output(dir, overwrite)?;
    Ok(Output {
        dir: dir.to_path_buf(),
        lock: Some(lock),
        created,
        complete: false,
    })
}

/// Writes rows into a dataset directory, `chunk_size` rows per sample file, then the manifest.
pub(crate) struct DatasetWriter<'a> {
    dir: &'a Path,
    columns: Columns,
    chunk_size: usize,
    pending: SampleBatch,
    files: Vec<FileEntry>,
    counts: Counts,
}

impl<'a> DatasetWriter<'a> {
    /// A writer into `dir` (already prepared).
    pub(crate) fn new(dir: &'a Path, columns: Columns, chunk_size: u64) -> Result<Self> {
        columns.validate()?;
        if chunk_size == 0 {
            return Err(Error::invalid("the chunk size must be at least 1 sample"));
        }
        create_dir(&dir.join(SAMPLES_DIR))?;
        Ok(DatasetWriter {
            dir,
            pending: columns.batch(),
            columns,
            chunk_size: chunk_size as usize,
            files: Vec::new(),
            counts: Counts::default(),
        })
    }

    /// Whether no row was pushed yet.
    pub(crate) fn is_empty(&self) -> bool {
        self.files.is_empty() && self.pending.is_empty()
    }

    /// Appends one row.
    pub(crate) fn push(&mut self, row: SampleRow<'_>) -> Result<()> {
        self.pending.push(row)?;
        if self.pending.len() >= self.chunk_size {
            self.flush()?;
        }
        Ok(())
    }

    fn flush(&mut self) -> Result<()> {
        if self.pending.is_empty() {
            return Ok(());
        }
        let batch = std::mem::replace(&mut self.pending, self.columns.batch());
        let name = sample_file_name(self.files.len() as u64);
        self.files
            .push(write_sample_file(self.dir, name, &self.columns, &batch)?);
        self.counts.add(&batch);
        Ok(())
    }

    /// Writes the last rows and the manifest.
    pub(crate) fn finish(mut self, origin: Origin) -> Result<Manifest> {
        self.flush()?;
        let manifest = Manifest::new(self.columns, self.counts, self.files, origin);
        manifest.write(self.dir)?;
        Ok(manifest)
    }
}
