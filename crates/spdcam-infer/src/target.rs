//! What a model predicts and how an SPD comes back from it: PCA coefficients of the SPD
//! (the default), the same with the light's u′v′ chromaticity beside them (`--target
//! pca-colour`, [`crate::colour_head`]), or the channel weights of a luminaire (`--target
//! weights`, the thesis's G/H experiments), whose channel spectra are fitted from the
//! training data.

use crate::colour_head::{ColourHead, Conformer};
use crate::colour_map::ColourMap;
use crate::error::{InferError, Result};
use crate::pca::{Components, Pca};
use faer::{linalg::solvers::Solve, Mat, Side};
use serde::{Deserialize, Serialize};

/// Which targets to train on.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum TargetKind {
    /// PCA coefficients of the max-normalised SPD.
    Pca(Components),
    /// PCA coefficients and the light's u′v′, the colour outputs weighing `colour_weight`
    /// PCA coefficients each in the loss.
    PcaColour {
        /// The PCA components kept.
        components: Components,
        /// The weight of each colour output against one PCA coefficient.
        colour_weight: f64,
    },
    /// The luminaire's channel weights.
    Weights,
}

/// PCA coefficients and the light's chromaticity: the network's outputs are the
/// coefficients, then u′ and v′.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PcaColour {
    /// The PCA of the training SPDs.
    pub pca: Pca,
    /// The colour outputs.
    pub colour: ColourHead,
}

/// The channel spectra of a luminaire, fitted so that an SPD is
/// `Σ wᵢ·channelᵢ` divided by its maximum.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Channels {
    /// Channel names (the dataset's weight columns).
    pub names: Vec<String>,
    /// One spectrum per channel on the model's grid.
    pub spectra: Vec<Vec<f64>>,
    /// RMSE between the training SPDs and the ones the fitted channels give for their weights.
    pub fit_rmse: f64,
}

/// A model's target space: how targets are made from an SPD and an SPD from targets.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Target {
    /// PCA coefficients.
    Pca(Pca),
    /// PCA coefficients, then the light's u′v′.
    #[serde(rename = "pca-colour")]
    PcaColour(PcaColour),
    /// Channel weights.
    Weights(Channels),
}

/// A [`Target`] ready to decode many rows ([`Target::decoder`]).
pub struct Decoder<'a> {
    target: &'a Target,
    /// The colour head of a PCA-colour target that pulls the spectrum.
    colour: Option<Conformer<'a>>,
    /// The colour map and its head, for a PCA target.
    map: Option<(&'a ColourMap, Conformer<'a>)>,
}

impl Decoder<'_> {
    /// The (relative, max-normalised, non-negative) SPD for one row of targets, as
    /// [`Target::decode_into`] makes it.
    pub fn decode_into(&self, targets: &[f64], spd: &mut [f64]) {
        match self.target {
            Target::Pca(p) => match &self.map {
                Some((map, conformer)) => {
                    let mut coefficients = targets.to_vec();
                    map.correct_with(conformer, &mut coefficients);
                    p.reconstruct_into(&coefficients, spd);
                }
                None => p.reconstruct_into(targets, spd),
            },
            Target::PcaColour(p) => {
                let k = p.pca.len();
                let mut coefficients = targets[..k].to_vec();
                if let Some(colour) = &self.colour {
                    colour.conform(&mut coefficients, [targets[k], targets[k + 1]]);
                }
                if let Some((map, conformer)) = &self.map {
                    map.correct_with(conformer, &mut coefficients);
                }
                p.pca.reconstruct_into(&coefficients, spd);
            }
            Target::Weights(c) => {
                spd.iter_mut().for_each(|v| *v = 0.0);
                for (w, ch) in targets.iter().zip(&c.spectra) {
                    for (v, x) in spd.iter_mut().zip(ch) {
                        *v += w.max(0.0) * x;
                    }
                }
            }
        }
        // An estimate is a relative SPD: peak 1, nothing below 0.
        spdcam_core::spectral::clip_normalise(spd);
    }
}

