//! Illuminant spectra: Planckian radiators, the CIE daylight (D-series) model and the tabulated
//! CIE standard illuminants D65, A and D50.
//!
//! Scenes in the simulator are lit by a spectral power distribution; these are the standard
//! ones a camera is characterised and judged under. Sources: Planck's law with the constants
//! colour-science 0.4.7 uses; CIE 015:2018 for the daylight model (x_D(T), M1, M2 and the
//! S0, S1, S2 basis, shipped as `data/cie_daylight_basis.csv`); the CIE tables of D65, D50
//! and the CIE formula for A, shipped as `data/illuminants_cie.csv` (see `data/PROVENANCE.md`).

use crate::error::{short_number, Error, Result};
use crate::spectral::{Extrapolation, Grid, Interpolation, Spd, SpectralSet};
use serde::{Deserialize, Serialize};
use std::sync::OnceLock;

/// First radiation constant c1 = 2πhc², in W·m², as colour-science 0.4.7 (`CONSTANT_C1`).
pub const PLANCK_C1: f64 = 3.741771e-16;
/// Second radiation constant c2 = hc/k, in m·K: the ITS-90 value 1.4388e-2 of CIE 015 and
/// colour-science 0.4.7 (`CONSTANT_C2`). The CODATA 2018 value 1.438776877e-2 would move a
/// Planckian CCT by 1.6e-5 relative.
pub const PLANCK_C2: f64 = 1.4388e-2;

/// Lowest CCT of the CIE daylight formula, in kelvin (CIE 015:2018).
pub const DAYLIGHT_CCT_MIN_K: f64 = 4000.0;
/// Highest CCT of the CIE daylight formula, in kelvin (CIE 015:2018).
pub const DAYLIGHT_CCT_MAX_K: f64 = 25000.0;

/// Spectral radiance of a blackbody at `lambda_nm` and `t_kelvin` in W·sr⁻¹·m⁻²·nm⁻¹:
/// c1 / (π λ⁵ (exp(c2/(λT)) − 1)) with λ in metres, times 1e-9 m/nm (refractive index 1).
pub(crate) fn planck_radiance(lambda_nm: f64, t_kelvin: f64) -> f64 {
    let l = lambda_nm * 1e-9;
    PLANCK_C1 / (std::f64::consts::PI * l.powi(5) * (PLANCK_C2 / (l * t_kelvin)).exp_m1()) * 1e-9
}

/// Planck's law: the spectral radiance of a blackbody at `t_kelvin` on `grid`, in
/// W·sr⁻¹·m⁻²·nm⁻¹ (absolute; the same as colour-science's `sd_blackbody`, with
/// [`PLANCK_C1`] and [`PLANCK_C2`], refractive index 1). Errors on a temperature that is not a
/// positive finite number, or a grid reaching 0 nm or below.
pub fn planck(t_kelvin: f64, grid: &Grid) -> Result<Spd> {
    if !(t_kelvin.is_finite() && t_kelvin > 0.0) {
        return Err(Error::invalid(format!(
            "blackbody temperature {} K is not a positive number",
            short_number(t_kelvin)
        )));
    }
    if grid.start_nm <= 0.0 {
        return Err(Error::invalid(format!(
            "blackbody radiance needs positive wavelengths; the grid starts at {} nm",
            grid.start_nm
        )));
    }
    let values = grid
        .wavelengths()
        .iter()
        .map(|&w| planck_radiance(w, t_kelvin))
        .collect();
    Spd::new(*grid, values)
}

