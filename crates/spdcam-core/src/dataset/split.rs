//! Seeded train / validation / test splits.

use super::manifest::{Manifest, Origin};
use super::reader::Dataset;
use super::writer::{clear_output, ensure_dir, prepare_output, DatasetWriter, SPLIT_PARTS};
use super::DEFAULT_CHUNK_SIZE;
use crate::error::{Error, Result};
use crate::seed;
use std::path::Path;

/// Which part (0 train, 1 val, 2 test) each of `n` rows goes to: a seeded shuffle
/// (Fisher–Yates driven by [`seed::derive`]) of which the first `round(f₀·n)` rows train,
/// the next `round(f₁·n)` validate and the rest test.
pub fn assign_parts(n: u64, fractions: [f64; 3], seed: u64) -> Result<Vec<u8>> {
    let sum: f64 = fractions.iter().sum();
    if fractions.iter().any(|f| !f.is_finite() || *f < 0.0) || (sum - 1.0).abs() > 1e-6 {
        return Err(Error::invalid(format!(
            "split fractions {},{},{} must be non-negative and add up to 1",
            fractions[0], fractions[1], fractions[2]
        )));
    }
    let n_train = ((fractions[0] * n as f64).round() as u64).min(n);
    let n_val = ((fractions[1] * n as f64).round() as u64).min(n - n_train);
    let mut order: Vec<u64> = (0..n).collect();
    for i in (1..order.len()).rev() {
        let j = (seed::derive(seed, i as u64) % (i as u64 + 1)) as usize;
        order.swap(i, j);
    }
    let mut parts = vec![2u8; n as usize];
    for (k, &row) in order.iter().enumerate() {
        let k = k as u64;
        if k < n_train {
            parts[row as usize] = 0;
        } else if k < n_train + n_val {
            parts[row as usize] = 1;
        }
    }
    Ok(parts)
}

/// Splits `input` into `out/train`, `out/val` and `out/test` by [`assign_parts`]; each part
/// keeps the source's row order and sample numbers. `progress` is told how many rows were
/// copied.
pub fn split(
    input: &Dataset,
    out: &Path,
    fractions: [f64; 3],
    seed: u64,
    overwrite: bool,
    progress: &dyn Fn(u64),
) -> Result<[Manifest; 3]> {
    let parts = assign_parts(input.len(), fractions, seed)?;
    let output = prepare_output(out, &[input.dir()], overwrite)?;
    let dirs = SPLIT_PARTS.map(|p| out.join(p));
    for dir in &dirs {
        ensure_dir(dir)?;
        clear_output(dir, overwrite)?;
    }
    let mut writers = Vec::with_capacity(3);
    for dir in &dirs {
        writers.push(DatasetWriter::new(
            dir,
            input.columns().clone(),
            DEFAULT_CHUNK_SIZE,
        )?);
    }
    let mut position = 0usize;
    for batch in input.batches() {
        let batch = batch?;
        for i in 0..batch.len() {
            writers[parts[position] as usize].push(batch.row(i))?;
            position += 1;
        }
        progress(batch.len() as u64);
    }
    let mut manifests = Vec::with_capacity(3);
    for (writer, part) in writers.into_iter().zip(SPLIT_PARTS) {
        manifests.push(writer.finish(Origin::Split {
            part: part.to_string(),
            fractions,
            seed,
            source_samples: input.len(),
            source: Box::new(input.manifest().origin.clone()),
        })?);
    }
    output.finish();
    Ok(manifests.try_into().expect("one manifest per part"))
}
