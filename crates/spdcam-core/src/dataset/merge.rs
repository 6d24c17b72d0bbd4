//! Joining datasets: the shards of one `generate` run back into that run, or any datasets
//! with the same columns one after the other, each sample once: samples already held (by
//! content, [`super::identity::sample_hash`]) are refused or dropped.

use super::batch::{Columns, Precision};
use super::identity::SeenSamples;
use super::manifest::{GenerateSettings, Manifest, Origin};
use super::reader::Dataset;
use super::writer::{prepare_output, DatasetWriter};
use super::DEFAULT_CHUNK_SIZE;
use crate::error::{Error, Result};
use std::collections::BTreeMap;
use std::path::Path;

/// What [`merge`] does with a sample it already holds (same features and light as an earlier
/// sample of the inputs, whatever path it came by: a split part, an export imported again,
/// a copy).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Duplicates {
    /// Refuse the merge, naming how many samples repeat and in which inputs.
    Refuse,
    /// Keep the first copy of each sample and leave the others out.
    Drop,
}

/// What [`merge`] wrote.
#[derive(Debug, Clone)]
pub struct MergeReport {
    /// The manifest of the merged dataset.
    pub manifest: Manifest,
    /// Samples left out as copies of earlier ones ([`Duplicates::Drop`]).
    pub dropped: u64,
}

/// The settings shared by shards of one run, and the shards in sample order; `None` when
/// the inputs are not all shards of one run.
fn shards_of_one_run(inputs: &[Dataset]) -> Option<(GenerateSettings, Vec<&Dataset>)> {
    let whole = |s: &GenerateSettings| GenerateSettings {
        shard: None,
        sample_range: [0, s.count],
        ..s.clone()
    };
    let first = inputs.first()?;
    let settings = match &first.manifest().origin {
        Origin::Generated(s) if s.shard.is_some() => whole(s),
        _ => return None,
    };
    let same_run = inputs.iter().all(|d| {
        let m = d.manifest();
        matches!(&m.origin, Origin::Generated(s) if s.shard.is_some() && whole(s) == settings)
            && m.columns == first.manifest().columns
            && m.spdcam_version == first.manifest().spdcam_version
    });
    if !same_run {
        return None;
    }
    let mut ordered: Vec<&Dataset> = inputs.iter().collect();
    ordered.sort_by_key(|d| d.manifest().origin.generated().map(|s| s.sample_range));
    Some((settings, ordered))
}

/// Checks that the shards' sample ranges tile `[0, count)` exactly.
fn check_coverage(settings: &GenerateSettings, shards: &[&Dataset]) -> Result<()> {
    let mut next = 0;
    for d in shards {
        let s = d
            .manifest()
            .origin
            .generated()
            .expect("shards are generated");
        let [start, end] = s.sample_range;
        if start == end {
            continue;
        }
        let shard = s.shard.map(|s| s.to_string()).unwrap_or_default();
        if start > next {
            return Err(Error::invalid(format!(
                "samples {next}–{} are missing: no shard holds them (found shard {shard} of {} starting at {start})",
                start - 1,
                d.dir().display()
            )));
        }
        if start < next {
            return Err(Error::invalid(format!(
                "shard {shard} of {} overlaps another shard (samples from {start})",
                d.dir().display()
            )));
        }
        next = end;
    }
    if next != settings.count {
        return Err(Error::invalid(format!(
            "samples {next}–{} of the run's {} are missing: a shard was not given",
            settings.count - 1,
            settings.count
        )));
    }
    Ok(())
}

/// The generate runs whose samples `origin` holds: its own, or those of the datasets it
/// merged. (A split part holds only some of its source's samples, so it is not looked into.)
fn generated_runs(origin: &Origin) -> Vec<&GenerateSettings> {
    match origin {
        Origin::Generated(s) => vec![s.as_ref()],
        Origin::Merged { sources } => sources.iter().flat_map(generated_runs).collect(),
        Origin::Imported(_) | Origin::Split { .. } => Vec::new(),
    }
}