/// Chromaticity (x_D, y_D) of CIE daylight at correlated colour temperature `cct` in kelvin,
/// by the CIE 015:2018 formulas: x_D = −4.6070e9/T³ + 2.9678e6/T² + 0.09911e3/T + 0.244063 for
/// 4,000 ≤ T ≤ 7,000 K, x_D = −2.0064e9/T³ + 1.9018e6/T² + 0.24748e3/T + 0.237040 for
/// 7,000 < T ≤ 25,000 K, and y_D = −3.000 x_D² + 2.870 x_D − 0.275. Errors outside
/// 4,000–25,000 K.
pub fn daylight_xy(cct: f64) -> Result<[f64; 2]> {
    if !(DAYLIGHT_CCT_MIN_K..=DAYLIGHT_CCT_MAX_K).contains(&cct) {
        return Err(Error::invalid(format!(
            "daylight CCT {} K is outside the CIE daylight range {DAYLIGHT_CCT_MIN_K}–{DAYLIGHT_CCT_MAX_K} K",
            short_number(cct)
        )));
    }
    let t = cct;
    let x = if t <= 7000.0 {
        -4.6070e9 / t.powi(3) + 2.9678e6 / t.powi(2) + 0.09911e3 / t + 0.244063
    } else {
        -2.0064e9 / t.powi(3) + 1.9018e6 / t.powi(2) + 0.24748e3 / t + 0.237040
    };
    Ok([x, -3.000 * x * x + 2.870 * x - 0.275])
}

/// The CIE D-series SPD at correlated colour temperature `cct` (kelvin) on `grid`, relative,
/// 100 at 560 nm: [`daylight_xy`] then [`daylight_from_xy`]. Errors outside 4,000–25,000 K.
///
/// The standard illuminants are defined at nominal temperatures scaled by the 1968 change of
/// c2: D65 is daylight at 6500 × 1.4388/1.4380 ≈ 6504 K and D50 at ≈ 5003 K.
pub fn daylight(cct: f64, grid: &Grid) -> Result<Spd> {
    daylight_from_xy(daylight_xy(cct)?, grid)
}

/// The CIE D-series SPD of daylight chromaticity `xy` on `grid` (CIE 015:2018):
/// `DaylightBasis::on_grid(grid)?.spd(xy)`; see [`DaylightBasis`].
pub fn daylight_from_xy(xy: [f64; 2], grid: &Grid) -> Result<Spd> {
    DaylightBasis::on_grid(grid)?.spd(xy)
}

/// The CIE daylight basis S0, S1, S2 on a working grid, for computing many D-series SPDs on
/// one grid (e.g. the reference illuminants of colour rendering) without resampling the basis
/// each time.
///
/// The basis (shipped at 5 nm, 300–830 nm) is resampled to the grid by linear interpolation,
/// the interpolation CIE 015 recommends for it, and is zero outside 300–830 nm.
#[derive(Debug, Clone, PartialEq)]
pub struct DaylightBasis {
    grid: Grid,
    basis: [Vec<f64>; 3],
    /// S0, S1, S2 at 560 nm, where the SPDs are normalised to 100.
    at_560: [f64; 3],
}

impl DaylightBasis {
    /// The basis on `grid`.
    pub fn on_grid(grid: &Grid) -> Result<DaylightBasis> {
        let native = daylight_basis();
        let i560 = native
            .wavelengths()
            .iter()
            .position(|&w| w == 560.0)
            .expect("the shipped daylight basis has a 560 nm row");
        let (set, _) = native.resample(grid, Interpolation::Linear, Extrapolation::Zero)?;
        Ok(DaylightBasis {
            grid: *grid,
            basis: [0, 1, 2].map(|i| set.item(i).to_vec()),
            at_560: [0, 1, 2].map(|i| native.item(i)[i560]),
        })
    }

    /// The D-series SPD of daylight chromaticity `xy` (CIE 015:2018):
    /// S = S0 + M1·S1 + M2·S2 with M = 0.0241 + 0.2562x − 0.7341y,
    /// M1 = (−1.3515 − 1.7703x + 5.9114y)/M, M2 = (0.0300 − 31.4424x + 30.0717y)/M, M1 and M2
    /// rounded to three decimals as CIE 015 prescribes (and colour-science does by default),
    /// normalised to 100 at 560 nm.
    pub fn spd(&self, xy: [f64; 2]) -> Result<Spd> {
        let [x, y] = xy;
        let m = 0.0241 + 0.2562 * x - 0.7341 * y;
        if !(x.is_finite() && y.is_finite()) || m.abs() < 1e-6 {
            return Err(Error::invalid(format!(
                "chromaticity ({x}, {y}) has no CIE daylight spectrum (M = {m})"
            )));
        }
        let round3 = |v: f64| (v * 1000.0).round() / 1000.0;
        let m1 = round3((-1.3515 - 1.7703 * x + 5.9114 * y) / m);
        let m2 = round3((0.0300 - 31.4424 * x + 30.0717 * y) / m);
        let [s0, s1, s2] = &self.basis;
        let scale = 100.0 / (self.at_560[0] + m1 * self.at_560[1] + m2 * self.at_560[2]);
        let values = s0
            .iter()
            .zip(s1)
            .zip(s2)
            .map(|((a, b), c)| scale * (a + m1 * b + m2 * c))
            .collect();
        Spd::new(self.grid, values)
    }
}

