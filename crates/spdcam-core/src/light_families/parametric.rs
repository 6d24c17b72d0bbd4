//! Lights of real rooms drawn from a few parameters: CIE daylight and Planckian radiators at
//! a random colour temperature, phosphor-converted white LEDs and fluorescent-like line
//! spectra. Every SPD is normalised by its maximum.

use crate::cie_illuminant;
use crate::colorimetry::{cct_duv_to_uv, Observer};
use crate::error::{Error, Result};
use crate::spectral::{normalise_peak, Grid};
use rand::rngs::SmallRng;
use rand::Rng;

/// A range of correlated colour temperatures, drawn uniformly in mired (1/T), so warm and
/// cool lights are as far apart perceptually as they are in the sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CctRange {
    /// The lowest CCT (K).
    pub min_k: f64,
    /// The highest CCT (K).
    pub max_k: f64,
}

impl CctRange {
    /// Parses `MIN-MAX` in kelvin, or returns `default` for an empty string; the range must
    /// lie within `limits`.
    pub fn parse(text: &str, default: CctRange, limits: CctRange, spec: &str) -> Result<CctRange> {
        if text.is_empty() {
            return Ok(default);
        }
        let bad = || {
            Error::invalid(format!(
                "'{spec}': '{text}' is not a CCT range like {}-{} (kelvin)",
                default.min_k, default.max_k
            ))
        };
        let (a, b) = text.split_once('-').ok_or_else(bad)?;
        let parse = |s: &str| {
            s.trim_end_matches(['K', 'k'])
                .parse::<f64>()
                .map_err(|_| bad())
        };
        let range = CctRange {
            min_k: parse(a)?,
            max_k: parse(b)?,
        };
        if !(range.min_k <= range.max_k
            && range.min_k >= limits.min_k
            && range.max_k <= limits.max_k)
        {
            return Err(Error::invalid(format!(
                "'{spec}': the CCT range {}–{} K must be increasing and within {}–{} K",
                range.min_k, range.max_k, limits.min_k, limits.max_k
            )));
        }
        Ok(range)
    }

    /// A temperature drawn uniformly in mired.
    pub fn draw(&self, rng: &mut SmallRng) -> f64 {
        let (lo, hi) = (1e6 / self.max_k, 1e6 / self.min_k);
        1e6 / (lo + (hi - lo) * rng.random::<f64>())
    }
}

/// CIE daylight (D series) at `cct`, normalised by its maximum (the absolute-scaled one,
/// 100 at 560 nm, is [`cie_illuminant::daylight`]).
pub fn normalised_daylight(cct: f64, grid: &Grid) -> Result<Vec<f64>> {
    let mut spd = cie_illuminant::daylight(cct, grid)?.into_values();
    normalise_peak(&mut spd)?;
    Ok(spd)
}

/// Planck's law at `cct`, normalised by its maximum (the absolute radiance is
/// [`cie_illuminant::planck`]).
pub fn normalised_planck(cct: f64, grid: &Grid) -> Result<Vec<f64>> {
    let mut spd = cie_illuminant::planck(cct, grid)?.into_values();
    normalise_peak(&mut spd)?;
    Ok(spd)
}

/// A Gaussian band averaged over each grid interval (so narrow lines keep their energy on a
/// coarse grid), added into `spd` with peak height `amplitude`.
fn add_band(spd: &mut [f64], grid: &Grid, centre: f64, sigma: f64, amplitude: f64) {
    const SUB: usize = 9;
    for (i, s) in spd.iter_mut().enumerate() {
        let l = grid.wavelength(i);
        let mean: f64 = (0..SUB)
            .map(|j| {
                let x = l + grid.step_nm * ((j as f64 + 0.5) / SUB as f64 - 0.5);
                (-(x - centre).powi(2) / (2.0 * sigma * sigma)).exp()
            })
            .sum::<f64>()
            / SUB as f64;
        *s += amplitude * mean;
    }
}

