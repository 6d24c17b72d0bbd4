//! The CIE 1931 2° standard observer on a working grid, and spectrum → XYZ integration.

use crate::colorimetry::xyz_to_xy;
use crate::error::Result;
use crate::spectral::{Extrapolation, Grid, Interpolation, SpectralSet};
use std::sync::OnceLock;

/// The shipped CIE 1931 2° CMF table (colour-science 0.4.7, CIE tabulation, 360–830 nm, 1 nm).
const CIE1931_CSV: &str = include_str!("../../../../data/cie_1931_2deg_cmf.csv");

/// The native 1 nm CMF table, parsed once; items are x̄, ȳ, z̄ in that order.
pub(super) fn cie1931_native() -> &'static SpectralSet {
    static TABLE: OnceLock<SpectralSet> = OnceLock::new();
    TABLE.get_or_init(|| {
        let set = SpectralSet::from_csv_str(CIE1931_CSV, "built-in cie_1931_2deg_cmf.csv")
            .expect("the shipped CIE 1931 CMF table parses");
        assert_eq!(
            set.names(),
            ["x_bar", "y_bar", "z_bar"],
            "the shipped CIE 1931 CMF table has columns x_bar, y_bar, z_bar"
        );
        set
    })
}

/// The CIE 1931 2° standard colour-matching functions x̄, ȳ, z̄ sampled on a working grid.
///
/// Source: CIE 015:2018 (CIE 1931 standard colorimetric observer), the 1 nm table of
/// 360–830 nm shipped as `data/cie_1931_2deg_cmf.csv` (exported from colour-science 0.4.7).
/// Integration is a plain sum over the grid samples times the step (the CIE 015 practice of
/// summation at the tabulation interval); no band-pass correction is applied.
#[derive(Debug, Clone, PartialEq)]
pub struct Observer {
    grid: Grid,
    cmf: [Vec<f64>; 3],
}

impl Observer {
    /// The CIE 1931 2° observer on `grid`. The 1 nm table is resampled with Sprague (1880)
    /// interpolation (CIE 167:2005; exact at the tabulated wavelengths, so any grid on whole
    /// nanometres just picks table values), and is zero outside 360–830 nm.
    pub fn cie1931(grid: &Grid) -> Result<Observer> {
        let (set, _) =
            cie1931_native().resample(grid, Interpolation::Sprague1880, Extrapolation::Zero)?;
        Ok(Observer {
            grid: *grid,
            cmf: [0, 1, 2].map(|i| set.item(i).to_vec()),
        })
    }

    /// The CIE 1964 10° supplementary standard observer on `grid` (CIE 015:2018; the 1 nm table
    /// of 360–830 nm shipped as `data/cie_1964_10deg_cmf.csv`), resampled as
    /// [`Observer::cie1931`] does. CIE 224:2017 and ANSI/IES TM-30 compute colour fidelity with it.
    pub fn cie1964_10deg(grid: &Grid) -> Result<Observer> {
        static TABLE: OnceLock<SpectralSet> = OnceLock::new();
        let native = TABLE.get_or_init(|| {
            crate::builtin::CIE1964_10DEG_CMF
                .load()
                .expect("the shipped CIE 1964 CMF table parses")
        });
        let (set, _) = native.resample(grid, Interpolation::Sprague1880, Extrapolation::Zero)?;
        Ok(Observer {
            grid: *grid,
            cmf: [0, 1, 2].map(|i| set.item(i).to_vec()),
        })
    }

    /// The grid the CMFs are sampled on.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// One colour-matching function on the grid: 0 = x̄, 1 = ȳ, 2 = z̄.
    ///
    /// # Panics
    /// If `channel > 2`.
    pub fn cmf(&self, channel: usize) -> &[f64] {
        &self.cmf[channel]
    }

    /// Absolute tristimulus values of a spectrum: X = Σ S(λ)·x̄(λ)·Δλ and likewise Y, Z
    /// (CIE 015:2018, summation at the grid step Δλ). For a radiance in W·sr⁻¹·m⁻²·nm⁻¹ the
    /// result is in W·sr⁻¹·m⁻² per unit of the CMFs; the caller normalises (e.g. by K_m or
    /// to Y = 1).
    ///
    /// # Panics
    /// If `spd` does not have one value per grid sample.
    pub fn spd_to_xyz(&self, spd: &[f64]) -> [f64; 3] {
        self.check_len(spd, "spectrum");
        self.cmf
            .each_ref()
            .map(|c| c.iter().zip(spd).map(|(c, s)| c * s).sum::<f64>() * self.grid.step_nm)
    }

    /// The xy chromaticity of a spectrum (CIE 015:2018); see [`Observer::spd_to_xyz`].
    pub fn spd_to_xy(&self, spd: &[f64]) -> [f64; 2] {
        xyz_to_xy(self.spd_to_xyz(spd))
    }