impl Target {
    /// The number of targets.
    pub fn len(&self) -> usize {
        match self {
            Target::Pca(p) => p.len(),
            Target::PcaColour(p) => p.pca.len() + 2,
            Target::Weights(c) => c.names.len(),
        }
    }

    /// Whether there are no targets (never true for a fitted target).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The SPD's length.
    pub fn spd_len(&self) -> usize {
        match self {
            Target::Pca(p) => p.dim(),
            Target::PcaColour(p) => p.pca.dim(),
            Target::Weights(c) => c.spectra.first().map_or(0, Vec::len),
        }
    }

    /// The (relative, max-normalised, non-negative) SPD for one row of targets, its colour
    /// corrected by `map` where given (a PCA target only: [`ColourMap::correct`]). For many
    /// rows, [`Target::decoder`] once.
    pub fn decode_into(&self, targets: &[f64], spd: &mut [f64], map: Option<&ColourMap>) {
        self.decoder(map).decode_into(targets, spd);
    }

    /// A decoder of many rows of targets, its colour corrected by `map` where given: what
    /// does not depend on the row computed once.
    pub fn decoder<'a>(&'a self, map: Option<&'a ColourMap>) -> Decoder<'a> {
        let pca = self.pca();
        Decoder {
            target: self,
            // A head that does not pull (0) leaves the spectrum as it is.
            colour: match self {
                Target::PcaColour(p) if p.colour.pull != 0.0 => Some(p.colour.conformer(&p.pca)),
                _ => None,
            },
            map: map.zip(pca).map(|(m, pca)| (m, m.head.conformer(pca))),
        }
    }

    /// The targets of one max-normalised SPD on the model's grid, or `None` for a target
    /// made from channel weights (their targets are the dataset's weights).
    pub fn encode(&self, spd: &[f64]) -> Option<Vec<f64>> {
        match self {
            Target::Pca(p) => Some(p.project(spd)),
            Target::PcaColour(p) => {
                let mut t = p.pca.project(spd);
                t.extend(p.colour.uv(spd).unwrap_or([0.0; 2]));
                Some(t)
            }
            Target::Weights(_) => None,
        }
    }

    /// The PCA of the SPDs, for a target that has one.
    pub fn pca(&self) -> Option<&Pca> {
        match self {
            Target::Pca(p) => Some(p),
            Target::PcaColour(p) => Some(&p.pca),
            Target::Weights(_) => None,
        }
    }

    /// Checks the stored numbers (for a target read from a file).
    pub fn validate(&self) -> Result<()> {
        match self {
            Target::Pca(p) => p.validate(),
            Target::PcaColour(p) => {
                p.pca.validate()?;
                p.colour.validate(p.pca.dim())
            }
            Target::Weights(c) => {
                let d = self.spd_len();
                if c.names.is_empty()
                    || c.names.len() != c.spectra.len()
                    || d == 0
                    || c.spectra.iter().any(|s| s.len() != d)
                {
                    return Err(InferError::invalid(
                        "the channel spectra do not match their names or grid",
                    ));
                }
                if c.spectra.iter().flatten().any(|v| !v.is_finite()) {
                    return Err(InferError::invalid(
                        "the channel spectra hold non-finite numbers",
                    ));
                }
                Ok(())
            }
        }
    }
}

