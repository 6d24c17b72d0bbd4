//! Sensor image formation (thesis Eq. 3.1–3.3): light × reflectance × sensitivity, integrated
//! over wavelength, seen through a Bayer filter (single sensor) or by three sensors.

use crate::builtin::{self, DataDir};
use crate::chart::Chart;
use crate::error::{Error, Result};
use crate::raster::{CfaPattern, Mosaic, RgbImage};
use crate::spectral::{Extrapolation, Grid, Interpolation, SpectralSet};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// A camera's relative spectral sensitivities (R, G, B) on the simulation grid.
#[derive(Debug, Clone)]
pub struct Sensitivities {
    /// The camera's name (its table or file).
    pub name: String,
    /// Three items, R, G, B, on the simulation grid.
    pub curves: SpectralSet,
}

/// Files skipped as no valid sensitivity set, each with why.
pub type SkippedFiles = Vec<(PathBuf, Error)>;

/// The range a camera's data must cover: where lights are estimated.
const REQUIRED_RANGE_NM: (f64, f64) = (400.0, 700.0);
/// A camera short of the required range is still accepted when its response at the
/// uncovered edge is below this fraction of its peak (zero there is then a fair assumption).
const NEGLIGIBLE_EDGE: f64 = 0.02;

impl Sensitivities {
    /// The sensitivities `spec` names: a CSV file (r,g,b), a built-in camera, or a CSV in
    /// the data directory's `cameras` or `thesis` folder; resampled onto `grid`.
    pub fn resolve(spec: &str, data_dir: &DataDir, grid: &Grid) -> Result<Sensitivities> {
        let (name, measured) = builtin::resolve_table(
            spec,
            "camera",
            builtin::CAMERAS,
            data_dir,
            &["cameras", "thesis"],
        )?;
        Sensitivities::new(&name, &measured, grid)
    }

    /// Every camera sensitivity CSV in `dir`, sorted by file name, and the files that are
    /// not a valid sensitivity set, each with why (skipped).
    pub fn in_dir(
        dir: &Path,
        data_dir: &DataDir,
        grid: &Grid,
    ) -> Result<(Vec<Sensitivities>, SkippedFiles)> {
        let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
            .map_err(|e| Error::io(dir, e))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|e| e == "csv"))
            .collect();
        files.sort();
        let mut found = Vec::with_capacity(files.len());
        let mut skipped = Vec::new();
        for f in files {
            match Sensitivities::resolve(&f.to_string_lossy(), data_dir, grid) {
                Ok(s) => found.push(s),
                Err(e) => skipped.push((f, e)),
            }
        }
        Ok((found, skipped))
    }

    /// Checks and resamples measured sensitivities (three columns R, G, B, any sampling) onto
    /// `grid`; outside the data they are zero. The data must cover 400–700 nm, or fall to a
    /// negligible response at the uncovered edge.
    pub fn new(name: &str, measured: &SpectralSet, grid: &Grid) -> Result<Sensitivities> {
        if measured.len() != 3 {
            return Err(Error::invalid(format!(
                "camera '{name}' has {} sensitivity columns ({}); expected three: r,g,b",
                measured.len(),
                crate::error::brief_list(measured.names())
            )));
        }
        let measured = measured
            .clone()
            .require_non_negative("camera sensitivity", 0.01)?;
        let w = measured.wavelengths();
        let (lo, hi) = (w[0], w[w.len() - 1]);
        let peak = measured
            .items()
            .iter()
            .flatten()
            .cloned()
            .fold(0.0f64, f64::max);
        if peak <= 0.0 {
            return Err(Error::invalid(format!(
                "camera '{name}' has no positive sensitivity"
            )));
        }
        let edge_max = |i: usize| measured.items().iter().map(|c| c[i]).fold(0.0f64, f64::max);
        let short_low = lo > REQUIRED_RANGE_NM.0 && edge_max(0) > NEGLIGIBLE_EDGE * peak;
        let short_high = hi < REQUIRED_RANGE_NM.1 && edge_max(w.len() - 1) > NEGLIGIBLE_EDGE * peak;
        if short_low || short_high {
            return Err(Error::invalid(format!(
                "camera '{name}' covers {lo}–{hi} nm; sensitivities must cover {}–{} nm",
                REQUIRED_RANGE_NM.0, REQUIRED_RANGE_NM.1
            )));
        }
        let (curves, _) = measured.resample(grid, Interpolation::Auto, Extrapolation::Zero)?;
        let curves = curves.with_names(vec!["r".into(), "g".into(), "b".into()])?;
        Ok(Sensitivities {
            name: name.to_string(),
            curves,
        })
    }
}