/// Whether two runs draw the same sample for the same number: everything that makes a
/// sample equal (seed, lighting, camera, chart, pipeline, grid, randomisation), whatever
/// the count, the shard or the file size.
fn same_draws(a: &GenerateSettings, b: &GenerateSettings) -> bool {
    let draws = |s: &GenerateSettings| GenerateSettings {
        count: 0,
        shard: None,
        sample_range: [0, 0],
        chunk_size: 0,
        images: false,
        ..s.clone()
    };
    draws(a) == draws(b)
}

/// Refuses two inputs that hold the same samples, from their manifests alone (before any
/// sample is read): overlapping samples of one generate run (a dataset given twice, a copy
/// of it, runs with the same seed and settings), the same part of one split, or identical
/// sample files. Merging them would hold each sample twice, and a split of the result would
/// put copies in both train and test.
fn check_distinct(inputs: &[Dataset]) -> Result<()> {
    for (i, a) in inputs.iter().enumerate() {
        for b in &inputs[i + 1..] {
            let (ma, mb) = (a.manifest(), b.manifest());
            let shown = || format!("{} and {}", a.dir().display(), b.dir().display());
            for ra in generated_runs(&ma.origin) {
                for rb in generated_runs(&mb.origin) {
                    let start = ra.sample_range[0].max(rb.sample_range[0]);
                    let end = ra.sample_range[1].min(rb.sample_range[1]);
                    if same_draws(ra, rb) && start < end {
                        return Err(Error::invalid(format!(
                            "{} hold the same samples: numbers {start}–{} of one generate run \
                             (lighting {}, seed {}); merging would hold each of them twice. \
                             Give each dataset once, generate with another --seed, or add \
                             --drop-duplicates to keep one copy of each",
                            shown(),
                            end - 1,
                            ra.lighting.spec,
                            ra.seed
                        )));
                    }
                }
            }
            if matches!(ma.origin, Origin::Split { .. }) && ma.origin == mb.origin {
                return Err(Error::invalid(format!(
                    "{} are the same part of one split: merging would hold each sample twice \
                     (add --drop-duplicates to keep one copy of each)",
                    shown()
                )));
            }
            let shared = ma
                .files
                .iter()
                .find(|f| f.sha256.is_some() && mb.files.iter().any(|g| g.sha256 == f.sha256));
            if let Some(file) = shared {
                return Err(Error::invalid(format!(
                    "{} hold identical sample files ({} of the first): merging would hold \
                     its samples twice (add --drop-duplicates to keep one copy of each)",
                    shown(),
                    file.name
                )));
            }
        }
    }
    Ok(())
}

/// The columns all inputs share (features stored in the widest precision of any input).
fn common_columns(inputs: &[Dataset]) -> Result<Columns> {
    let first = inputs[0].columns();
    for d in &inputs[1..] {
        let c = d.columns();
        let what = if c.feature_names != first.feature_names {
            Some("feature columns")
        } else if c.spd_grid != first.spd_grid {
            Some("SPD grid")
        } else if c.weight_names != first.weight_names {
            Some("weight columns")
        } else {
            None
        };
        if let Some(what) = what {
            return Err(Error::invalid(format!(
                "{} and {} have different {what}; only datasets with the same columns can be merged",
                inputs[0].dir().display(),
                d.dir().display()
            )));
        }
    }
    let precision = inputs
        .iter()
        .map(|d| d.columns().feature_precision)
        .max()
        .unwrap_or(Precision::Float32);
    Ok(Columns {
        feature_precision: precision,
        ..first.clone()
    })
}

