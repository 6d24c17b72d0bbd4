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
use rand::SeedableRng;
use rand_distr::{Distribution, Poisson};
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

/// Values the noise stage draws and transforms at a time: a multiple of [`LANES`], small
/// enough to stay in registers and L1.
const BLOCK: usize = 64;

/// Adds noise to a normalised raw plane (row-major, `width` wide) in place and returns it normalised again
/// (`(ADU − black) / (full − black)`, so values may fall slightly below zero, as raw data do).
/// Deterministic for a given `seed`, whatever the number of threads.
///
/// Each band of `ROWS_PER_STREAM` rows draws its standard normal deviates from its own
/// `NormalStream`, a block at a time, so the arithmetic runs on vector instructions: every
/// pixel brighter than `NORMAL_APPROXIMATION_E` electrons gets the normal approximation of
/// its shot noise plus read noise in one expression; the few darker ones are redone with
/// exact Poisson shot noise from a second generator of the band.
pub fn add_noise(data: &mut [f32], width: usize, params: &NoiseParams, seed: u64) {
    let adc = Adc {
        range: params.signal_range_adu() as f32,
        gain: params.gain_adu_per_e as f32,
        read: params.read_noise_e as f32,
        black: params.black_level_adu as f32,
        full: params.full_scale_adu() as f32,
    };
    let process = |(band, rows): (usize, &mut [f32])| {
        noise_band_widest(rows, seed::derive(seed, band as u64), &adc)
    };
    let chunk = ROWS_PER_STREAM * width.max(1);
    if data.len() > 200_000 {
        data.par_chunks_mut(chunk).enumerate().for_each(process);
    } else {
        data.chunks_mut(chunk).enumerate().for_each(process);
    }
}

/// The noise parameters as the per-pixel arithmetic uses them.
#[derive(Clone, Copy)]
struct Adc {
    /// ADU above black of a normalised 1.0.
    range: f32,
    /// ADU per electron.
    gain: f32,
    /// Read noise in electrons.
    read: f32,
    black: f32,
    full: f32,
}

/// [`noise_band`] compiled for AVX2 where the CPU has it (eight values per instruction
/// instead of four). Both builds do the same IEEE operations, so their results are identical.
fn noise_band_widest(values: &mut [f32], band_seed: u64, adc: &Adc) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        #[target_feature(enable = "avx2")]
        fn avx2(values: &mut [f32], band_seed: u64, adc: &Adc) {
            noise_band(values, band_seed, adc)
        }
        // SAFETY: the CPU supports AVX2, as checked just above.
        return unsafe { avx2(values, band_seed, adc) };
    }
    noise_band(values, band_seed, adc)
}

/// Adds noise to one band of rows with the band's own generators.
#[inline(always)]
fn noise_band(values: &mut [f32], band_seed: u64, adc: &Adc) {
    let Adc {
        range,
        gain,
        read,
        black,
        full,
    } = *adc;
    let electrons_per_unit = range / gain;
    let mut normals = NormalStream::new(band_seed);
    let mut poisson_rng = SmallRng::seed_from_u64(seed::derive(band_seed, 1));
    let mut mean = [0.0f32; BLOCK];
    let mut z = [0.0f32; BLOCK];
    let mut electrons = [0.0f32; BLOCK];
    for values in values.chunks_mut(BLOCK) {
        let n = values.len();
        normals.fill(&mut z);
        for ((m, e), (&v, &z)) in mean
            .iter_mut()
            .zip(&mut electrons)
            .zip(values.iter().zip(&z))
        {
            *m = (v * electrons_per_unit).max(0.0);
            *e = *m + z * (*m + read * read).sqrt();
        }
        for i in 0..n {
            if mean[i] <= NORMAL_APPROXIMATION_E {
                let shot = if mean[i] > 0.0 {
                    Poisson::new(mean[i])
                        .map(|p| p.sample(&mut poisson_rng))
                        .unwrap_or(mean[i])
                } else {
                    0.0
                };
                electrons[i] = shot + z[i] * read;
            }
        }
        for (v, &e) in values.iter_mut().zip(&electrons) {
            // Round half up by truncation (no libm call), then clip to the ADC's range; the
            // value is at least 0, and one too large for i32 saturates and is clipped.
            let adu = ((black + e * gain + 0.5).max(0.0) as i32 as f32).min(full);
            *v = (adu - black) / range;
        }
    }
}

/// Generators stepped side by side in [`NormalStream`].
const LANES: usize = 8;

