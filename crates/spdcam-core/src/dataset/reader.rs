//! Reading a dataset directory: its manifest and its samples, one file at a time or all.

use super::batch::{Columns, SampleBatch};
use super::file;
use super::manifest::Manifest;
use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

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

    /// Reads sample file `k` of the manifest.
    pub fn read_file(&self, k: usize) -> Result<SampleBatch> {
        let entry = &self.manifest.files[k];
        let path = self.dir.join(&entry.name);
        let batch = file::decode(&path, self.columns())?;
        if batch.len() as u64 != entry.rows {
            return Err(Error::invalid(format!(
                "{}: {} rows, the manifest says {}",
                path.display(),
                batch.len(),
                entry.rows
            )));
        }
        Ok(batch)
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
