//! Reading a dataset directory: its manifest and its samples, one file at a time or all.

use super::batch::{Columns, Counts, SampleBatch};
use super::file_read;
use super::identity::SeenSamples;
use super::lock::DirLock;
use super::manifest::{FileEntry, Manifest};
use crate::error::{Error, Result};
use crate::limits;
use std::path::{Path, PathBuf};

/// Reads sample file `entry` of the dataset in `dir`: its bytes (size checked against
/// [`limits::CHUNK_BYTES`]), checked against the manifest's checksum, then decoded.
pub(crate) fn read_sample_file(
    dir: &Path,
    entry: &FileEntry,
    columns: &Columns,
) -> Result<SampleBatch> {
    let path = dir.join(&entry.name);
    let source = path.display().to_string();
    let size = std::fs::metadata(&path)
        .map_err(|e| Error::io(&path, e))?
        .len();
    limits::CHUNK_BYTES.check(size, &source)?;
    let bytes = std::fs::read(&path).map_err(|e| Error::io(&path, e))?;
    entry.verify(&bytes, dir)?;
    let batch = file_read::decode(bytes.into(), columns, &source)?;
    if batch.len() as u64 != entry.rows {
        return Err(Error::invalid(format!(
            "{source}: {} rows, the manifest says {}",
            batch.len(),
            entry.rows
        )));
    }
    Ok(batch)
}

/// Whether `name` is a relative path that stays inside the dataset directory.
fn inside(name: &str) -> bool {
    let path = Path::new(name);
    !name.is_empty()
        && path
            .components()
            .all(|c| matches!(c, std::path::Component::Normal(_)))
}

/// What [`Dataset::verify`] found.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Verification {
    /// Files read and found as the manifest describes them.
    pub files_ok: usize,
    /// Of those, files the manifest has no checksum for (older datasets).
    pub without_checksum: usize,
    /// What is wrong, one line each, naming the file.
    pub problems: Vec<String>,
    /// Samples that repeat an earlier sample of the dataset (same features and light,
    /// [`super::sample_hash`]); when any do, `problems` says so too.
    pub duplicates: u64,
    /// Why the samples were not checked for duplicates (more of them than
    /// [`limits::DISTINCT_SAMPLES`]), when they were not.
    pub duplicates_unchecked: Option<String>,
}

/// An opened dataset directory.
#[derive(Debug, Clone)]
pub struct Dataset {
    dir: PathBuf,
    manifest: Manifest,
}

impl Dataset {
    /// Opens `dir`: reads the manifest and checks that every sample file it lists is there.
    pub fn open(dir: &Path) -> Result<Dataset> {
        let manifest = Manifest::read(dir)?;
        let listed: u64 = manifest.files.iter().map(|f| f.rows).sum();
        if listed != manifest.samples {
            return Err(Error::invalid(format!(
                "{}: the manifest counts {} samples but its files hold {listed}",
                dir.display(),
                manifest.samples
            )));
        }
        if let Some(f) = manifest.files.iter().find(|f| !inside(&f.name)) {
            return Err(Error::invalid(format!(
                "{}: the manifest lists sample file '{}', which is not a path inside the dataset",
                dir.display(),
                f.name
            )));
        }
        if let Some(f) = manifest.files.iter().find(|f| !dir.join(&f.name).is_file()) {
            return Err(Error::invalid(format!(
                "{}: sample file {} listed in the manifest is missing",
                dir.display(),
                f.name
            )));
        }
        Ok(Dataset {
            dir: dir.to_path_buf(),
            manifest,
        })
    }

    /// The directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The manifest.
    pub fn manifest(&self) -> &Manifest {
        &self.manifest
    }

    /// The columns of the samples.
    pub fn columns(&self) -> &Columns {
        &self.manifest.columns
    }

    /// Number of samples.
    pub fn len(&self) -> u64 {
        self.manifest.samples
    }

    /// Whether the dataset holds no sample.
    pub fn is_empty(&self) -> bool {
        self.manifest.samples == 0
    }

    /// Reads sample file `k` of the manifest, checking its checksum.
    pub fn read_file(&self, k: usize) -> Result<SampleBatch> {
        read_sample_file(&self.dir, &self.manifest.files[k], self.columns())
    }

