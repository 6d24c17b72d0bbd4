//! Colour fidelity and gamut of CIE 224:2017 and ANSI/IES TM-30-20: Rf, Rg and the 16 hue-bin
//! local fidelity, chroma shift and hue shift.
//!
//! CIE 224:2017, "CIE 2017 colour fidelity index for accurate scientific use", and ANSI/IES
//! TM-30-20, "IES method for evaluating light source color rendition". The 99 colour
//! evaluation samples (`data/tm30_ces99.csv`) are computed under the test light and under the
//! reference illuminant of its CCT ([`ReferenceIlluminants::cie2017`]) with the CIE 1964 10° observer,
//! each light normalised to Y = 100; CIECAM02 in the CIE 224 viewing conditions gives
//! CAM02-UCS coordinates ([`Cam02Viewing`]); ΔE_i is their Euclidean distance and
//! Rf = 10 ln(1 + exp((100 − 6.73 ΔĒ)/10)) (CIE 224:2017 Eq. 13). TM-30 groups the samples into
//! 16 bins of 22.5° by their hue under the reference; Rg is the area of the polygon of the
//! test bin averages (a′, b′) over that of the reference (× 100); for each bin j with
//! centre angle θ_j = 22.5° j + 11.25°, the chroma shift is (Δa′ cos θ_j + Δb′ sin θ_j)/|ref|,
//! the hue shift (−Δa′ sin θ_j + Δb′ cos θ_j)/|ref|, and the local fidelity Rf of the bin's
//! mean ΔE (TM-30-20 §4). Computed at 5 nm over 380–780 nm, the CES table's own sampling
//! (CIE 224 allows 5 nm), as colour-science's `colour_fidelity_index_ANSIIESTM3018` does for
//! 5 nm data.

use super::cam02::{Cam02Ucs, Cam02Viewing};
use super::reference::ReferenceIlluminants;
use super::spectrum::{BandWeights, LightSpectrum, QUALITY_GRID};
use crate::builtin;
use crate::colorimetry::Observer;
use crate::error::{Error, Result};
use crate::spectral::Grid;
use serde::{Deserialize, Serialize};
use std::sync::OnceLock;

/// 380–780 nm at 5 nm, the grid of the computation.
pub const TM30_GRID: Grid = Grid::SIMULATION;
/// Number of colour evaluation samples.
pub const CES_COUNT: usize = 99;
/// Number of hue bins.
pub const HUE_BINS: usize = 16;
/// The scale factor c_f of CIE 224:2017 Eq. 13.
const CF: f64 = 6.73;

/// One of TM-30's 16 hue bins.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct HueBin {
    /// Local colour fidelity R_f,hj.
    pub rf: f64,
    /// Local chroma shift R_cs,hj as a fraction (−0.1 = 10 % less chroma).
    pub chroma_shift: f64,
    /// Local hue shift R_hs,hj (radians, relative to the bin's mean reference chroma).
    pub hue_shift: f64,
    /// Mean (a′, b′) of the bin's samples under the test light.
    pub test_ab: [f64; 2],
    /// Mean (a′, b′) of the bin's samples under the reference illuminant.
    pub reference_ab: [f64; 2],
}

/// CIE 224:2017 / ANSI/IES TM-30-20 colour fidelity and gamut of a light.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ColourFidelity {
    /// Fidelity index Rf.
    pub rf: f64,
    /// Gamut index Rg.
    pub rg: f64,
    /// Per-sample fidelity R_f,CESi, ces01 first.
    pub rf_ces: Vec<f64>,
    /// The 16 hue bins, bin 1 (0–22.5°) first.
    pub bins: Vec<HueBin>,
}

/// What the computation needs on [`TM30_GRID`], built once.
struct Tables {
    /// CES × 10° CMF, function `3·sample + channel`.
    weights: BandWeights,
    cmf10: Observer,
    references: ReferenceIlluminants,
}

fn tables() -> &'static Tables {
    static T: OnceLock<Tables> = OnceLock::new();
    T.get_or_init(|| {
        let ces = builtin::TM30_CES99
            .load()
            .expect("the shipped CES table parses");
        ces.require_grid(&TM30_GRID, "the CES table")
            .expect("the shipped CES table is 380–780 nm at 5 nm");
        let cmf10 = Observer::cie1964_10deg(&TM30_GRID).expect("CIE 1964 observer");
        let references = ReferenceIlluminants::on_grid(&TM30_GRID).expect("references");
        let functions: Vec<Vec<f64>> = ces
            .items()
            .iter()
            .flat_map(|r| {
                let cmf10 = &cmf10;
                (0..3).map(move |c| r.iter().zip(cmf10.cmf(c)).map(|(r, c)| r * c).collect())
            })
            .collect();
        let weights = BandWeights::new(&functions);
        Tables {
            weights,
            cmf10,
            references,
        }
    })
}

/// CAM02-UCS coordinates of the 99 samples under a light sampled on [`TM30_GRID`].
fn sample_appearance(spd: &[f64]) -> Vec<Cam02Ucs> {
    let t = tables();
    let white = t.cmf10.spd_to_xyz(spd);
    let k = 100.0 / white[1];
    let view = Cam02Viewing::cie2017(white.map(|v| k * v));
    // The samples' sums lack the Δλ that spd_to_xyz includes.
    let k = k * TM30_GRID.step_nm;
    let mut sums = vec![0.0; 3 * CES_COUNT];
    t.weights.apply(spd, &mut sums);
    sums.chunks_exact(3)
        .map(|xyz| view.ucs([k * xyz[0], k * xyz[1], k * xyz[2]]))
        .collect()
}

