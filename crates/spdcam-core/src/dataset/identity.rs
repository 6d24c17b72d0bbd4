//! Sample identity by content: a 128-bit hash of each sample's features and light, so that a
//! sample is recognised whatever path it came by (a split part, an export imported again,
//! a copy of a directory) even when its sample number and family were lost on the way.
//!
//! Memory: one entry a sample (a 128-bit hash and the input it came from: 24 bytes, in a
//! hash table kept at most 7/8 full, about 34 bytes a sample), so the default of
//! [`limits::DISTINCT_SAMPLES`], 25 million samples, takes about 0.8 GiB and 10⁸ samples
//! about 3.4 GiB; the limit is checked before the table is made.

use super::batch::SampleRow;
use crate::error::Result;
use crate::limits;
use std::collections::HashMap;

/// The content hash of one sample: the first 128 bits of SHA-256 (FIPS 180-4) over its
/// feature values then its light, each rounded to single precision (IEEE 754 binary32,
/// little-endian, −0 taken as +0). The light is its channel weights when the dataset has
/// them (they make the SPD: an import from weights rebuilds each SPD from weights stored as
/// float32, so the SPDs differ from the generated ones in their last bits while the weights
/// are exact), else its SPD. Single precision is what generated datasets store: a float32
/// value exported to CSV (the fewest digits that read back as the same float32) and
/// imported again (as float64) hashes the same, while any change a float32 can hold changes
/// the hash. Sample numbers, families and attempts are left out: an import numbers its rows
/// afresh and names its own family.
pub fn sample_hash(row: &SampleRow<'_>) -> [u64; 2] {
    use sha2::Digest;
    let light = if row.weights.is_empty() {
        row.spd
    } else {
        row.weights
    };
    let mut buffer = Vec::with_capacity(4 * (row.features.len() + light.len()));
    for &v in row.features.iter().chain(light) {
        let single = if v == 0.0 { 0.0f32 } else { v as f32 };
        buffer.extend_from_slice(&single.to_le_bytes());
    }
    let digest = sha2::Sha256::digest(&buffer);
    let word = |k: usize| u64::from_le_bytes(digest[k..k + 8].try_into().expect("8 bytes"));
    [word(0), word(8)]
}

/// The samples seen so far, each with the input (0-based) that first held it.
#[derive(Debug)]
pub struct SeenSamples {
    first_in: HashMap<[u64; 2], u32>,
}

impl SeenSamples {
    /// Room for `samples` samples; refused beyond [`limits::DISTINCT_SAMPLES`], the error
    /// naming `context`.
    pub fn with_capacity(samples: u64, context: &str) -> Result<SeenSamples> {
        limits::DISTINCT_SAMPLES.check(samples, context)?;
        Ok(SeenSamples {
            first_in: HashMap::with_capacity(samples as usize),
        })
    }

    /// Records `row` of input `input`; when an equal sample was seen before, gives the input
    /// that first held it (and records nothing).
    pub fn insert(&mut self, row: &SampleRow<'_>, input: u32) -> Option<u32> {
        let hash = sample_hash(row);
        match self.first_in.entry(hash) {
            std::collections::hash_map::Entry::Occupied(e) => Some(*e.get()),
            std::collections::hash_map::Entry::Vacant(e) => {
                e.insert(input);
                None
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row<'a>(features: &'a [f64], spd: &'a [f64]) -> SampleRow<'a> {
        SampleRow {
            sample: 0,
            family: "f",
            features,
            spd,
            weights: &[],
            attempts: 1,
        }
    }

    #[test]
    fn a_float32_value_written_as_text_and_read_back_hashes_the_same() {
        let stored = [0.1f32 as f64, 200.7f32 as f64];
        let text: Vec<f64> = stored
            .iter()
            .map(|&v| format!("{}", v as f32).parse::<f64>().unwrap())
            .collect();
        assert_ne!(
            stored,
            text.as_slice(),
            "the test needs values that differ as f64"
        );
        assert_eq!(
            sample_hash(&row(&stored, &[1.0])),
            sample_hash(&row(&text, &[1.0]))
        );
        assert_eq!(
            sample_hash(&row(&[-0.0], &[1.0])),
            sample_hash(&row(&[0.0], &[1.0]))
        );
        assert_ne!(
            sample_hash(&row(&[1.0], &[0.5])),
            sample_hash(&row(&[1.0], &[0.25]))
        );
        assert_ne!(
            sample_hash(&row(&[1.0], &[0.5])),
            sample_hash(&row(&[1.1], &[0.5]))
        );
    }

    #[test]
    fn with_weights_the_light_is_its_weights() {
        let weights = [0.8f32 as f64, 0.35f32 as f64];
        let with = |spd: &'static [f64]| SampleRow {
            weights: &weights,
            ..row(&[1.0], spd)
        };
        assert_eq!(
            sample_hash(&with(&[0.5, 1.0])),
            sample_hash(&with(&[0.5000001, 1.0]))
        );
        let other = [0.8f32 as f64, 0.36f32 as f64];
        let changed = SampleRow {
            weights: &other,
            ..row(&[1.0], &[0.5, 1.0])
        };
        assert_ne!(sample_hash(&with(&[0.5, 1.0])), sample_hash(&changed));
    }

    #[test]
    fn repeated_samples_name_the_input_that_first_held_them() {
        let mut seen = SeenSamples::with_capacity(3, "test").unwrap();
        assert_eq!(seen.insert(&row(&[1.0], &[1.0]), 0), None);
        assert_eq!(seen.insert(&row(&[2.0], &[1.0]), 1), None);
        assert_eq!(seen.insert(&row(&[1.0], &[1.0]), 1), Some(0));
        assert_eq!(seen.insert(&row(&[2.0], &[1.0]), 2), Some(1));
    }
}