/// Standard normal deviates, [`LANES`] at a time, in plain arithmetic the compiler
/// vectorises: uniforms from [`LANES`] xoshiro128+ generators (Blackman & Vigna 2021,
/// "Scrambled linear pseudorandom number generators", ACM TOMS 47(4), the variant they
/// recommend for floating-point output), each turned into a deviate by the inverse normal
/// distribution function Φ⁻¹(u) = √2·erfinv(2u − 1), with M. Giles's single-precision
/// erfinv (2012, "Approximating the erfinv function", GPU Computing Gems Jade, 109–116) and
/// Cephes's `logf` polynomial (S. Moshier 1984). Within 1e-6 of Φ⁻¹ for every uniform the
/// generator gives (u = (k + ½)/2²³, |z| ≤ 5.3).
struct NormalStream {
    state: [[u32; LANES]; 4],
}

impl NormalStream {
    /// A stream seeded from `seed` through SplitMix64, as the xoshiro authors advise.
    #[inline(always)]
    fn new(seed: u64) -> NormalStream {
        let mut words = (1..).map(|k| crate::seed::derive(seed, k));
        let mut state = [[0u32; LANES]; 4];
        #[allow(clippy::needless_range_loop)] // one lane's four words per step
        for lane in 0..LANES {
            let (a, b) = (words.next().unwrap_or(1), words.next().unwrap_or(2));
            state[0][lane] = a as u32;
            state[1][lane] = (a >> 32) as u32;
            state[2][lane] = b as u32;
            // An all-zero state would stay zero.
            state[3][lane] = (b >> 32) as u32 | 1;
        }
        NormalStream { state }
    }

    /// Fills `out` (a multiple of [`LANES`] long) with standard normal deviates.
    #[inline(always)]
    fn fill(&mut self, out: &mut [f32; BLOCK]) {
        for block in out.chunks_exact_mut(LANES) {
            let [s0, s1, s2, s3] = &mut self.state;
            let mut u = [0.0f32; LANES];
            for l in 0..LANES {
                let result = s0[l].wrapping_add(s3[l]);
                let t = s1[l] << 9;
                s2[l] ^= s0[l];
                s3[l] ^= s1[l];
                s1[l] ^= s2[l];
                s0[l] ^= s3[l];
                s2[l] ^= t;
                s3[l] = s3[l].rotate_left(11);
                // The top 23 bits, centred in their interval: u in (0, 1), never 0 or 1.
                u[l] = ((result >> 9) as i32 as f32 + 0.5) * (1.0 / 8_388_608.0);
            }
            for (z, u) in block.iter_mut().zip(u) {
                *z = inverse_normal_cdf(u);
            }
        }
    }
}

/// Φ⁻¹(u) for u in (0, 1): √2·erfinv(2u − 1) by Giles's single-precision approximation,
/// with his w = −ln(1 − x²) taken as −ln(4u(1 − u)) (no cancellation near u = 0 or 1).
/// Both branches are evaluated and one selected, so the function vectorises.
#[inline(always)]
#[allow(clippy::excessive_precision)] // the published coefficients, as printed
fn inverse_normal_cdf(u: f32) -> f32 {
    let w = -ln(4.0 * u * (1.0 - u));
    let x = 2.0 * u - 1.0;
    let a = w - 2.5;
    let mut p = 2.810_226_4e-8_f32;
    for c in [
        3.432_739_4e-7,
        -3.523_387_7e-6,
        -4.391_506_5e-6,
        2.185_808_7e-4,
        -1.253_725e-3,
        -4.177_681_6e-3,
        0.246_640_73,
        1.501_409_4,
    ] {
        p = c + p * a;
    }
    let b = w.sqrt() - 3.0;
    let mut q = -2.002_142_6e-4_f32;
    for c in [
        1.009_505_6e-4,
        1.349_343_2e-3,
        -3.673_428_4e-3,
        5.739_507_7e-3,
        -7.622_461_3e-3,
        9.438_870_5e-3,
        1.001_674_1,
        2.832_976_8,
    ] {
        q = c + q * b;
    }
    let erfinv = if w < 5.0 { p } else { q } * x;
    std::f32::consts::SQRT_2 * erfinv
}

