//! The virtual camera's colour calibration as a DNG carries it: `ColorMatrix1/2` (XYZ →
//! camera raw RGB) fitted on the chart under CIE A and D65 as camera makers and Adobe fit
//! theirs (least squares over a chart's patches, then scaled so that the illuminant's white
//! reads 1 in its largest channel: DNG 1.6 ch. 6), and the camera's neutral under a light.

use super::Camera;
use crate::cie_illuminant::StandardIlluminant;
use crate::colorimetry::Observer;
use crate::error::{Error, Result};
use crate::spectral::Spd;
use nalgebra::{Matrix3, Vector3};

/// The EXIF `LightSource` codes of the two calibration illuminants.
pub const CALIBRATION_ILLUMINANTS: [(u16, StandardIlluminant); 2] =
    [(17, StandardIlluminant::A), (21, StandardIlluminant::D65)];

impl Camera {
    /// Raw camera RGB of every patch under `spd` (no exposure, glare or white balance).
    fn patch_raw(&self, spd: &Spd) -> Result<Vec<[f64; 3]>> {
        let light = self.light(spd)?;
        let mut raw = Vec::new();
        self.response.raw_into(&light, &mut raw);
        raw.truncate(self.chart.reflectances.len());
        Ok(raw.iter().map(|v| v.map(f64::from)).collect())
    }

    /// `ColorMatrix` under `illuminant`: XYZ → camera raw RGB, the least-squares fit over
    /// the chart's patches (XYZ with the illuminant's white at Y = 1), scaled so that the
    /// illuminant's white maps to a largest channel of 1.
    pub fn dng_colour_matrix(&self, illuminant: StandardIlluminant) -> Result<Matrix3<f64>> {
        let spd = illuminant.spd(&self.grid)?;
        let observer = Observer::cie1931(&self.grid)?;
        let white = observer.spd_to_xyz(spd.values());
        if white[1].is_nan() || white[1] <= 0.0 {
            return Err(Error::invalid(
                "the calibration illuminant has no luminance",
            ));
        }
        let xyz: Vec<[f64; 3]> = (0..self.chart.reflectances.len())
            .map(|p| {
                observer
                    .reflectance_to_xyz(self.chart.reflectances.item(p), spd.values())
                    .map(|v| v / white[1])
            })
            .collect();
        let raw = self.patch_raw(&spd)?;
        let fitted = super::colour::fit_correction_matrix(&xyz, &raw)?;
        let neutral = fitted * Vector3::new(white[0], white[1], white[2]) / white[1];
        let top = neutral.max();
        if top.is_nan() || top <= 0.0 {
            return Err(Error::invalid(
                "the camera gives the calibration illuminant's white no signal",
            ));
        }
        Ok(fitted / top)
    }

    /// Both `ColorMatrix` tags of a DNG, by EXIF `LightSource` code.
    pub fn dng_colour_matrices(&self) -> Result<[(u16, Matrix3<f64>); 2]> {
        let [(c1, i1), (c2, i2)] = CALIBRATION_ILLUMINANTS;
        Ok([
            (c1, self.dng_colour_matrix(i1)?),
            (c2, self.dng_colour_matrix(i2)?),
        ])
    }

    /// The camera's raw RGB of a perfect white under `spd`, green 1: the as-shot neutral a
    /// camera that read its light exactly would record.
    pub fn neutral_under(&self, spd: &Spd) -> Result<[f64; 3]> {
        let raw = self.patch_raw(spd)?;
        let (p, r) = self
            .chart
            .reflectances
            .len()
            .checked_sub(0)
            .map(|n| {
                (0..n).map(|p| {
                    let refl = self.chart.reflectances.item(p);
                    (p, refl.iter().sum::<f64>() / refl.len() as f64)
                })
            })
            .into_iter()
            .flatten()
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .ok_or_else(|| Error::invalid("the chart has no patches"))?;
        let v = raw[p].map(|c| c / r);
        if v[1].is_nan() || v[1] <= 0.0 {
            return Err(Error::invalid(
                "the light gives this camera no green signal",
            ));
        }
        Ok(v.map(|c| c / v[1]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builtin;
    use crate::camera::sensor::Sensitivities;
    use crate::camera::CameraConfig;
    use crate::chart::Chart;
    use crate::spectral::Grid;

    #[test]
    fn the_fitted_matrices_read_their_own_illuminant_back() {
        let grid = Grid::SIMULATION;
        let table = &builtin::CAMERAS[0];
        let sensitivities = Sensitivities::new(table.name, &table.load().unwrap(), &grid).unwrap();
        let chart = Chart::colorchecker24(&grid).unwrap();
        let camera = Camera::new(&sensitivities, chart, CameraConfig::default(), &grid).unwrap();
        let observer = Observer::cie1931(&grid).unwrap();
        for (_, illuminant) in CALIBRATION_ILLUMINANTS {
            let m = camera.dng_colour_matrix(illuminant).unwrap();
            let spd = illuminant.spd(&grid).unwrap();
            let neutral = camera.neutral_under(&spd).unwrap();
            // The white's XYZ through the matrix has the white's chromaticity, within the
            // fit's residual over 24 patches.
            let xyz = m.try_inverse().unwrap() * Vector3::from(neutral);
            let xy = crate::colorimetry::xyz_to_xy([xyz[0], xyz[1], xyz[2]]);
            let truth = observer.spd_to_xy(spd.values());
            assert!(
                (xy[0] - truth[0]).abs() < 0.004 && (xy[1] - truth[1]).abs() < 0.004,
                "{illuminant:?}: {xy:?} vs {truth:?}"
            );
            let white = m * Vector3::from(crate::colorimetry::xy_to_xyz(truth, 1.0));
            assert!((white.max() - 1.0).abs() < 0.02, "{white:?}");
        }
    }
}