    /// Relative tristimulus values of a reflectance (or transmittance) `refl` lit by
    /// `illuminant`, normalised so a perfect reflector has Y = 1: X = k·Σ R·S·x̄ with
    /// k = 1/Σ S·ȳ (CIE 015:2018 relative colorimetry, with k for Y = 1 instead of 100).
    /// An illuminant with Σ S·ȳ = 0 gives NaN.
    ///
    /// # Panics
    /// If `refl` or `illuminant` does not have one value per grid sample.
    pub fn reflectance_to_xyz(&self, refl: &[f64], illuminant: &[f64]) -> [f64; 3] {
        self.check_len(refl, "reflectance");
        self.check_len(illuminant, "illuminant");
        let k = 1.0 / dot(&self.cmf[1], illuminant);
        self.cmf.each_ref().map(|c| {
            k * c
                .iter()
                .zip(refl)
                .zip(illuminant)
                .map(|((c, r), s)| c * r * s)
                .sum::<f64>()
        })
    }

    /// The white point of an illuminant, XYZ with Y = 1 (the perfect reflector under it), the
    /// white of CIELAB and of white balance.
    pub fn white_xyz(&self, illuminant: &[f64]) -> [f64; 3] {
        self.check_len(illuminant, "illuminant");
        let k = 1.0 / dot(&self.cmf[1], illuminant);
        self.cmf.each_ref().map(|c| k * dot(c, illuminant))
    }

    fn check_len(&self, values: &[f64], what: &str) {
        assert_eq!(
            values.len(),
            self.grid.count,
            "{what} has {} values but the observer's grid {} has {}",
            values.len(),
            self.grid,
            self.grid.count
        );
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn native_table_is_360_to_830_at_1nm() {
        let t = cie1931_native();
        assert_eq!(t.grid(), Some(Grid::new(360.0, 830.0, 1.0).unwrap()));
        // CIE 1931 ȳ peaks at 555 nm with value 1.
        let y = t.item(1);
        assert_eq!(y[555 - 360], 1.0);
    }

    #[test]
    fn observer_on_5nm_grid_picks_table_values() {
        let obs = Observer::cie1931(&Grid::SIMULATION).unwrap();
        let native = cie1931_native();
        for (i, w) in Grid::SIMULATION.wavelengths().iter().enumerate() {
            let j = (*w - 360.0) as usize;
            for c in 0..3 {
                assert!((obs.cmf(c)[i] - native.item(c)[j]).abs() < 1e-15, "{w} nm");
            }
        }
        assert_eq!(obs.grid(), &Grid::SIMULATION);
    }

    #[test]
    fn equal_energy_spectrum_is_near_e_white() {
        // The 1931 CMFs have (nearly) equal integrals, so an equal-energy spectrum sits at
        // x = y ≈ 1/3.
        let grid = Grid::new(360.0, 830.0, 1.0).unwrap();
        let obs = Observer::cie1931(&grid).unwrap();
        let xy = obs.spd_to_xy(&vec![1.0; grid.count]);
        assert!(
            (xy[0] - 1.0 / 3.0).abs() < 1e-4 && (xy[1] - 1.0 / 3.0).abs() < 1e-4,
            "{xy:?}"
        );
        // Σ ȳ·Δλ of the 1931 observer is 106.857 (1 nm sum over 360–830 nm).
        let xyz = obs.spd_to_xyz(&vec![1.0; grid.count]);
        assert!((xyz[1] - 106.857).abs() < 1e-3, "{xyz:?}");
    }

    #[test]
    fn perfect_reflector_has_y_one_and_equals_white() {
        let obs = Observer::cie1931(&Grid::SIMULATION).unwrap();
        let illum: Vec<f64> = (0..81).map(|i| 50.0 + i as f64).collect();
        let white = obs.white_xyz(&illum);
        let refl = obs.reflectance_to_xyz(&vec![1.0; 81], &illum);
        assert!((white[1] - 1.0).abs() < 1e-15);
        for (a, b) in white.iter().zip(refl) {
            assert!((a - b).abs() < 1e-15);
        }
        let grey = obs.reflectance_to_xyz(&vec![0.18; 81], &illum);
        assert!((grey[1] - 0.18).abs() < 1e-15);
    }

    #[test]
    fn ten_degree_observer_is_the_cie_1964_table() {
        // CIE 015:2018 Table 2: ȳ₁₀(555 nm) = 0.999110, x̄₁₀(600 nm) = 1.123990, and ȳ₁₀
        // peaks at 1 (557 nm).
        let obs = Observer::cie1964_10deg(&Grid::new(360.0, 830.0, 1.0).unwrap()).unwrap();
        assert_eq!(obs.cmf(1)[555 - 360], 0.99911);
        assert_eq!(obs.cmf(0)[600 - 360], 1.12399);
        assert_eq!(obs.cmf(1)[557 - 360], 1.0);
        let peak = obs.cmf(1).iter().cloned().fold(0.0, f64::max);
        assert!((peak - 1.0).abs() < 1e-6, "{peak}");
    }

    #[test]
    #[should_panic(expected = "spectrum has 3 values")]
    fn wrong_length_panics_with_message() {
        Observer::cie1931(&Grid::SIMULATION)
            .unwrap()
            .spd_to_xyz(&[1.0, 2.0, 3.0]);
    }
}
