//! The reference illuminants colour rendering and colour fidelity compare a light with.

use crate::colorimetry::Observer;
use crate::error::Result;
use crate::illuminant::{daylight, planck};
use crate::spectral::Grid;

/// The CIE 13.3-1995 reference illuminant at correlated colour temperature `cct` on `grid`
/// (CIE 13.3-1995 §5.1): a Planckian radiator below 5000 K, CIE daylight (D-series, CIE 015)
/// from 5000 K. Errors above 25,000 K, where CIE daylight is not defined.
pub fn reference_cie1995(cct: f64, grid: &Grid) -> Result<Vec<f64>> {
    if cct < 5000.0 {
        planck(cct, grid)
    } else {
        daylight(cct, grid)
    }
}

/// The CIE 224:2017 (and ANSI/IES TM-30-20) reference illuminant at `cct` on `grid`
/// (CIE 224:2017 §4.1): Planckian below 4000 K, CIE daylight above 5000 K, and between them
/// the mixture (1 − m)·P/Y_P + m·D/Y_D with m = (T − 4000)/1000, each part normalised to its
/// luminance Y with the CIE 1931 2° observer `obs` (on `grid`). Errors above 25,000 K.
pub fn reference_cie2017(cct: f64, grid: &Grid, obs: &Observer) -> Result<Vec<f64>> {
    if cct < 4000.0 {
        return planck(cct, grid);
    }
    if cct > 5000.0 {
        return daylight(cct, grid);
    }
    let p = planck(cct, grid)?;
    let d = daylight(cct, grid)?;
    let (yp, yd) = (obs.spd_to_xyz(&p)[1], obs.spd_to_xyz(&d)[1]);
    let m = (cct - 4000.0) / 1000.0;
    Ok(p.iter()
        .zip(&d)
        .map(|(p, d)| (1.0 - m) * p / yp + m * d / yd)
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn switches_and_blends_at_the_standard_temperatures() {
        let grid = Grid::SIMULATION;
        let obs = Observer::cie1931(&grid).unwrap();
        assert_eq!(
            reference_cie1995(4999.0, &grid).unwrap(),
            planck(4999.0, &grid).unwrap()
        );
        assert_eq!(
            reference_cie1995(5000.0, &grid).unwrap(),
            daylight(5000.0, &grid).unwrap()
        );
        assert_eq!(
            reference_cie2017(3999.0, &grid, &obs).unwrap(),
            planck(3999.0, &grid).unwrap()
        );
        // At 4500 K the blend is half Planckian, half daylight, each at Y = 1.
        let mix = reference_cie2017(4500.0, &grid, &obs).unwrap();
        let p = planck(4500.0, &grid).unwrap();
        let d = daylight(4500.0, &grid).unwrap();
        let (yp, yd) = (obs.spd_to_xyz(&p)[1], obs.spd_to_xyz(&d)[1]);
        for i in [0, 40, 80] {
            let expected = 0.5 * p[i] / yp + 0.5 * d[i] / yd;
            assert!((mix[i] - expected).abs() < 1e-15 * expected.abs().max(1.0));
        }
        assert!((obs.spd_to_xyz(&mix)[1] - 1.0).abs() < 1e-12);
        // At exactly 4000 K the blend is all Planckian, at 5000 K all daylight (Y = 1).
        let at4000 = reference_cie2017(4000.0, &grid, &obs).unwrap();
        let p4 = planck(4000.0, &grid).unwrap();
        let yp4 = obs.spd_to_xyz(&p4)[1];
        assert!((at4000[40] - p4[40] / yp4).abs() < 1e-15);
        assert!(reference_cie1995(30_000.0, &grid).is_err());
        assert!(reference_cie2017(30_000.0, &grid, &obs).is_err());
    }
}