/// The error for samples found again: `repeats[(first, later)]` samples of input `later`
/// were already held by input `first`.
fn repeated(inputs: &[&Dataset], repeats: &BTreeMap<(usize, usize), u64>) -> Error {
    let total: u64 = repeats.values().sum();
    let pairs: Vec<String> = repeats
        .iter()
        .map(|(&(first, later), n)| {
            let later_dir = inputs[later].dir().display();
            if first == later {
                format!("{n} of {later_dir} repeat samples of {later_dir} itself")
            } else {
                format!(
                    "{n} of {later_dir} are already in {}",
                    inputs[first].dir().display()
                )
            }
        })
        .collect();
    Error::invalid(format!(
        "{total} samples would be held twice (same features and light): {}. A model would weigh \
         them double, and a split of the result could put copies of one sample in both train \
         and test. Give each sample's dataset once, or add --drop-duplicates to keep the first \
         copy of each",
        pairs.join("; ")
    ))
}

/// Merges `inputs` into the dataset directory `out`. When they are the shards of one
/// `generate` run (in any order), the result is that run as one directory — the same files
/// a single run writes — and every shard must be present (their sample ranges prove them
/// distinct). Otherwise the datasets are joined one after the other (same columns needed),
/// keeping their sample numbers, and each sample is recognised by its content
/// ([`super::identity::sample_hash`]; at most [`crate::limits::DISTINCT_SAMPLES`] samples):
/// one already held refuses the merge, or with [`Duplicates::Drop`] is left out. Nothing
/// is left in `out` when the merge fails. `progress` is told how many rows were read.
pub fn merge(
    inputs: &[Dataset],
    out: &Path,
    overwrite: bool,
    duplicates: Duplicates,
    progress: &dyn Fn(u64),
) -> Result<MergeReport> {
    if inputs.is_empty() {
        return Err(Error::invalid("merge needs at least one dataset"));
    }
    let dirs: Vec<&Path> = inputs.iter().map(Dataset::dir).collect();
    crate::fsio::check_output_apart(out, &dirs)?;
    let shards = shards_of_one_run(inputs);
    if shards.is_none() && duplicates == Duplicates::Refuse {
        check_distinct(inputs)?;
    }
    let (ordered, columns, chunk_size, origin) = match shards {
        Some((settings, shards)) => {
            check_coverage(&settings, &shards)?;
            let columns = shards[0].columns().clone();
            (
                shards,
                columns,
                settings.chunk_size,
                Origin::Generated(Box::new(settings)),
            )
        }
        None => (
            inputs.iter().collect(),
            common_columns(inputs)?,
            DEFAULT_CHUNK_SIZE,
            Origin::Merged {
                sources: inputs.iter().map(|d| d.manifest().origin.clone()).collect(),
            },
        ),
    };
    let mut seen = match &origin {
        Origin::Generated(_) => None,
        _ => {
            let total = inputs.iter().map(Dataset::len).sum();
            let context = format!("merging {} datasets", inputs.len());
            Some(SeenSamples::with_capacity(total, &context)?)
        }
    };
    let output = prepare_output(out, &dirs, overwrite)?;
    let mut writer = DatasetWriter::new(out, columns, chunk_size)?;
    let mut repeats: BTreeMap<(usize, usize), u64> = BTreeMap::new();
    for (k, dataset) in ordered.iter().enumerate() {
        for batch in dataset.batches() {
            let batch = batch?;
            for i in 0..batch.len() {
                let row = batch.row(i);
                if let Some(first) = seen.as_mut().and_then(|s| s.insert(&row, k as u32)) {
                    *repeats.entry((first as usize, k)).or_insert(0) += 1;
                } else if repeats.is_empty() || duplicates == Duplicates::Drop {
                    writer.push(row)?;
                }
            }
            progress(batch.len() as u64);
        }
    }
    if !repeats.is_empty() && duplicates == Duplicates::Refuse {
        return Err(repeated(&ordered, &repeats));
    }
    let manifest = writer.finish(origin)?;
    output.finish();
    Ok(MergeReport {
        manifest,
        dropped: repeats.values().sum(),
    })
}
