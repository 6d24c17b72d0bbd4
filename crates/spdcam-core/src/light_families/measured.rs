//! Measured SPDs as a light family: one of a set at random, or a random mixture of two.

use crate::builtin::{self, DataDir};
use crate::error::{Error, Result};
use crate::spectral::{normalise_peak, Extrapolation, Grid, Interpolation};
use rand::rngs::SmallRng;
use rand::Rng;

/// A set of measured SPDs on the working grid, each normalised by its maximum.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredSpds {
    /// The set's name (its file or recipe name).
    pub name: String,
    /// The SPDs, each with maximum 1.
    pub spds: Vec<Vec<f64>>,
    /// Mix two different SPDs of the set in random proportions instead of picking one.
    pub mix_pairs: bool,
}

impl MeasuredSpds {
    /// Parses `FILE[:mix]` (a spectral CSV by path or name under the data directory).
    pub fn parse(rest: &str, spec: &str, data_dir: &DataDir, grid: &Grid) -> Result<MeasuredSpds> {
        let (file, option) = match rest.rsplit_once(':') {
            Some((f, "mix")) => (f, true),
            _ => (rest, false),
        };
        if file.is_empty() {
            return Err(Error::invalid(format!(
                "'{spec}': name a spectral CSV of SPDs, e.g. spds:lamps.csv or spds:lamps.csv:mix"
            )));
        }
        let (name, set) = builtin::resolve_table(file, "SPD set", &[], data_dir, &["spds"])?;
        let set = set.require_non_negative(&format!("{name} SPD"), 0.05)?;
        let (set, _) = set.resample(grid, Interpolation::Linear, Extrapolation::Zero)?;
        let mut spds = Vec::with_capacity(set.len());
        for (item, values) in set.names().iter().zip(set.items()) {
            let mut spd = values.clone();
            if normalise_peak(&mut spd).is_err() {
                return Err(Error::invalid(format!(
                    "{name}: SPD '{item}' is dark on {grid}"
                )));
            }
            spds.push(spd);
        }
        if option && spds.len() < 2 {
            return Err(Error::invalid(format!(
                "'{spec}': mixing pairs needs at least two SPDs; {name} has {}",
                spds.len()
            )));
        }
        Ok(MeasuredSpds {
            name,
            spds,
            mix_pairs: option,
        })
    }

    /// One SPD of the set, or a mixture a·s₁ + (1 − a)·s₂ of two different ones (a uniform on
    /// [0, 1)), normalised by its maximum.
    pub fn draw(&self, rng: &mut SmallRng) -> Vec<f64> {
        let n = self.spds.len();
        let first = rng.random_range(0..n);
        if !self.mix_pairs {
            return self.spds[first].clone();
        }
        let second = (first + rng.random_range(1..n)) % n;
        let a = rng.random::<f64>();
        let mut spd: Vec<f64> = self.spds[first]
            .iter()
            .zip(&self.spds[second])
            .map(|(x, y)| a * x + (1.0 - a) * y)
            .collect();
        // A mix of two lit spectra is lit: the normalisation cannot fail.
        normalise_peak(&mut spd).ok();
        spd
    }

    /// One line for manifests.
    pub fn describe(&self) -> String {
        format!(
            "measured SPDs {} ({} SPDs){}",
            self.name,
            self.spds.len(),
            if self.mix_pairs {
                ", random mixtures of two"
            } else {
                ", one at random"
            }
        )
    }
}
