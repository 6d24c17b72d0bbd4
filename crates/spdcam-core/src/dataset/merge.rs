//! Joining datasets: the shards of one `generate` run back into that run, or any datasets
//! with the same columns one after the other.

use super::batch::{Columns, Precision};
use super::manifest::{GenerateSettings, Manifest, Origin};
use super::reader::Dataset;
use super::writer::{prepare_output, DatasetWriter};
use super::DEFAULT_CHUNK_SIZE;
use crate::error::{Error, Result};
use std::path::Path;

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

/// Refuses two inputs that hold the same samples: overlapping samples of one generate run
/// (a dataset given twice, a copy of it, runs with the same seed and settings), the same
/// part of one split, or identical sample files. Merging them would hold each sample twice,
/// and a split of the result would put copies in both train and test.
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
                             Give each dataset once, or generate with another --seed",
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
                    "{} are the same part of one split: merging would hold each sample twice",
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
                     its samples twice",
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

/// Merges `inputs` into the dataset directory `out`. When they are the shards of one
/// `generate` run (in any order), the result is that run as one directory — the same files
/// a single run writes — and every shard must be present. Otherwise the datasets are
/// joined one after the other (same columns needed), keeping their sample numbers.
/// `progress` is told how many rows were copied.
pub fn merge(
    inputs: &[Dataset],
    out: &Path,
    overwrite: bool,
    progress: &dyn Fn(u64),
) -> Result<Manifest> {
    if inputs.is_empty() {
        return Err(Error::invalid("merge needs at least one dataset"));
    }
    let dirs: Vec<&Path> = inputs.iter().map(Dataset::dir).collect();
    crate::fsio::check_output_apart(out, &dirs)?;
    let shards = shards_of_one_run(inputs);
    if shards.is_none() {
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
    let output = prepare_output(out, &dirs, overwrite)?;
    let mut writer = DatasetWriter::new(out, columns, chunk_size)?;
    for dataset in ordered {
        for batch in dataset.batches() {
            let batch = batch?;
            for i in 0..batch.len() {
                writer.push(batch.row(i))?;
            }
            progress(batch.len() as u64);
        }
    }
    let manifest = writer.finish(origin)?;
    output.finish();
    Ok(manifest)
}