/// Phosphor-converted white LEDs: a blue pump (peak 440–460 nm, σ 8–12 nm), a broad
/// yellow-green phosphor band (peak 540–580 nm, σ 35–55 nm) and a red phosphor band
/// (600–640 nm, σ 25–40 nm), their heights solved so the white lands on a chromaticity drawn
/// like a binned LED's: CCT uniform in mired over 2,700–6,500 K, Duv uniform on ±0.006
/// (the ANSI C78.377 tolerance).
#[derive(Debug, Clone, PartialEq)]
pub struct PhosphorLeds {
    observer: Observer,
}

/// Shapes whose heights cannot reach the drawn white are drawn again, at most this often.
const PHOSPHOR_TRIES: usize = 1000;

impl PhosphorLeds {
    /// Phosphor whites on `grid`.
    pub fn new(grid: &Grid) -> Result<PhosphorLeds> {
        Ok(PhosphorLeds {
            observer: Observer::cie1931(grid)?,
        })
    }

    /// One white LED, normalised by its maximum.
    pub fn draw(&self, rng: &mut SmallRng) -> Result<Vec<f64>> {
        let grid = *self.observer.grid();
        let u = |rng: &mut SmallRng, a: f64, b: f64| a + (b - a) * rng.random::<f64>();
        let cct = CctRange {
            min_k: 2700.0,
            max_k: 6500.0,
        }
        .draw(rng);
        let [ut, vt] = cct_duv_to_uv(cct, u(rng, -0.006, 0.006))?;
        for _ in 0..PHOSPHOR_TRIES {
            let mut bands = [
                vec![0.0; grid.count],
                vec![0.0; grid.count],
                vec![0.0; grid.count],
            ];
            add_band(
                &mut bands[0],
                &grid,
                u(rng, 440.0, 460.0),
                u(rng, 8.0, 12.0),
                1.0,
            );
            add_band(
                &mut bands[1],
                &grid,
                u(rng, 540.0, 580.0),
                u(rng, 35.0, 55.0),
                1.0,
            );
            add_band(
                &mut bands[2],
                &grid,
                u(rng, 600.0, 640.0),
                u(rng, 25.0, 40.0),
                1.0,
            );
            // (u, v) = (4X, 6Y) / (X + 15Y + 3Z) is linear in the band heights once the
            // denominator is multiplied out: two equations for the pump and red heights
            // with the yellow band at height 1.
            let rows = bands.clone().map(|b| {
                let [x, y, z] = self.observer.spd_to_xyz(&b);
                let d = x + 15.0 * y + 3.0 * z;
                [4.0 * x - ut * d, 6.0 * y - vt * d]
            });
            let (p, r, yb) = (rows[0], rows[2], rows[1]);
            let det = p[0] * r[1] - p[1] * r[0];
            if det.abs() < 1e-300 {
                continue;
            }
            let pump = (-yb[0] * r[1] + yb[1] * r[0]) / det;
            let red = (-p[0] * yb[1] + p[1] * yb[0]) / det;
            if !(pump > 0.05 && (0.0..=1.5).contains(&red)) {
                continue;
            }
            let mut spd: Vec<f64> = (0..grid.count)
                .map(|i| pump * bands[0][i] + bands[1][i] + red * bands[2][i])
                .collect();
            normalise_peak(&mut spd)?;
            return Ok(spd);
        }
        Err(Error::invalid(format!(
            "no phosphor LED reached CCT {cct:.0} K in {PHOSPHOR_TRIES} shapes"
        )))
    }
}

