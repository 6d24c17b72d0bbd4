//! The reference illuminants colour rendering and colour fidelity compare a light with.

use crate::cie_illuminant::{daylight_xy, planck, DaylightBasis};
use crate::colorimetry::Observer;
use crate::error::Result;
use crate::spectral::{Grid, Spd};

/// Planckian and CIE daylight references on one grid, with what they need prepared once.
#[derive(Debug, Clone)]
pub struct ReferenceIlluminants {
    grid: Grid,
    daylight: DaylightBasis,
    observer: Observer,
}

impl ReferenceIlluminants {
    /// The references on `grid`.
    pub fn on_grid(grid: &Grid) -> Result<ReferenceIlluminants> {
        Ok(ReferenceIlluminants {
            grid: *grid,
            daylight: DaylightBasis::on_grid(grid)?,
            observer: Observer::cie1931(grid)?,
        })
    }

    /// CIE daylight (D-series, CIE 015:2018) at `cct`; errors outside 4000–25,000 K.
    fn daylight(&self, cct: f64) -> Result<Spd> {
        self.daylight.spd(daylight_xy(cct)?)
    }

    /// The CIE 13.3-1995 reference illuminant at correlated colour temperature `cct`
    /// (CIE 13.3-1995 §5.1): a Planckian radiator below 5000 K, CIE daylight from 5000 K.
    /// Errors above 25,000 K, where CIE daylight is not defined.
    pub fn cie1995(&self, cct: f64) -> Result<Spd> {
        if cct < 5000.0 {
            planck(cct, &self.grid)
        } else {
            self.daylight(cct)
        }
    }

    /// The CIE 224:2017 (and ANSI/IES TM-30-20) reference illuminant at `cct` (CIE 224:2017
    /// §4.1): Planckian below 4000 K, CIE daylight above 5000 K, and between them the mixture
    /// (1 − m)·P/Y_P + m·D/Y_D with m = (T − 4000)/1000, each part normalised to its luminance
    /// Y with the CIE 1931 2° observer. Errors above 25,000 K.
    pub fn cie2017(&self, cct: f64) -> Result<Spd> {
        if cct < 4000.0 {
            return planck(cct, &self.grid);
        }
        if cct > 5000.0 {
            return self.daylight(cct);
        }
        let p = planck(cct, &self.grid)?;
        let d = self.daylight(cct)?;
        let (yp, yd) = (
            self.observer.spd_to_xyz(&p)[1],
            self.observer.spd_to_xyz(&d)[1],
        );
        let m = (cct - 4000.0) / 1000.0;
        let mix = p
            .iter()
            .zip(d.iter())
            .map(|(p, d)| (1.0 - m) * p / yp + m * d / yd)
            .collect();
        Spd::new(self.grid, mix)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cie_illuminant::daylight;

    #[test]
    fn switches_and_blends_at_the_standard_temperatures() {
        let grid = Grid::SIMULATION;
        let refs = ReferenceIlluminants::on_grid(&grid).unwrap();
        let obs = Observer::cie1931(&grid).unwrap();
        assert_eq!(
            refs.cie1995(4999.0).unwrap(),
            planck(4999.0, &grid).unwrap()
        );
        assert_eq!(
            refs.cie1995(5000.0).unwrap(),
            daylight(5000.0, &grid).unwrap()
        );
        assert_eq!(
            refs.cie2017(3999.0).unwrap(),
            planck(3999.0, &grid).unwrap()
        );
        assert_eq!(
            refs.cie2017(6000.0).unwrap(),
            daylight(6000.0, &grid).unwrap()
        );
        // At 4500 K the blend is half Planckian, half daylight, each at Y = 1.
        let mix = refs.cie2017(4500.0).unwrap();
        let p = planck(4500.0, &grid).unwrap();
        let d = daylight(4500.0, &grid).unwrap();
        let (yp, yd) = (obs.spd_to_xyz(&p)[1], obs.spd_to_xyz(&d)[1]);
        for i in [0, 40, 80] {
            let expected = 0.5 * p[i] / yp + 0.5 * d[i] / yd;
            assert!((mix[i] - expected).abs() < 1e-15 * expected.abs().max(1.0));
        }
        assert!((obs.spd_to_xyz(&mix)[1] - 1.0).abs() < 1e-12);
        // At exactly 4000 K the blend is all Planckian (at Y = 1).
        let at4000 = refs.cie2017(4000.0).unwrap();
        let p4 = planck(4000.0, &grid).unwrap();
        let yp4 = obs.spd_to_xyz(&p4)[1];
        assert!((at4000[40] - p4[40] / yp4).abs() < 1e-15);
        assert!(refs.cie1995(30_000.0).is_err());
        assert!(refs.cie2017(30_000.0).is_err());
    }
}