    /// Reads every sample file and checks it against the manifest: checksum, columns,
    /// finite values, row counts, and the manifest's totals of samples, attempts and
    /// families; and that no sample repeats another (by content, up to
    /// [`limits::DISTINCT_SAMPLES`] samples). Unlike reading, it goes on after a bad file
    /// and lists every problem.
    pub fn verify(&self, progress: &dyn Fn(u64)) -> Verification {
        let mut report = Verification::default();
        let mut counts = Counts::default();
        let context = format!("checking {} for duplicate samples", self.dir.display());
        let mut seen = match SeenSamples::with_capacity(self.len(), &context) {
            Ok(seen) => Some(seen),
            Err(e) => {
                report.duplicates_unchecked = Some(e.to_string());
                None
            }
        };
        for (k, entry) in self.manifest.files.iter().enumerate() {
            match self.read_file(k) {
                Ok(batch) => {
                    report.files_ok += 1;
                    report.without_checksum += usize::from(entry.sha256.is_none());
                    counts.add(&batch);
                    if let Some(seen) = seen.as_mut() {
                        for i in 0..batch.len() {
                            if seen.insert(&batch.row(i), 0).is_some() {
                                report.duplicates += 1;
                            }
                        }
                    }
                    progress(batch.len() as u64);
                }
                Err(e) => report.problems.push(e.to_string()),
            }
        }
        if report.duplicates > 0 {
            report.problems.push(format!(
                "{}: {} samples repeat earlier samples of the dataset (same features and light): \
                 a model would weigh them double, and a split could put copies of one sample in \
                 both train and test; keep one copy of each with `spdcam dataset merge {} \
                 --drop-duplicates -o NEW_DIR`",
                self.dir.display(),
                report.duplicates,
                self.dir.display()
            ));
        }
        if report.problems.is_empty() {
            let m = &self.manifest;
            if (counts.samples, counts.attempts) != (m.samples, m.attempts) {
                report.problems.push(format!(
                    "{}: the files hold {} samples from {} attempts, the manifest says {} from {}",
                    self.dir.display(),
                    counts.samples,
                    counts.attempts,
                    m.samples,
                    m.attempts
                ));
            }
            if counts.families != m.families {
                report.problems.push(format!(
                    "{}: the files' family counts differ from the manifest's",
                    self.dir.display()
                ));
            }
        }
        report
    }

    /// Re-reads every sample file after they were rewritten on purpose (e.g. filtered or
    /// re-encoded with pandas, same columns), and rewrites the manifest with their row
    /// counts, checksums and totals. Takes the directory's lock.
    pub fn update_checksums(dir: &Path) -> Result<Manifest> {
        let _lock = DirLock::acquire(dir)?;
        let mut manifest = Manifest::read(dir)?;
        let mut counts = Counts::default();
        for entry in &mut manifest.files {
            let path = dir.join(&entry.name);
            let bytes = std::fs::read(&path).map_err(|e| Error::io(&path, e))?;
            let batch = file_read::decode(
                bytes.clone().into(),
                &manifest.columns,
                &path.display().to_string(),
            )?;
            counts.add(&batch);
            *entry = FileEntry::of_bytes(entry.name.clone(), batch.len() as u64, &bytes);
        }
        manifest.samples = counts.samples;
        manifest.attempts = counts.attempts;
        manifest.valid_ratio =
            (counts.attempts > 0).then(|| counts.samples as f64 / counts.attempts as f64);
        manifest.families = counts.families;
        manifest.write(dir)?;
        Ok(manifest)
    }

    /// The samples file by file, in row order; one file is in memory at a time.
    pub fn batches(&self) -> impl Iterator<Item = Result<SampleBatch>> + '_ {
        (0..self.manifest.files.len()).map(|k| self.read_file(k))
    }

    /// Every sample in one batch (features and SPDs as row-major matrices).
    pub fn load(&self) -> Result<SampleBatch> {
        let mut all = self.columns().batch();
        for batch in self.batches() {
            all.append(batch?);
        }
        Ok(all)
    }

    /// The rows at the given positions (0-based), in increasing order and each once, reading
    /// only the files that hold them.
    pub fn rows_at(&self, positions: &[u64]) -> Result<SampleBatch> {
        let mut sorted = positions.to_vec();
        sorted.sort_unstable();
        sorted.dedup();
        let mut out = self.columns().batch();
        let mut wanted = sorted.into_iter().peekable();
        let mut first = 0u64;
        for (k, entry) in self.manifest.files.iter().enumerate() {
            let end = first + entry.rows;
            if wanted.peek().is_some_and(|&p| p < end) {
                let batch = self.read_file(k)?;
                while let Some(p) = wanted.next_if(|&p| p < end) {
                    out.push(batch.row((p - first) as usize))?;
                }
            }
            first = end;
        }
        if let Some(p) = wanted.next() {
            return Err(Error::invalid(format!(
                "row {p} is beyond the {} samples of {}",
                self.len(),
                self.dir.display()
            )));
        }
        Ok(out)
    }
}
