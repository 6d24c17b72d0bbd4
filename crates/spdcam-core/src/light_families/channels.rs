//! Channels of a tunable source and the rules by which their weights are drawn: the Gaussian
//! channels of the thesis and the channels of a measured multi-channel LED luminaire.

use crate::error::{Error, Result};
use crate::spectral::{normalise_peak, Grid};
use rand::rngs::SmallRng;
use rand::seq::index;
use rand::Rng;

/// Named channel SPDs on one grid; a light is their weighted sum, normalised by its maximum.
#[derive(Debug, Clone, PartialEq)]
pub struct Channels {
    /// Each channel's name (its CSV column).
    pub names: Vec<String>,
    /// One SPD per channel, on the grid the lighting was built for.
    pub spds: Vec<Vec<f64>>,
}

impl Channels {
    /// The thesis's Gaussian channels for N = 4…7 (THESIS-PARAMETERS: centre, width in nm);
    /// other N spread evenly over 400–700 nm, centres at the middles of N equal bands and
    /// the full width at half maximum equal to the band width. Each channel peaks at 1 and
    /// is sampled at the grid's wavelengths, as the thesis did.
    pub fn gaussian(n: usize, grid: &Grid) -> Result<Channels> {
        if !(1..=64).contains(&n) {
            return Err(Error::invalid(format!(
                "gaussian:{n}: the number of channels must be 1 to 64"
            )));
        }
        let thesis: &[(f64, f64)] = match n {
            4 => &[(430.0, 15.0), (510.0, 20.0), (590.0, 20.0), (670.0, 15.0)],
            5 => &[
                (430.0, 15.0),
                (490.0, 20.0),
                (550.0, 20.0),
                (610.0, 20.0),
                (670.0, 15.0),
            ],
            6 => &[
                (420.0, 15.0),
                (470.0, 20.0),
                (520.0, 20.0),
                (570.0, 20.0),
                (620.0, 20.0),
                (670.0, 15.0),
            ],
            7 => &[
                (430.0, 15.0),
                (470.0, 20.0),
                (510.0, 20.0),
                (550.0, 20.0),
                (590.0, 20.0),
                (630.0, 20.0),
                (670.0, 15.0),
            ],
            _ => &[],
        };
        let shapes: Vec<(f64, f64)> = if thesis.is_empty() {
            let band = 300.0 / n as f64;
            let sigma = band / (8.0f64 * 2.0f64.ln()).sqrt();
            (0..n)
                .map(|j| (400.0 + (j as f64 + 0.5) * band, sigma))
                .collect()
        } else {
            thesis.to_vec()
        };
        let wavelengths = grid.wavelengths();
        Ok(Channels {
            names: (1..=n).map(|j| format!("ch{j}")).collect(),
            spds: shapes
                .iter()
                .map(|&(mu, sigma)| {
                    wavelengths
                        .iter()
                        .map(|&l| (-(l - mu).powi(2) / (2.0 * sigma * sigma)).exp())
                        .collect()
                })
                .collect(),
        })
    }

    /// Number of channels.
    pub fn len(&self) -> usize {
        self.spds.len()
    }

    /// Whether there is no channel.
    pub fn is_empty(&self) -> bool {
        self.spds.is_empty()
    }

    /// Σ wᵢ·channelᵢ, normalised by its maximum; an error when the sum is dark.
    pub fn combine(&self, weights: &[f64]) -> Result<Vec<f64>> {
        if weights.len() != self.len() {
            return Err(Error::invalid(format!(
                "{} weights for {} channels",
                weights.len(),
                self.len()
            )));
        }
        let mut spd = vec![0.0; self.spds.first().map_or(0, Vec::len)];
        for (w, channel) in weights.iter().zip(&self.spds) {
            if *w != 0.0 {
                spd.iter_mut().zip(channel).for_each(|(s, c)| *s += w * c);
            }
        }
        normalise_peak(&mut spd)
            .map(|()| spd)
            .map_err(|_| Error::invalid("the weights light no channel: the SPD is dark"))
    }
}

/// How channel weights are drawn: which channels may light, how many of them at once, the
/// range of a weight and its rounding step.
#[derive(Debug, Clone, PartialEq)]
pub struct WeightRule {
    /// Indices (0-based) of the channels that may light; the others stay at 0.
    pub lit: Vec<usize>,
    /// How many of the `lit` channels light in one draw (chosen at random).
    pub k: usize,
    /// Weights are uniform on [0, max), then rounded to `step`.
    pub max: f64,
    /// The rounding step of a weight (0: not rounded).
    pub step: f64,
}

impl WeightRule {
    /// Every one of `n` channels lit, weights uniform on [0, 1) rounded to 0.01 (the thesis).
    pub fn all(n: usize) -> WeightRule {
        WeightRule {
            lit: (0..n).collect(),
            k: n,
            max: 1.0,
            step: 0.01,
        }
    }