/// The CIE daylight basis S0, S1, S2 (300–830 nm, 5 nm), parsed once.
fn daylight_basis() -> &'static SpectralSet {
    static TABLE: OnceLock<SpectralSet> = OnceLock::new();
    TABLE.get_or_init(|| {
        let set = SpectralSet::from_csv_str(
            include_str!("../../../data/cie_daylight_basis.csv"),
            "built-in cie_daylight_basis.csv",
        )
        .expect("the shipped daylight basis parses");
        assert_eq!(set.names(), ["S0", "S1", "S2"], "daylight basis columns");
        set
    })
}

/// The CIE standard illuminants D65, A, D50 (300–780 nm, 5 nm), parsed once.
fn standard_table() -> &'static SpectralSet {
    static TABLE: OnceLock<SpectralSet> = OnceLock::new();
    TABLE.get_or_init(|| {
        SpectralSet::from_csv_str(
            include_str!("../../../data/illuminants_cie.csv"),
            "built-in illuminants_cie.csv",
        )
        .expect("the shipped illuminant table parses")
    })
}

/// A CIE standard illuminant with a shipped table (`data/illuminants_cie.csv`, relative SPDs,
/// 100 at 560 nm, 300–780 nm at 5 nm).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum StandardIlluminant {
    /// CIE D65, average daylight (≈ 6504 K), the sRGB white; CIE 015 table.
    D65,
    /// CIE illuminant A, tungsten (Planckian, 2856 K); CIE 015 formula.
    A,
    /// CIE D50, horizon daylight (≈ 5003 K), the ICC/printing white; CIE 015 table.
    D50,
}

impl StandardIlluminant {
    /// All standard illuminants, in table order.
    pub const ALL: [StandardIlluminant; 3] = [
        StandardIlluminant::D65,
        StandardIlluminant::A,
        StandardIlluminant::D50,
    ];

    /// The CIE name, also the column of `data/illuminants_cie.csv`: `D65`, `A` or `D50`.
    pub fn name(&self) -> &'static str {
        match self {
            StandardIlluminant::D65 => "D65",
            StandardIlluminant::A => "A",
            StandardIlluminant::D50 => "D50",
        }
    }

    /// The illuminant called `name` (case-insensitive).
    pub fn parse(name: &str) -> Result<StandardIlluminant> {
        let name = name.trim();
        Self::ALL
            .into_iter()
            .find(|i| i.name().eq_ignore_ascii_case(name))
            .ok_or_else(|| Error::UnknownName {
                kind: "illuminant",
                name: name.to_string(),
                valid: Self::ALL.map(|i| i.name()).join(", "),
            })
    }

    /// The relative SPD (100 at 560 nm) on `grid`: the table resampled with Sprague (1880)
    /// interpolation (CIE 167:2005; exact at the 5 nm table points), zero outside 300–780 nm.
    ///
    /// ```
    /// use spdcam_core::cie_illuminant::StandardIlluminant;
    /// use spdcam_core::spectral::Grid;
    ///
    /// let grid = Grid::ESTIMATION;
    /// let d65 = StandardIlluminant::parse("D65")?.spd(&grid)?;
    /// assert_eq!(d65.grid(), &grid);
    /// assert!((d65[grid.index_of(560.0).unwrap()] - 100.0).abs() < 1e-9);
    /// # Ok::<(), spdcam_core::Error>(())
    /// ```
    pub fn spd(&self, grid: &Grid) -> Result<Spd> {
        let table = standard_table();
        let column = table
            .position(self.name())
            .expect("the shipped illuminant table has a column per standard illuminant");
        let (set, _) =
            table
                .select(&[column])
                .resample(grid, Interpolation::Auto, Extrapolation::Zero)?;
        Spd::new(*grid, set.item(0).to_vec())
    }
}