/// Rf of a mean colour difference (CIE 224:2017 Eq. 13).
fn fidelity(delta_e: f64) -> f64 {
    10.0 * ((100.0 - CF * delta_e) / 10.0).exp().ln_1p()
}

/// Area of the polygon through `points` in order (shoelace formula).
fn polygon_area(points: &[[f64; 2]]) -> f64 {
    let n = points.len();
    (0..n)
        .map(|i| {
            let (u, v) = (points[i], points[(i + 1) % n]);
            u[0] * v[1] - u[1] * v[0]
        })
        .sum::<f64>()
        / 2.0
}

/// CIE 224:2017 / ANSI/IES TM-30-20 colour fidelity and gamut of `light` at correlated colour
/// temperature `cct` (kelvin). The light is taken at the 5 nm samples of 380–780 nm. Errors
/// where the reference illuminant is not defined (above 25,000 K) and when a hue bin holds no
/// sample under the reference (then the gamut polygon is not defined).
pub fn colour_fidelity_cie2017(light: &LightSpectrum, cct: f64) -> Result<ColourFidelity> {
    let t = tables();
    let offset = QUALITY_GRID
        .index_of(TM30_GRID.start_nm)
        .expect("the TM-30 grid starts on the quality grid");
    let stride = (TM30_GRID.step_nm / QUALITY_GRID.step_nm).round() as usize;
    let test_spd: Vec<f64> = (0..TM30_GRID.count)
        .map(|i| light.values()[offset + i * stride])
        .collect();
    let reference = t.references.cie2017(cct)?;
    let test = sample_appearance(&test_spd);
    let refr = sample_appearance(&reference);

    let delta_e: Vec<f64> = test
        .iter()
        .zip(&refr)
        .map(|(a, b)| ((a.j - b.j).powi(2) + (a.a - b.a).powi(2) + (a.b - b.b).powi(2)).sqrt())
        .collect();
    let mean_de = delta_e.iter().sum::<f64>() / CES_COUNT as f64;

    let mut count = [0usize; HUE_BINS];
    let mut sum_t = [[0.0; 2]; HUE_BINS];
    let mut sum_r = [[0.0; 2]; HUE_BINS];
    let mut sum_de = [0.0; HUE_BINS];
    for ((a, b), de) in test.iter().zip(&refr).zip(&delta_e) {
        let j = ((b.hue_degrees() / 22.5).floor() as usize).min(HUE_BINS - 1);
        count[j] += 1;
        sum_t[j] = [sum_t[j][0] + a.a, sum_t[j][1] + a.b];
        sum_r[j] = [sum_r[j][0] + b.a, sum_r[j][1] + b.b];
        sum_de[j] += de;
    }
    if let Some(j) = count.iter().position(|&c| c == 0) {
        return Err(Error::invalid(format!(
            "TM-30 hue bin {} holds no colour sample under the {cct:.0} K reference",
            j + 1
        )));
    }
    let mean = |s: [f64; 2], n: usize| [s[0] / n as f64, s[1] / n as f64];
    let test_avg: Vec<[f64; 2]> = (0..HUE_BINS).map(|j| mean(sum_t[j], count[j])).collect();
    let ref_avg: Vec<[f64; 2]> = (0..HUE_BINS).map(|j| mean(sum_r[j], count[j])).collect();
    let bins = (0..HUE_BINS)
        .map(|j| {
            let theta = (22.5 * j as f64 + 11.25).to_radians();
            let (sin, cos) = theta.sin_cos();
            let norm = ref_avg[j][0].hypot(ref_avg[j][1]);
            let da = test_avg[j][0] - ref_avg[j][0];
            let db = test_avg[j][1] - ref_avg[j][1];
            HueBin {
                rf: fidelity(sum_de[j] / count[j] as f64),
                chroma_shift: (da * cos + db * sin) / norm,
                hue_shift: (-da * sin + db * cos) / norm,
                test_ab: test_avg[j],
                reference_ab: ref_avg[j],
            }
        })
        .collect();
    Ok(ColourFidelity {
        rf: fidelity(mean_de),
        rg: 100.0 * polygon_area(&test_avg) / polygon_area(&ref_avg),
        rf_ces: delta_e.iter().map(|&de| fidelity(de)).collect(),
        bins,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fidelity_formula_and_polygon_area() {
        // ΔE = 0 gives Rf = 10 ln(1 + e^10) ≈ 100.0005 (CIE 224:2017 Eq. 13).
        assert!((fidelity(0.0) - 10.0 * (1.0 + 10f64.exp()).ln()).abs() < 1e-12);
        assert!((fidelity(100.0 / CF) - 10.0 * 2f64.ln()).abs() < 1e-12);
        let square = [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]];
        assert!((polygon_area(&square) - 4.0).abs() < 1e-15);
    }

    #[test]
    fn a_reference_illuminant_has_full_fidelity_and_gamut() {
        let spd = crate::cie_illuminant::planck(3000.0, &QUALITY_GRID).unwrap();
        let light = LightSpectrum::on_grid(&QUALITY_GRID, &spd).unwrap();
        let f = colour_fidelity_cie2017(&light, 3000.0).unwrap();
        assert!((f.rf - fidelity(0.0)).abs() < 1e-9, "{}", f.rf);
        assert!((f.rg - 100.0).abs() < 1e-9, "{}", f.rg);
        assert_eq!(f.bins.len(), HUE_BINS);
        assert_eq!(f.rf_ces.len(), CES_COUNT);
        for b in &f.bins {
            assert!(b.chroma_shift.abs() < 1e-12 && b.hue_shift.abs() < 1e-12);
        }
    }
}
