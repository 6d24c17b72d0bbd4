//! A deliberately simple patch-level JPEG-like camera, written apart from the main camera
//! pipeline (`camera/`): it shares only the measured tables (sensitivities, reflectances,
//! the CIE observer and D65). It checks that validation scores are not only "our simulator
//! against itself": a model that learned the main pipeline's quirks scores worse here.
//!
//! Per patch: raw = Σ_λ camera(λ) · reflectance(λ) · light(λ); a linear lighting gradient
//! across the chart; veiling flare (a fraction of the mean raw added to every patch);
//! grey-world white balance (gains that equalise the patches' channel means, Buchsbaum
//! 1980) applied partially (gains raised to a power below 1); a 3×3 colour matrix fitted by
//! least squares under D65 from the white-balanced raw values to the patches' linear sRGB;
//! auto exposure (the patches' mean luminance scaled to a target); clipping; the sRGB curve
//! (IEC 61966-2-1); rounding to 8 bits.

use crate::camera::sensor::Sensitivities;
use crate::chart::Chart;
use crate::cie_illuminant::StandardIlluminant;
use crate::colorimetry::Observer;
use crate::colorimetry::{srgb_encode, xyz_to_linear_srgb};
use crate::error::{Error, Result};
use crate::spectral::Grid;
use nalgebra::{DMatrix, Matrix3, Vector3};
use rand::rngs::SmallRng;
use rand::Rng;

/// One shot's settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shot {
    /// Power of the grey-world gains (1 = full white balance, 0 = none).
    pub adaptation: f64,
    /// Mean luminance of the patches after exposure (linear, 0–1).
    pub exposure_target: f64,
    /// Flare: this fraction of the patches' mean raw value is added to every patch.
    pub flare: f64,
    /// Relative light gain 1 + gx·x + gy·y, x and y the patch centre from −½ to ½.
    pub gradient: [f64; 2],
}

impl Shot {
    /// A shot drawn uniformly from modest ranges: adaptation 0.6–1, exposure target
    /// 0.12–0.3, flare 0–0.05, gradient ±0.15 per chart width and height.
    pub fn draw(rng: &mut SmallRng) -> Shot {
        let mut u = |a: f64, b: f64| a + (b - a) * rng.random::<f64>();
        Shot {
            adaptation: u(0.6, 1.0),
            exposure_target: u(0.12, 0.3),
            flare: u(0.0, 0.05),
            gradient: [u(-0.15, 0.15), u(-0.15, 0.15)],
        }
    }
}

/// A camera photographing one chart's feature patches.
#[derive(Debug, Clone)]
pub struct SimpleCamera {
    /// Per feature patch: camera sensitivity × reflectance, per channel, on the grid.
    weights: Vec<[Vec<f64>; 3]>,
    /// Per feature patch: its centre across the chart, −½…½.
    centres: Vec<[f64; 2]>,
    /// White-balanced camera RGB → linear sRGB, fitted under D65.
    matrix: Matrix3<f64>,
    grid: Grid,
}

impl SimpleCamera {
    /// The camera `sensitivities` looking at `chart` (both on `grid`); fits its colour matrix.
    pub fn new(sensitivities: &Sensitivities, chart: &Chart, grid: &Grid) -> Result<SimpleCamera> {
        let curves = &sensitivities.curves;
        if curves.len() != 3 || curves.item(0).len() != grid.count {
            return Err(Error::invalid(format!(
                "camera '{}' is not three curves on {grid}",
                sensitivities.name
            )));
        }
        let weights: Vec<[Vec<f64>; 3]> = chart
            .feature_patches
            .iter()
            .map(|&p| {
                let refl = chart.reflectances.item(p);
                std::array::from_fn(|c| {
                    curves
                        .item(c)
                        .iter()
                        .zip(refl)
                        .map(|(s, r)| s * r)
                        .collect()
                })
            })
            .collect();
        let centres = chart.feature_centres();
        let d65 = StandardIlluminant::D65.spd(grid)?;
        let observer = Observer::cie1931(grid)?;
        let white_y = observer.white_xyz(&d65)[1];
        let mut camera = SimpleCamera {
            weights,
            centres,
            matrix: Matrix3::identity(),
            grid: *grid,
        };
        let raw = camera.white_balanced(&camera.raw(&d65, [0.0, 0.0], 0.0), 1.0);
        let target: Vec<[f64; 3]> = chart
            .feature_patches
            .iter()
            .map(|&p| {
                let xyz = observer.reflectance_to_xyz(chart.reflectances.item(p), &d65);
                xyz_to_linear_srgb(xyz.map(|v| v / white_y))
            })
            .collect();
        let n = raw.len();
        let a = DMatrix::from_fn(n, 3, |i, c| raw[i][c]);
        let b = DMatrix::from_fn(n, 3, |i, c| target[i][c]);
        let solved = a
            .svd(true, true)
            .solve(&b, 1e-12)
            .map_err(|e| Error::invalid(format!("colour matrix under D65: {e}")))?;
        // raw row · solved = target row, so the matrix acting on column vectors is solvedᵀ.
        camera.matrix = Matrix3::from_fn(|r, c| solved[(c, r)]);
        Ok(camera)
    }

    /// Raw patch values under `light` with a gradient and flare.
    fn raw(&self, light: &[f64], gradient: [f64; 2], flare: f64) -> Vec<[f64; 3]> {
        let mut raw: Vec<[f64; 3]> = self
            .weights
            .iter()
            .zip(&self.centres)
            .map(|(w, [x, y])| {
                let gain = (1.0 + gradient[0] * x + gradient[1] * y).max(0.0);
                std::array::from_fn(|c| {
                    gain * w[c].iter().zip(light).map(|(a, b)| a * b).sum::<f64>()
                })
            })
            .collect();
        let mean = channel_means(&raw);
        for v in &mut raw {
            for c in 0..3 {
                v[c] += flare * mean[c];
            }
        }
        raw
    }