/// A fluorescent-like lamp: the mercury lines (404.7, 435.8, 546.1, 577.0 nm) and the
/// tri-phosphor bands of rare-earth lamps (blue 450 nm broad, terbium 543 nm, europium
/// 611 nm narrow), each with a random strength, on a broad Planckian base (2,700–6,500 K)
/// of random level.
pub fn fluorescent(grid: &Grid, rng: &mut SmallRng) -> Result<Vec<f64>> {
    let u = |rng: &mut SmallRng, a: f64, b: f64| a + (b - a) * rng.random::<f64>();
    let base_cct = u(rng, 2700.0, 6500.0);
    let mut spd = normalised_planck(base_cct, grid)?;
    let level = u(rng, 0.05, 0.4);
    spd.iter_mut().for_each(|v| *v *= level);
    for (centre, sigma, lo, hi) in [
        (404.7, 1.5, 0.05, 0.3),
        (435.8, 1.5, 0.2, 0.8),
        (546.1, 1.5, 0.3, 1.0),
        (577.0, 2.0, 0.05, 0.3),
        (450.0, 15.0, 0.0, 0.3),
        (543.0, 3.0, 0.0, 1.0),
        (611.0, 3.0, 0.2, 1.0),
    ] {
        let width = sigma * u(rng, 0.8, 1.5);
        add_band(&mut spd, grid, centre, width, u(rng, lo, hi));
    }
    normalise_peak(&mut spd)?;
    Ok(spd)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cie_illuminant::StandardIlluminant;
    use crate::colorimetry::{uv_to_cct_duv, xy_to_uv1960};
    use rand::SeedableRng;

    #[test]
    fn daylight_at_6504_is_d65() {
        let grid = Grid::SIMULATION;
        let ours = normalised_daylight(6504.0, &grid).unwrap();
        let d65 = StandardIlluminant::D65
            .spd(&grid)
            .unwrap()
            .normalised_by_max();
        let worst = ours
            .iter()
            .zip(d65.iter())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        // The CIE tabulates D65 from rounded basis weights: the two agree to about 1 %.
        assert!(worst < 0.015, "largest difference {worst}");
    }

    #[test]
    fn cct_draws_stay_in_range_and_cover_it() {
        let range = CctRange {
            min_k: 1500.0,
            max_k: 10000.0,
        };
        let mut rng = SmallRng::seed_from_u64(1);
        let draws: Vec<f64> = (0..2000).map(|_| range.draw(&mut rng)).collect();
        assert!(draws.iter().all(|&t| (1500.0..=10000.0).contains(&t)));
        assert!(draws.iter().any(|&t| t < 1700.0) && draws.iter().any(|&t| t > 7000.0));
        let limits = range;
        assert!(CctRange::parse("2000-3000", range, limits, "s").is_ok());
        assert!(CctRange::parse("3000-2000", range, limits, "s").is_err());
        assert!(CctRange::parse("1000-3000", range, limits, "s").is_err());
        assert!(CctRange::parse("warm", range, limits, "s").is_err());
    }

    #[test]
    fn phosphor_leds_are_whites() {
        let grid = Grid::SIMULATION;
        let observer = Observer::cie1931(&grid).unwrap();
        let leds = PhosphorLeds::new(&grid).unwrap();
        let mut rng = SmallRng::seed_from_u64(7);
        for _ in 0..200 {
            let spd = leds.draw(&mut rng).unwrap();
            let (cct, duv) = uv_to_cct_duv(xy_to_uv1960(observer.spd_to_xy(&spd))).unwrap();
            assert!((2690.0..6510.0).contains(&cct), "CCT {cct}");
            assert!(duv.abs() < 0.0061, "Duv {duv}");
            // A blue pump below 470 nm and a broad band beyond.
            let peak = (0..spd.len())
                .max_by(|&a, &b| spd[a].total_cmp(&spd[b]))
                .unwrap();
            let blue = grid.index_of(450.0).unwrap();
            assert!(spd[blue] > 0.1 && grid.wavelength(peak) > 430.0);
        }
    }

    #[test]
    fn fluorescent_has_its_lines() {
        let grid = Grid::SIMULATION;
        let mut rng = SmallRng::seed_from_u64(2);
        let spd = fluorescent(&grid, &mut rng).unwrap();
        let at = |nm: f64| spd[grid.index_of(nm).unwrap()];
        // The 545 nm bin holds the mercury line and the terbium band: far above its
        // neighbours 20 nm away.
        assert!(at(545.0) > 2.0 * at(525.0));
        assert!((spd.iter().cloned().fold(0.0, f64::max) - 1.0).abs() < 1e-12);
    }
}