/// How the image is captured: one sensor behind a Bayer filter, or three sensors.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum SensorMode {
    /// Thesis Eq. 3.3: each pixel sees one channel through the colour filter array.
    SingleSensor(CfaPattern),
    /// Thesis Eq. 3.2 (Karaimer & Brown 2018): every pixel sees all three channels.
    ThreeSensor,
}

impl std::str::FromStr for SensorMode {
    type Err = Error;

    /// Parses a Bayer pattern (`rggb`, `bggr`, `grbg`, `gbrg`, any case) or `three`.
    fn from_str(text: &str) -> Result<SensorMode> {
        if text.eq_ignore_ascii_case("three") {
            return Ok(SensorMode::ThreeSensor);
        }
        text.parse::<CfaPattern>()
            .map(SensorMode::SingleSensor)
            .map_err(|_| Error::UnknownName {
                kind: "sensor",
                name: text.to_string(),
                valid: "rggb, bggr, grbg, gbrg, three".into(),
            })
    }
}

/// Sensor settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SensorConfig {
    /// One Bayer sensor (demosaiced) or three full-resolution sensors.
    pub mode: SensorMode,
    /// The brightest raw value is scaled to this fraction of full scale (the thesis
    /// normalises to the maximum: 1.0); above 1 the brightest patches clip.
    pub exposure: f64,
}

impl Default for SensorConfig {
    fn default() -> Self {
        SensorConfig {
            mode: SensorMode::SingleSensor(CfaPattern::Rggb),
            exposure: 1.0,
        }
    }
}

/// The camera's raw response of every chart region per unit of light in each band:
/// `kernel[(region·3 + channel)·bands + band] = S_channel(λ)·R_region(λ)·Δλ`.
/// Regions are the patches (row-major) and, last, the background.
#[derive(Debug, Clone)]
pub struct SpectralResponse {
    bands: usize,
    regions: usize,
    kernel: Vec<f32>,
}

impl SpectralResponse {
    /// Precomputes the response of `chart` seen by `camera` (both on `grid`).
    pub fn new(camera: &Sensitivities, chart: &Chart, grid: &Grid) -> Result<SpectralResponse> {
        camera.curves.require_grid(grid, "camera")?;
        chart.reflectances.require_grid(grid, "chart")?;
        let bands = grid.count;
        let regions = chart.reflectances.len() + 1;
        let background = vec![chart.background_reflectance; bands];
        let mut kernel = Vec::with_capacity(regions * 3 * bands);
        for r in 0..regions {
            let refl = if r + 1 < regions {
                chart.reflectances.item(r)
            } else {
                &background
            };
            for c in 0..3 {
                let s = camera.curves.item(c);
                kernel.extend((0..bands).map(|b| (s[b] * refl[b] * grid.step_nm) as f32));
            }
        }
        Ok(SpectralResponse {
            bands,
            regions,
            kernel,
        })
    }

    /// Number of regions (patches + background).
    pub fn regions(&self) -> usize {
        self.regions
    }