/// Natural logarithm of a positive normal `x`, by Cephes's `logf` (S. Moshier 1984):
/// x = m·2ᵉ with m in [√½, √2), ln(m) by a degree-9 polynomial in m − 1; within 5e-7.
#[inline(always)]
#[allow(clippy::excessive_precision)] // the published coefficients, as printed
fn ln(x: f32) -> f32 {
    let bits = x.to_bits();
    let mut e = ((bits >> 23) & 0xff) as i32 - 127;
    let mut m = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000);
    let big = m > std::f32::consts::SQRT_2;
    m = if big { m * 0.5 } else { m };
    e += i32::from(big);
    let f = m - 1.0;
    let z = f * f;
    let mut y = 7.037_683_6e-2_f32;
    for c in [
        -1.151_461e-1,
        1.167_699_9e-1,
        -1.242_014_1e-1,
        1.424_932_3e-1,
        -1.666_805_8e-1,
        2.000_071_4e-1,
        -2.499_999_4e-1,
        3.333_333_1e-1,
    ] {
        y = y * f + c;
    }
    let e = e as f32;
    let y = y * f * z - 2.121_944_4e-4 * e - 0.5 * z;
    f + y + 0.693_359_375 * e
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
    fn inverse_normal_cdf_matches_published_quantiles() {
        // Φ⁻¹ at uniforms exact in f32: scipy.special.ndtri; 0.75 → 0.6744897502 (the
        // quartile, Abramowitz & Stegun Table 26.5).
        for (u, z) in [
            (0.5, 0.0),
            (0.75, 0.674_489_750_196_081_7),
            (0.9375, 1.534_120_544_352_546_3),
            (0.000_976_562_5, -3.097_269_078_198_784_6),
            (9.536_743_164_062_5e-7, -4.763_001_034_267_814),
            (0.999_999_046_325_683_6, 4.763_001_034_267_814),
            (0.999_999_880_790_710_4, 5.166_578_119_728_753_5),
        ] {
            let got = f64::from(inverse_normal_cdf(u as f32));
            assert!((got - z).abs() < 2e-6, "Φ⁻¹({u}) = {got}, expected {z}");
        }
        for k in 1..1000 {
            let x = k as f32 / 1000.0 * 30.0;
            assert!((ln(x) as f64 - (x as f64).ln()).abs() < 5e-7, "ln {x}");
        }
    }

    #[test]
    fn normal_stream_has_the_moments_and_tails_of_a_standard_normal() {
        let mut stream = NormalStream::new(9);
        let mut block = [0.0f32; BLOCK];
        let (mut n, mut sum, mut sq, mut fourth, mut beyond_2, mut beyond_3) =
            (0.0f64, 0.0, 0.0, 0.0, 0.0, 0.0);
        for _ in 0..40_000 {
            stream.fill(&mut block);
            for &z in &block {
                let z = z as f64;
                n += 1.0;
                sum += z;
                sq += z * z;
                fourth += z.powi(4);
                beyond_2 += f64::from(u8::from(z.abs() > 2.0));
                beyond_3 += f64::from(u8::from(z.abs() > 3.0));
            }
        }
        // 2.56 million deviates: standard errors 6e-4 (mean), 9e-4 (variance), 5e-3 (kurtosis).
        assert!((sum / n).abs() < 3e-3, "mean {}", sum / n);
        assert!((sq / n - 1.0).abs() < 5e-3, "variance {}", sq / n);
        assert!(
            (fourth / n - 3.0).abs() < 3e-2,
            "fourth moment {}",
            fourth / n
        );
        // P(|Z| > 2) = 0.045500, P(|Z| > 3) = 0.0026998.
        assert!(
            (beyond_2 / n / 0.045_500 - 1.0).abs() < 0.02,
            "{}",
            beyond_2 / n
        );
        assert!(
            (beyond_3 / n / 0.002_699_8 - 1.0).abs() < 0.05,
            "{}",
            beyond_3 / n
        );
    }

    #[test]
    fn vector_builds_give_the_same_noise() {
        let p = NoiseParams::THESIS;
        let adc = Adc {
            range: p.signal_range_adu() as f32,
            gain: p.gain_adu_per_e as f32,
            read: p.read_noise_e as f32,
            black: p.black_level_adu as f32,
            full: p.full_scale_adu() as f32,
        };
        // Levels from dark (exact Poisson) to clipped, over a band and a partial block.
        let clean: Vec<f32> = (0..5000).map(|i| (i % 250) as f32 / 200.0 - 0.05).collect();
        let (mut a, mut b) = (clean.clone(), clean.clone());
        noise_band(&mut a, 42, &adc);
        noise_band_widest(&mut b, 42, &adc);
        assert_eq!(
            a.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            b.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
        );
        assert_ne!(a, clean);
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