impl std::fmt::Display for StandardIlluminant {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn planck_matches_hand_computation_and_rejects_bad_input() {
        // 5000 K at 560 nm: c1/(π λ⁵ (e^{c2/(λT)} − 1)) · 1e-9.
        let grid = Grid::new(560.0, 560.0, 1.0).unwrap();
        let l: f64 = 560e-9;
        let expected = 3.741771e-16
            / (std::f64::consts::PI * l.powi(5))
            / ((1.4388e-2 / (l * 5000.0)).exp() - 1.0)
            * 1e-9;
        let v = planck(5000.0, &grid).unwrap()[0];
        assert!((v / expected - 1.0).abs() < 1e-12, "{v} vs {expected}");
        assert!(planck(0.0, &grid).is_err());
        assert!(planck(-5.0, &grid).is_err());
        assert!(planck(f64::NAN, &grid).is_err());
        assert!(planck(5000.0, &Grid::new(0.0, 10.0, 5.0).unwrap()).is_err());
    }

    #[test]
    fn daylight_is_100_at_560_and_checks_range() {
        for t in [4000.0, 5003.0, 6504.0, 7000.0, 7001.0, 25000.0] {
            let spd = daylight(t, &Grid::SIMULATION).unwrap();
            assert!((spd[36] - 100.0).abs() < 1e-12, "{t} K: {}", spd[36]);
        }
        assert!(daylight(3999.0, &Grid::SIMULATION).is_err());
        assert!(daylight(25001.0, &Grid::SIMULATION).is_err());
        assert!(daylight_xy(f64::NAN).is_err());
        // The two branches of x_D(T) nearly meet at 7000 K.
        let a = daylight_xy(7000.0).unwrap();
        let b = daylight_xy(7000.0 + 1e-9).unwrap();
        assert!((a[0] - b[0]).abs() < 1e-4, "{a:?} {b:?}");
    }

    #[test]
    fn daylight_at_6504k_reproduces_the_d65_table() {
        // D65 is the D-series at 6500·1.4388/1.4380 K; at the 10 nm points the model
        // reproduces the CIE table to its 4-decimal rounding.
        let grid = Grid::new(300.0, 780.0, 10.0).unwrap();
        let model = daylight(6500.0 * 1.4388 / 1.4380, &grid).unwrap();
        let table = StandardIlluminant::D65.spd(&grid).unwrap();
        for (i, (m, t)) in model.iter().zip(table.iter()).enumerate() {
            assert!(
                (m - t).abs() <= 5.0001e-4,
                "{} nm: {m} vs {t}",
                grid.wavelength(i)
            );
        }
    }

    #[test]
    fn daylight_from_unreachable_chromaticity_is_an_error() {
        // M = 0.0241 + 0.2562x − 0.7341y vanishes here.
        let y = (0.0241 + 0.2562 * 0.3) / 0.7341;
        assert!(daylight_from_xy([0.3, y], &Grid::SIMULATION).is_err());
        assert!(daylight_from_xy([f64::NAN, 0.3], &Grid::SIMULATION).is_err());
    }

    #[test]
    fn standard_illuminants_names_and_tables() {
        for i in StandardIlluminant::ALL {
            assert_eq!(StandardIlluminant::parse(i.name()).unwrap(), i);
            assert_eq!(i.to_string(), i.name());
            let spd = i.spd(&Grid::SIMULATION).unwrap();
            assert!((spd[36] - 100.0).abs() < 1e-9, "{i}: {}", spd[36]);
        }
        assert_eq!(
            StandardIlluminant::parse("d65").unwrap(),
            StandardIlluminant::D65
        );
        let e = StandardIlluminant::parse("F2").unwrap_err().to_string();
        assert!(e.contains("'F2'") && e.contains("D65, A, D50"), "{e}");
        // Zero beyond the table's 780 nm end.
        let spd = StandardIlluminant::A
            .spd(&Grid::new(770.0, 790.0, 5.0).unwrap())
            .unwrap();
        assert!(spd[2] > 0.0 && spd[3] == 0.0 && spd[4] == 0.0);
    }
}