    /// The raw (R, G, B) of every region under `light` (one value per band), into `out`.
    pub fn raw_into(&self, light: &[f32], out: &mut Vec<[f32; 3]>) {
        debug_assert_eq!(light.len(), self.bands);
        out.clear();
        out.extend(self.kernel.chunks_exact(3 * self.bands).map(|region| {
            let mut rgb = [0.0f32; 3];
            for (c, row) in region.chunks_exact(self.bands).enumerate() {
                rgb[c] = dot(row, light);
            }
            rgb
        }));
    }
}

/// A dot product written so the compiler vectorises it (eight independent accumulators).
#[inline]
fn dot(a: &[f32], b: &[f32]) -> f32 {
    let mut acc = [0.0f32; 8];
    let (a8, b8) = (a.chunks_exact(8), b.chunks_exact(8));
    let tail: f32 = a8
        .remainder()
        .iter()
        .zip(b8.remainder())
        .map(|(x, y)| x * y)
        .sum();
    for (x, y) in a8.zip(b8) {
        for j in 0..8 {
            acc[j] += x[j] * y[j];
        }
    }
    acc.iter().sum::<f32>() + tail
}

/// Automatic exposure, as a JPEG camera meters: the mean green raw value of the chart's
/// patches is brought to `target` of full scale; raw values above full scale then clip
/// (the sensor saturates).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AutoExposure {
    /// The metered level, a fraction of full scale.
    pub target: f64,
}

impl AutoExposure {
    /// The exposure scale for the first `patches` regions of `raw`; `None` when they have
    /// no green signal.
    pub fn scale(&self, raw: &[[f32; 3]], patches: usize) -> Option<f32> {
        let green = super::patch_mean(raw, patches)[1];
        (green > 0.0).then(|| self.target as f32 / green)
    }
}

/// The exposure scale: maps the brightest visible raw value to `exposure` of full scale.
pub fn exposure_scale(raw: &[[f32; 3]], shows_background: bool, exposure: f64) -> f32 {
    let visible = if shows_background {
        raw
    } else {
        &raw[..raw.len() - 1]
    };
    let max = visible.iter().flatten().cloned().fold(0.0f32, f32::max);
    if max > 0.0 {
        exposure as f32 / max
    } else {
        0.0
    }
}

/// Fills the mosaic: each pixel takes its region's value of the channel its filter passes.
pub fn form_mosaic(region_map: &[u16], region_rgb: &[[f32; 3]], mosaic: &mut Mosaic) {
    let (w, pattern) = (mosaic.width, mosaic.pattern);
    for (y, (row, map)) in mosaic
        .data
        .chunks_exact_mut(w)
        .zip(region_map.chunks_exact(w))
        .enumerate()
    {
        let (even, odd) = (pattern.channel_at(0, y), pattern.channel_at(1, y));
        for (x, (v, &r)) in row.iter_mut().zip(map).enumerate() {
            let c = if x & 1 == 0 { even } else { odd };
            *v = region_rgb[r as usize][c];
        }
    }
}

/// Fills the mosaic from a raw image of its size: each pixel takes the value of the channel
/// its filter passes, clipped at `full_scale`.
pub fn sample_mosaic(image: &RgbImage, full_scale: f32, mosaic: &mut Mosaic) {
    let (w, pattern) = (mosaic.width, mosaic.pattern);
    for (y, row) in mosaic.data.chunks_exact_mut(w).enumerate() {
        for (x, v) in row.iter_mut().enumerate() {
            *v = image.planes[pattern.channel_at(x, y)][y * w + x].min(full_scale);
        }
    }
}