impl Channels {
    /// Fits channel spectra to rows of weights (`k` per row) and max-normalised SPDs (`d` per
    /// row): alternating least squares on `mᵢ·spdᵢ = wᵢ·C` with `mᵢ = max(wᵢ·C)`. A channel
    /// whose weight is always 0 gets a zero spectrum.
    pub fn fit(names: Vec<String>, weights: &[f64], spds: &[f64], d: usize) -> Result<Channels> {
        let k = names.len();
        if k == 0 || d == 0 || !weights.len().is_multiple_of(k) || !spds.len().is_multiple_of(d) {
            return Err(InferError::invalid(
                "the weights and SPDs do not form rows for a channel fit",
            ));
        }
        let n = weights.len() / k;
        if spds.len() / d != n || n < k {
            return Err(InferError::invalid(format!(
                "a channel fit needs as many weight rows as SPD rows and at least {k}, got {n} and {}",
                spds.len() / d
            )));
        }
        let w = Mat::<f64>::from_fn(n, k, |i, j| weights[i * k + j]);
        let mut gram = w.transpose() * &w;
        let trace: f64 = (0..k).map(|j| gram[(j, j)]).sum();
        if trace <= 0.0 {
            return Err(InferError::invalid("every channel weight is 0"));
        }
        for j in 0..k {
            gram[(j, j)] += 1e-9 * trace / k as f64;
        }
        let llt = gram
            .llt(Side::Lower)
            .map_err(|e| InferError::Numerical(format!("channel fit: {e:?}")))?;
        let mut scale = vec![1.0f64; n];
        let mut c = Mat::<f64>::zeros(k, d);
        for _ in 0..200 {
            let rhs = Mat::<f64>::from_fn(n, d, |i, j| scale[i] * spds[i * d + j]);
            c = llt.solve(w.transpose() * &rhs);
            let fitted = &w * &c;
            let mut change: f64 = 0.0;
            for (i, s) in scale.iter_mut().enumerate() {
                let m = (0..d).map(|j| fitted[(i, j)]).fold(0.0, f64::max);
                if m > 0.0 {
                    change = change.max((m / *s - 1.0).abs());
                    *s = m;
                }
            }
            if change < 1e-10 {
                break;
            }
        }
        // Give the channels unit peaks (the overall scale is free).
        let peak = (0..k)
            .flat_map(|r| (0..d).map(move |j| (r, j)))
            .map(|(r, j)| c[(r, j)])
            .fold(0.0, f64::max);
        let peak = if peak > 0.0 { peak } else { 1.0 };
        let spectra: Vec<Vec<f64>> = (0..k)
            .map(|r| (0..d).map(|j| c[(r, j)] / peak).collect())
            .collect();
        let mut channels = Channels {
            names,
            spectra,
            fit_rmse: 0.0,
        };
        let target = Target::Weights(channels.clone());
        let mut sq = 0.0;
        let mut spd = vec![0.0; d];
        for i in 0..n {
            target.decode_into(&weights[i * k..(i + 1) * k], &mut spd, None);
            sq += spd
                .iter()
                .zip(&spds[i * d..(i + 1) * d])
                .map(|(a, b)| (a - b) * (a - b))
                .sum::<f64>();
        }
        channels.fit_rmse = (sq / (n * d) as f64).sqrt();
        Ok(channels)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    #[test]
    fn channel_fit_recovers_gaussian_channels() {
        let d = 61;
        let mus = [430.0, 510.0, 590.0, 670.0];
        let truth: Vec<Vec<f64>> = mus
            .iter()
            .map(|mu| {
                (0..d)
                    .map(|j| {
                        let l = 400.0 + 5.0 * j as f64;
                        (-(l - mu) * (l - mu) / 800.0).exp()
                    })
                    .collect()
            })
            .collect();
        let mut rng = rand::rngs::SmallRng::seed_from_u64(5);
        let n = 200;
        let mut weights = Vec::new();
        let mut spds = Vec::new();
        for _ in 0..n {
            let w: Vec<f64> = (0..4).map(|_| rng.random_range(0.0..1.0)).collect();
            let mut s: Vec<f64> = (0..d)
                .map(|j| (0..4).map(|c| w[c] * truth[c][j]).sum())
                .collect();
            spdcam_core::spectral::normalise_peak(&mut s).unwrap();
            weights.extend(w);
            spds.extend(s);
        }
        let names = (1..=4).map(|i| format!("w{i}")).collect();
        let ch = Channels::fit(names, &weights, &spds, d).unwrap();
        assert!(ch.fit_rmse < 1e-6, "fit RMSE {}", ch.fit_rmse);
    }
}