    /// Grey-world gains (relative to green) raised to `adaptation`, applied.
    fn white_balanced(&self, raw: &[[f64; 3]], adaptation: f64) -> Vec<[f64; 3]> {
        let mean = channel_means(raw);
        let gains: [f64; 3] = std::array::from_fn(|c| {
            if mean[c] > 0.0 {
                (mean[1] / mean[c]).powf(adaptation)
            } else {
                1.0
            }
        });
        raw.iter()
            .map(|v| std::array::from_fn(|c| v[c] * gains[c]))
            .collect()
    }

    /// The features (mean sRGB 0–255 of each feature patch, R, G, B per patch) of the chart
    /// under `light` (on the camera's grid) with `shot`.
    pub fn photograph(&self, light: &[f64], shot: &Shot) -> Result<Vec<f64>> {
        if light.len() != self.grid.count {
            return Err(Error::invalid(format!(
                "the light has {} values; the camera's grid {} needs {}",
                light.len(),
                self.grid,
                self.grid.count
            )));
        }
        let raw = self.raw(light, shot.gradient, shot.flare);
        let balanced = self.white_balanced(&raw, shot.adaptation);
        let linear: Vec<Vector3<f64>> = balanced
            .iter()
            .map(|v| self.matrix * Vector3::new(v[0], v[1], v[2]))
            .collect();
        let luminance = linear
            .iter()
            .map(|v| 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2])
            .sum::<f64>()
            / linear.len() as f64;
        if !(luminance > 0.0 && luminance.is_finite()) {
            return Err(Error::invalid(
                "the light gives the simple camera no signal",
            ));
        }
        let scale = shot.exposure_target / luminance;
        Ok(linear
            .iter()
            .flat_map(|v| {
                (0..3).map(move |c| {
                    let encoded: f64 = srgb_encode((v[c] * scale).clamp(0.0, 1.0));
                    (255.0 * encoded).round()
                })
            })
            .collect())
    }
}

fn channel_means(raw: &[[f64; 3]]) -> [f64; 3] {
    let n = raw.len().max(1) as f64;
    std::array::from_fn(|c| raw.iter().map(|v| v[c]).sum::<f64>() / n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builtin;
    use rand::SeedableRng;

    fn camera() -> (SimpleCamera, Chart) {
        let grid = Grid::SIMULATION;
        let chart = Chart::colorchecker24(&grid).unwrap();
        let sens =
            Sensitivities::new("d5100", &builtin::CAMERAS[0].load().unwrap(), &grid).unwrap();
        (SimpleCamera::new(&sens, &chart, &grid).unwrap(), chart)
    }

    #[test]
    fn under_d65_the_greys_come_out_grey_and_ordered() {
        let (cam, _) = camera();
        let d65 = StandardIlluminant::D65.spd(&Grid::SIMULATION).unwrap();
        let shot = Shot {
            adaptation: 1.0,
            exposure_target: 0.18,
            flare: 0.0,
            gradient: [0.0, 0.0],
        };
        let f = cam.photograph(&d65, &shot).unwrap();
        // ColorChecker 24: patches 19–24 are the neutral row, white to black.
        let greys: Vec<[f64; 3]> = (18..24)
            .map(|p| [f[3 * p], f[3 * p + 1], f[3 * p + 2]])
            .collect();
        for g in &greys {
            let spread = g.iter().cloned().fold(f64::MIN, f64::max)
                - g.iter().cloned().fold(f64::MAX, f64::min);
            assert!(spread <= 8.0, "grey patch {g:?}");
        }
        assert!(greys.windows(2).all(|w| w[0][1] > w[1][1]));
        // Exposure scales away: twice the light, the same features.
        let double: Vec<f64> = d65.iter().map(|v| 2.0 * v).collect();
        assert_eq!(cam.photograph(&double, &shot).unwrap(), f);
    }

    #[test]
    fn no_white_balance_keeps_a_warm_cast_and_drawn_shots_stay_in_range() {
        let (cam, _) = camera();
        let grid = Grid::SIMULATION;
        let a = StandardIlluminant::A.spd(&grid).unwrap();
        let mut shot = Shot {
            adaptation: 0.0,
            exposure_target: 0.18,
            flare: 0.0,
            gradient: [0.0, 0.0],
        };
        let warm = cam.photograph(&a, &shot).unwrap();
        // Patch 22 (neutral 5): red well above blue under illuminant A without balance.
        assert!(
            warm[3 * 21] > warm[3 * 21 + 2] + 20.0,
            "{:?}",
            &warm[63..66]
        );
        shot.adaptation = 1.0;
        let balanced = cam.photograph(&a, &shot).unwrap();
        assert!((balanced[3 * 21] - balanced[3 * 21 + 2]).abs() < warm[3 * 21] - warm[3 * 21 + 2]);
        let mut rng = SmallRng::seed_from_u64(3);
        for _ in 0..50 {
            let s = Shot::draw(&mut rng);
            assert!((0.6..=1.0).contains(&s.adaptation) && (0.0..=0.05).contains(&s.flare));
            let f = cam.photograph(&a, &s).unwrap();
            assert!(f
                .iter()
                .all(|v| (0.0..=255.0).contains(v) && v.fract() == 0.0));
        }
        assert!(cam.photograph(&[1.0; 3], &shot).is_err());
    }
}
