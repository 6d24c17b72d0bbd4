//! Sensor noise (thesis 3.1.2, Eq. 3.4): Poisson shot noise on the collected electrons,
//! Gaussian read noise, black level, clipping and quantisation at a bit depth.
//!
//! The normalised raw signal (0–1 of full scale) becomes `signal · (full − black)` ADU above
//! the black level; electrons are ADU divided by the conversion gain. Photon arrival is
//! Poisson and each photon is converted with probability QE, so the electron count is again
//! Poisson with mean `ADU / gain`: the quantum efficiency cancels out of the statistics, and
//! the photon-transfer curve is `σ²_ADU = gain·μ_ADU + (gain·σ_read)² + 1/12`.

use crate::error::{Error, Result};
use crate::seed;
use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Poisson, StandardNormal};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Noise parameters of a sensor.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct NoiseParams {
    /// Conversion gain in ADU per electron.
    pub gain_adu_per_e: f64,
    /// Read noise, standard deviation in electrons.
    pub read_noise_e: f64,
    /// Black level (offset) in ADU.
    pub black_level_adu: f64,
    /// Bits of the analogue-to-digital converter (8–16).
    pub bit_depth: u32,
}

/// Mean electron count above which shot noise is drawn from its normal approximation
/// (relative error of the variance far below the 5 % a photon-transfer check resolves).
const NORMAL_APPROXIMATION_E: f32 = 64.0;
/// Rows of the mosaic that share one random stream: the unit of parallel work.
const ROWS_PER_STREAM: usize = 16;

impl NoiseParams {
    /// The thesis's sensor (THESIS-PARAMETERS.md): 7.1 ADU/e⁻, 3.0 e⁻ read noise, black
    /// level 100 ADU, 16 bits.
    pub const THESIS: NoiseParams = NoiseParams {
        gain_adu_per_e: 7.1,
        read_noise_e: 3.0,
        black_level_adu: 100.0,
        bit_depth: 16,
    };
    /// A small-pixel phone sensor: about 4,000 e⁻ full well on 10 bits, 2.2 e⁻ read noise,
    /// black level 64 ADU.
    pub const PHONE: NoiseParams = NoiseParams {
        gain_adu_per_e: 0.24,
        read_noise_e: 2.2,
        black_level_adu: 64.0,
        bit_depth: 10,
    };

    /// The named presets.
    pub const PRESETS: [(&'static str, NoiseParams); 2] = [
        ("thesis", NoiseParams::THESIS),
        ("phone", NoiseParams::PHONE),
    ];

    /// Looks a preset up by name.
    pub fn preset(name: &str) -> Result<NoiseParams> {
        NoiseParams::PRESETS
            .iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(name))
            .map(|(_, p)| *p)
            .ok_or_else(|| crate::Error::UnknownName {
                kind: "noise preset",
                name: name.to_string(),
                valid: "thesis, phone, off".into(),
            })
    }

    /// Checks the parameters.
    pub fn validate(&self) -> Result<()> {
        if !(8..=16).contains(&self.bit_depth) {
            return Err(Error::invalid(format!(
                "bit depth {} is outside 8–16",
                self.bit_depth
            )));
        }
        let positive = |v: f64| v.is_finite() && v > 0.0;
        if !positive(self.gain_adu_per_e) || self.read_noise_e.is_nan() || self.read_noise_e < 0.0 {
            return Err(Error::invalid("noise gain must be > 0 and read noise >= 0"));
        }
        if self.black_level_adu.is_nan()
            || self.black_level_adu < 0.0
            || self.black_level_adu >= self.full_scale_adu() / 2.0
        {
            return Err(Error::invalid(format!(
                "black level {} ADU does not fit {} bits",
                self.black_level_adu, self.bit_depth
            )));
        }
        Ok(())
    }

    /// The largest ADU value.
    pub fn full_scale_adu(&self) -> f64 {
        ((1u64 << self.bit_depth) - 1) as f64
    }

    /// ADU above black that a normalised signal of 1.0 gives.
    pub fn signal_range_adu(&self) -> f64 {
        self.full_scale_adu() - self.black_level_adu
    }
}