    /// Checks the rule against a source of `n` channels.
    pub fn validate(&self, n: usize, spec: &str) -> Result<()> {
        if let Some(&bad) = self.lit.iter().find(|&&i| i >= n) {
            return Err(Error::invalid(format!(
                "'{spec}': channel {} does not exist; the source has {n} channels",
                bad + 1
            )));
        }
        if self.k == 0 || self.k > self.lit.len() {
            return Err(Error::invalid(format!(
                "'{spec}': k = {} channels cannot be chosen from the {} that may light",
                self.k,
                self.lit.len()
            )));
        }
        if !(self.max > 0.0 && self.max <= 1.0) {
            return Err(Error::invalid(format!(
                "'{spec}': max = {} is outside (0, 1]",
                self.max
            )));
        }
        if !(self.step >= 0.0 && self.step < self.max) {
            return Err(Error::invalid(format!(
                "'{spec}': step = {} must be ≥ 0 and below max = {}",
                self.step, self.max
            )));
        }
        Ok(())
    }

    /// Draws the weights of `n` channels: `k` of the lit channels at random, each uniform on
    /// [0, max) rounded to the step (a chosen channel that rounds to 0 is drawn again, so
    /// exactly `k` channels light); every other channel 0.
    pub fn draw(&self, n: usize, rng: &mut SmallRng) -> Vec<f64> {
        let mut weights = vec![0.0; n];
        let chosen = index::sample(rng, self.lit.len(), self.k);
        for position in chosen.iter() {
            weights[self.lit[position]] = loop {
                let w = rng.random::<f64>() * self.max;
                let w = if self.step > 0.0 {
                    ((w / self.step).round() * self.step).min(self.max)
                } else {
                    w
                };
                if w > 0.0 {
                    break w;
                }
            };
        }
        weights
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn thesis_four_channels_with_given_weights() {
        let grid = Grid::SIMULATION;
        let ch = Channels::gaussian(4, &grid).unwrap();
        let spd = ch.combine(&[0.5, 1.0, 0.25, 0.0]).unwrap();
        // At 510 nm the second channel peaks (1.0); the first contributes
        // 0.5·exp(−80²/450), the third 0.25·exp(−80²/800).
        let at = |nm: f64| spd[grid.index_of(nm).unwrap()];
        let peak = 1.0 + 0.5 * (-6400.0f64 / 450.0).exp() + 0.25 * (-6400.0f64 / 800.0).exp();
        assert!((at(510.0) - 1.0).abs() < 1e-12);
        let at_590 = 0.25 + (-6400.0f64 / 800.0).exp() + 0.5 * (-160.0f64.powi(2) / 450.0).exp();
        assert!((at(590.0) - at_590 / peak).abs() < 1e-12, "{}", at(590.0));
        let at_430 = 0.5 + (-6400.0f64 / 800.0).exp() + 0.25 * (-160.0f64.powi(2) / 800.0).exp();
        assert!((at(430.0) - at_430 / peak).abs() < 1e-12);
    }

    #[test]
    fn other_counts_spread_over_the_visible() {
        let grid = Grid::SIMULATION;
        let ch = Channels::gaussian(3, &grid).unwrap();
        let peak_nm = |c: &Vec<f64>| {
            let i = (0..c.len()).max_by(|&a, &b| c[a].total_cmp(&c[b])).unwrap();
            grid.wavelength(i)
        };
        let peaks: Vec<f64> = ch.spds.iter().map(peak_nm).collect();
        assert_eq!(peaks, vec![450.0, 550.0, 650.0]);
        assert!(Channels::gaussian(0, &grid).is_err());
    }

    #[test]
    fn dark_weights_are_refused() {
        let ch = Channels::gaussian(4, &Grid::SIMULATION).unwrap();
        assert!(ch.combine(&[0.0; 4]).is_err());
        assert!(ch.combine(&[1.0; 3]).is_err());
    }

    #[test]
    fn seven_of_seventeen() {
        let rule = WeightRule {
            lit: (2..19).collect(),
            k: 7,
            max: 0.75,
            step: 0.01,
        };
        rule.validate(24, "test").unwrap();
        let mut rng = SmallRng::seed_from_u64(3);
        for _ in 0..500 {
            let w = rule.draw(24, &mut rng);
            assert!(w[..2].iter().chain(&w[19..]).all(|&x| x == 0.0));
            assert_eq!(w.iter().filter(|&&x| x != 0.0).count(), 7);
            assert!(w.iter().all(|&x| (0.0..=0.75).contains(&x)));
            assert!(w
                .iter()
                .all(|&x| ((x * 100.0).round() - x * 100.0).abs() < 1e-9));
        }
    }

    #[test]
    fn bad_rules_are_named() {
        let mut rule = WeightRule::all(5);
        rule.k = 6;
        assert!(rule
            .validate(5, "s")
            .unwrap_err()
            .to_string()
            .contains("k = 6"));
        let mut rule = WeightRule::all(5);
        rule.max = 1.5;
        assert!(rule
            .validate(5, "s")
            .unwrap_err()
            .to_string()
            .contains("max"));
        rule.max = 0.0;
        assert!(rule.validate(5, "s").is_err());
    }
}