/// Fills a three-sensor image: every pixel takes its region's full (R, G, B).
pub fn form_three_sensor(region_map: &[u16], region_rgb: &[[f32; 3]], image: &mut RgbImage) {
    for (c, plane) in image.planes.iter_mut().enumerate() {
        for (v, &r) in plane.iter_mut().zip(region_map) {
            *v = region_rgb[r as usize][c];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::chart::Layout;

    fn flat_camera(grid: &Grid) -> Sensitivities {
        let set = SpectralSet::on_grid(
            grid,
            vec!["r".into(), "g".into(), "b".into()],
            vec![
                vec![1.0; grid.count],
                vec![0.5; grid.count],
                vec![0.25; grid.count],
            ],
        )
        .unwrap();
        Sensitivities::new("flat", &set, grid).unwrap()
    }

    #[test]
    fn raw_response_is_the_hand_computed_integral() {
        let grid = Grid::new(400.0, 700.0, 10.0).unwrap();
        let refl = SpectralSet::on_grid(
            &grid,
            vec!["a".into(), "b".into()],
            vec![vec![0.5; grid.count], vec![0.2; grid.count]],
        )
        .unwrap();
        let chart = Chart::from_reflectances("t", &refl, 1, 2, &grid).unwrap();
        let response = SpectralResponse::new(&flat_camera(&grid), &chart, &grid).unwrap();
        let light = vec![2.0f32; grid.count];
        let mut raw = Vec::new();
        response.raw_into(&light, &mut raw);
        // Σ S·R·I·Δλ = 31 bands × 1.0 × 0.5 × 2 × 10 nm
        assert!((raw[0][0] - 310.0).abs() < 1e-3);
        assert!((raw[0][1] - 155.0).abs() < 1e-3);
        assert!((raw[1][2] - 31.0).abs() < 1e-3);
        assert!((raw[2][0] - 31.0 * 0.04 * 20.0).abs() < 1e-3);
        assert_eq!(exposure_scale(&raw, false, 1.0), 1.0 / 310.0);
    }

    #[test]
    fn mosaic_follows_the_filter_pattern() {
        let layout = Layout::grid(1, 1, 4, 0, 0);
        let map = layout.region_map();
        let rgb = [[1.0, 2.0, 3.0], [0.0; 3]];
        for pattern in CfaPattern::ALL {
            let mut m = Mosaic::new(4, 4, pattern);
            form_mosaic(&map, &rgb, &mut m);
            for y in 0..4 {
                for x in 0..4 {
                    assert_eq!(m.get(x, y), (pattern.channel_at(x, y) + 1) as f32);
                }
            }
        }
    }

    #[test]
    fn a_sampled_mosaic_matches_the_region_mosaic_and_clips_at_full_scale() {
        let layout = Layout::grid(2, 2, 3, 1, 1);
        let map = layout.region_map();
        let rgb = [
            [1.0, 2.0, 3.0],
            [0.5, 0.25, 0.125],
            [4.0, 5.0, 6.0],
            [0.1, 0.2, 0.3],
            [0.0, 0.01, 0.02],
        ];
        let mut image = RgbImage::new(layout.width, layout.height);
        form_three_sensor(&map, &rgb, &mut image);
        let mut from_regions = Mosaic::new(layout.width, layout.height, CfaPattern::Grbg);
        form_mosaic(&map, &rgb, &mut from_regions);
        let mut sampled = Mosaic::new(layout.width, layout.height, CfaPattern::Grbg);
        sample_mosaic(&image, f32::INFINITY, &mut sampled);
        assert_eq!(sampled.data, from_regions.data);
        sample_mosaic(&image, 1.0, &mut sampled);
        let clipped: Vec<f32> = from_regions.data.iter().map(|v| v.min(1.0)).collect();
        assert_eq!(sampled.data, clipped);
    }

    #[test]
    fn camera_coverage_is_checked() {
        let narrow = SpectralSet::from_csv_str(
            "wavelength_nm,r,g,b\n450,1,1,1\n500,1,1,1\n550,1,1,1\n",
            "narrow",
        )
        .unwrap();
        let e = Sensitivities::new("narrow", &narrow, &Grid::SIMULATION).unwrap_err();
        assert!(e.to_string().contains("400–700"), "{e}");
        let two =
            SpectralSet::from_csv_str("wavelength_nm,r,g\n400,1,1\n700,1,1\n", "two").unwrap();
        assert!(Sensitivities::new("two", &two, &Grid::SIMULATION).is_err());
    }
}