/// Adds noise to a normalised raw plane (row-major, `width` wide) in place and returns it normalised again
/// (`(ADU − black) / (full − black)`, so values may fall slightly below zero, as raw data do).
/// Deterministic for a given `seed`, whatever the number of threads.
pub fn add_noise(data: &mut [f32], width: usize, params: &NoiseParams, seed: u64) {
    let w = width.max(1);
    let range = params.signal_range_adu() as f32;
    let gain = params.gain_adu_per_e as f32;
    let read = params.read_noise_e as f32;
    let black = params.black_level_adu as f32;
    let full = params.full_scale_adu() as f32;
    let process = |(band, rows): (usize, &mut [f32])| {
        let mut rng = SmallRng::seed_from_u64(seed::derive(seed, band as u64));
        for v in rows.iter_mut() {
            let mean_e = (*v * range / gain).max(0.0);
            let electrons = if mean_e > NORMAL_APPROXIMATION_E {
                let z: f32 = rng.sample(StandardNormal);
                mean_e + z * (mean_e + read * read).sqrt()
            } else {
                let shot = if mean_e > 0.0 {
                    Poisson::new(mean_e)
                        .map(|p| p.sample(&mut rng))
                        .unwrap_or(mean_e)
                } else {
                    0.0
                };
                let z: f32 = rng.sample(StandardNormal);
                shot + z * read
            };
            // Round half up by truncation (no libm call), then clip to the ADC's range.
            let adu = ((black + electrons * gain + 0.5).max(0.0) as u32 as f32).min(full);
            *v = (adu - black) / range;
        }
    };
    let chunk = ROWS_PER_STREAM * w;
    if data.len() > 200_000 {
        data.par_chunks_mut(chunk).enumerate().for_each(process);
    } else {
        data.chunks_mut(chunk).enumerate().for_each(process);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::{CfaPattern, Mosaic};

    fn flat_patch_stats(level: f32, params: &NoiseParams) -> (f64, f64) {
        let mut m = Mosaic::new(256, 256, CfaPattern::Rggb);
        m.data.fill(level);
        add_noise(&mut m.data, m.width, params, 7);
        let range = params.signal_range_adu();
        let adu: Vec<f64> = m.data.iter().map(|&v| v as f64 * range).collect();
        let mean = adu.iter().sum::<f64>() / adu.len() as f64;
        let var = adu.iter().map(|a| (a - mean).powi(2)).sum::<f64>() / (adu.len() - 1) as f64;
        (mean, var)
    }

    #[test]
    fn flat_patch_variance_follows_photon_transfer() {
        for params in [NoiseParams::THESIS, NoiseParams::PHONE] {
            for level in [0.01f32, 0.1, 0.5, 0.9] {
                let (mean, var) = flat_patch_stats(level, &params);
                let g = params.gain_adu_per_e;
                let expected = g * mean + (g * params.read_noise_e).powi(2) + 1.0 / 12.0;
                let rel = (var / expected - 1.0).abs();
                println!("level {level}: mean {mean:.1} ADU, var {var:.2} vs PTC {expected:.2} ({:.1} %)", rel * 100.0);
                assert!(
                    rel < 0.05,
                    "{params:?} level {level}: var {var} vs {expected}"
                );
                assert!((mean / (level as f64 * params.signal_range_adu()) - 1.0).abs() < 0.01);
            }
        }
    }

    #[test]
    fn low_light_uses_exact_poisson() {
        let params = NoiseParams {
            read_noise_e: 0.0,
            ..NoiseParams::THESIS
        };
        let level = (5.0 * params.gain_adu_per_e / params.signal_range_adu()) as f32;
        let (mean, var) = flat_patch_stats(level, &params);
        let g = params.gain_adu_per_e;
        let expected = g * mean + 1.0 / 12.0;
        assert!((var / expected - 1.0).abs() < 0.05, "{var} vs {expected}");
    }

    #[test]
    fn same_seed_same_noise_and_clipping() {
        let mut a = Mosaic::new(64, 64, CfaPattern::Rggb);
        a.data.fill(0.5);
        let mut b = a.clone();
        add_noise(&mut a.data, 64, &NoiseParams::THESIS, 3);
        add_noise(&mut b.data, 64, &NoiseParams::THESIS, 3);
        assert_eq!(a, b);
        let mut c = Mosaic::new(64, 64, CfaPattern::Rggb);
        c.data.fill(2.0);
        add_noise(&mut c.data, 64, &NoiseParams::PHONE, 1);
        let top = ((NoiseParams::PHONE.full_scale_adu() - 64.0)
            / NoiseParams::PHONE.signal_range_adu()) as f32;
        assert!(c.data.iter().all(|&v| v <= top + 1e-6));
    }

    #[test]
    fn invalid_parameters_are_named() {
        let p = NoiseParams {
            bit_depth: 20,
            ..NoiseParams::THESIS
        };
        assert!(p.validate().unwrap_err().to_string().contains("20"));
        assert!(NoiseParams::preset("nope").is_err());
    }
}
