//! A model's light-kind priors (`spdcam light-kinds fit`, [`spdcam_infer::kind_prior`]): per
//! kind of light, particles drawn from the kind's lighting recipe and the model's residuals
//! on photos of other lights of the kind, taken by the split's *training* cameras with the
//! randomised in-camera stage (the held-out cameras stay unseen for the protocols that
//! measure the priors, `spdcam experiment colour --light named`).
//!
//! Before the final priors are made from every residual photo, each kind's prior is fitted
//! on the even-numbered photos and tried on the odd-numbered ones; [`KindCheck`] is what
//! that trial measured, in distribution (training cameras, the kind's own recipe).

use crate::colour::{median, ColourScore};
use crate::error::{EvalError, Result};
use crate::held_out::{in_data_dir, training_cameras, SkippedCamera, GRID};
use crate::lamp_validation::randomised_rows;
use rayon::prelude::*;
use spdcam_core::builtin::DataDir;
use spdcam_core::chart::Chart;
use spdcam_core::dataset::REAL_PHOTO_SETS;
use spdcam_core::light_families::{LightKind, Lighting, ValidationSplit};
use spdcam_core::spectral::{normalise_by_max, Grid, Spd};
use spdcam_core::{seed, spectral_error};
use spdcam_infer::colour_map::ColourMap;
use spdcam_infer::kind_prior::{KindPrior, KindPriors, FORMAT, VERSION};
use spdcam_infer::pca::{Components, Pca};
use spdcam_infer::Model;
use std::path::PathBuf;

/// The variance of every kind's particles the common basis keeps.
pub const BASIS_VARIANCE: f64 = 0.99995;

/// What `spdcam light-kinds fit` is given.
#[derive(Debug, Clone)]
pub struct KindFitOptions {
    /// The model's file.
    pub model: PathBuf,
    /// The validation split: its training cameras take the residual photos.
    pub split: PathBuf,
    /// Directory of camera sensitivity CSVs holding the split's training cameras; `None`:
    /// the data directory's cameras/.
    pub cameras: Option<PathBuf>,
    /// Particles per kind.
    pub particles: usize,
    /// Residual photos per kind (each of a fresh light of the kind).
    pub photos: usize,
    /// Seed of the draws.
    pub seed: u64,
}

/// One kind's prior tried on photos it was not fitted on.
#[derive(Debug, Clone, PartialEq)]
pub struct KindCheck {
    /// The kind.
    pub kind: LightKind,
    /// The worst GFC of a particle rebuilt from the basis (how much of the kind it keeps).
    pub worst_particle_gfc: f64,
    /// The estimates without and with the kind named (1 % called unlike it expected).
    pub told: Told,
}

/// Photos estimated without and with their kind named.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Told {
    /// Mean GFC of the model's estimates, then of the estimates told the kind.
    pub gfc: [f64; 2],
    /// Median Δu′v′ of the same two.
    pub delta_uv: [f64; 2],
    /// The share of the photos whose estimate is called unlike the kind.
    pub unlike: f64,
}

impl Told {
    /// The scores of the model's estimates `estimates` (on `grid`, peak 1) of lights
    /// `truths` (on `grid`), without and with `kind` named through `priors` (and the model's
    /// colour `map`, as `estimate --light` names it).
    fn of<'a>(
        kind: LightKind,
        priors: &KindPriors,
        map: Option<&ColourMap>,
        pairs: impl Iterator<Item = (&'a [f64], &'a [f64])>,
        grid: &Grid,
    ) -> Result<Told> {
        let mut gfc = [Vec::new(), Vec::new()];
        let mut delta_uv = [Vec::new(), Vec::new()];
        let mut unlike = Vec::new();
        for (truth, estimate) in pairs {
            unlike.push(f64::from(u8::from(priors.unlike(kind, estimate)?)));
            let truth_spd = Spd::new(*grid, truth.to_vec())?;
            let told = priors.told(kind, estimate, map)?;
            for (k, spd) in [estimate.to_vec(), told].into_iter().enumerate() {
                gfc[k].push(spectral_error::gfc(truth, &spd)?);
                let score = ColourScore::of(&truth_spd, &Spd::new(*grid, spd)?)?;
                delta_uv[k].push(score.delta_uv_prime);
            }
        }
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
        Ok(Told {
            gfc: [mean(&gfc[0]), mean(&gfc[1])],
            delta_uv: [median(delta_uv[0].clone()), median(delta_uv[1].clone())],
            unlike: mean(&unlike),
        })
    }

    /// `0.9500 → 0.9600 | 0.0100 → 0.0090 | 1.0 %`: the cells of a table row.
    fn cells(&self) -> String {
        format!(
            "{:.4} → {:.4} | {:.4} → {:.4} | {:.1} %",
            self.gfc[0],
            self.gfc[1],
            self.delta_uv[0],
            self.delta_uv[1],
            100.0 * self.unlike
        )
    }
}

/// A real photo set estimated without and with the kind of its light named.
#[derive(Debug, Clone, PartialEq)]
pub struct RealCheck {
    /// The set's label.
    pub set: &'static str,
    /// The kind of its light.
    pub kind: LightKind,
    /// Photos.
    pub photos: usize,
    /// The estimates, "don't know" then the kind named.
    pub told: Told,
}

/// The kind of light of a real photo set: the Philips Hue lamps are colour-mixing LED lamps,
/// the Telelumen a multi-channel luminaire.
fn real_set_kind(label: &str) -> LightKind {
    if label.contains("Hue") {
        LightKind::RgbLed
    } else {
        LightKind::Luminaire
    }
}

/// The real photo sets (`thesis/measured/` of the data directory: the development photos of
/// the Telelumen/Canon set and the train and validation photos of the others, never their
/// test photos) estimated by `model` without and with their kind named through `priors`.
pub fn real_checks(
    model: &Model,
    priors: &KindPriors,
    data_dir: &DataDir,
) -> Result<Vec<RealCheck>> {
    let thesis = in_data_dir(None, "thesis", data_dir)?;
    let grid = model.grid();
    REAL_PHOTO_SETS
        .iter()
        .map(|set| {
            let photos = set.load(&thesis, &GRID)?;
            let kind = real_set_kind(set.label);
            let rows: Vec<f64> = photos.features.iter().flatten().copied().collect();
            let estimates = model.estimate_rows(&rows)?;
            let truths = photos
                .spds
                .iter()
                .map(|t| Ok(t.resampled(&grid)?.normalised_by_max().into_values()))
                .collect::<Result<Vec<_>>>()?;
            let pairs = truths
                .iter()
                .map(Vec::as_slice)
                .zip(estimates.chunks(grid.count));
            Ok(RealCheck {
                set: set.label,
                kind,
                photos: photos.spds.len(),
                told: Told::of(
                    kind,
                    priors,
                    model.header().colour_map.as_ref(),
                    pairs,
                    &grid,
                )?,
            })
        })
        .collect()
}

/// The real sets' checks as a Markdown table.
pub fn real_markdown(checks: &[RealCheck]) -> String {
    let mut out = String::from(
        "| real photo set | kind named | photos | mean GFC: don't know → kind named | \
         median Δu′v′: don't know → kind named | called unlike the kind |\n\
         |---|---|---:|---:|---:|---:|\n",
    );
    for c in checks {
        out.push_str(&format!(
            "| {} | {} | {} | {} |\n",
            c.set,
            c.kind.name(),
            c.photos,
            c.told.cells()
        ));
    }
    out
}

/// The priors made and what their trial measured.
#[derive(Debug, Clone)]
pub struct KindFit {
    /// The priors, fitted on every residual photo.
    pub priors: KindPriors,
    /// Per kind, the trial on the odd-numbered photos.
    pub checks: Vec<KindCheck>,
    /// Training cameras left out (unreadable curves).
    pub skipped: Vec<SkippedCamera>,
    /// The model the priors are for.
    pub model: Model,
}

/// The lights of one kind: particles and photographed lights, on the model's grid (peak 1)
/// and, for the camera, on the simulation grid.
struct KindLights {
    particles: Vec<Vec<f64>>,
    photographed: Vec<Spd>,
}

impl KindFit {
    /// Fits the priors of every kind for the model of `options` (see the module's
    /// documentation); `progress` hears of each kind.
    pub fn fit(
        options: &KindFitOptions,
        data_dir: &DataDir,
        progress: &mut dyn FnMut(&str),
    ) -> Result<KindFit> {
        if options.particles < 2 || options.photos < 20 {
            return Err(EvalError::invalid(
                "--particles must be at least 2 and --photos at least 20",
            ));
        }
        let model = Model::load(&options.model)?;
        let chart_name = model.header().chart.clone().ok_or_else(|| {
            EvalError::invalid(format!(
                "{}: the model names no chart",
                options.model.display()
            ))
        })?;
        let chart = Chart::resolve(&chart_name, None, data_dir, &GRID)?;
        model.check_features(&chart.feature_names(), &chart_name)?;
        let split = ValidationSplit::read(&options.split)?;
        let cameras = training_cameras(&split, options.cameras.as_deref(), data_dir)?;
        let grid = model.grid();
        let kinds: Vec<LightKind> = LightKind::ALL
            .into_iter()
            .filter(|k| *k != LightKind::Unknown)
            .collect();

        let lights = kinds
            .iter()
            .enumerate()
            .map(|(j, &kind)| {
                kind_lights(
                    kind,
                    options,
                    seed::derive(options.seed, j as u64),
                    data_dir,
                    &grid,
                )
            })
            .collect::<Result<Vec<_>>>()?;
        let all: Vec<f64> = lights.iter().flat_map(|l| l.particles.concat()).collect();
        let basis = Pca::fit(&all, grid.count, Components::Variance(BASIS_VARIANCE))?;

        let mut priors = Vec::new();
        let mut checks = Vec::new();
        for (j, (&kind, light)) in kinds.iter().zip(&lights).enumerate() {
            progress(kind.name());
            let recipe = kind.recipe().unwrap_or_default();
            let particles: Vec<Vec<f64>> = light
                .particles
                .iter()
                .map(|p| rounded(&basis.project(p)))
                .collect();
            let worst_particle_gfc = light
                .particles
                .iter()
                .zip(&particles)
                .map(|(p, c)| spectral_error::gfc(p, &basis.reconstruct(c)).unwrap_or(0.0))
                .fold(1.0, f64::min);
            let photographed: Vec<&Spd> = light.photographed.iter().collect();
            let stream = seed::derive(options.seed, 100 + j as u64);
            let rows = randomised_rows(&cameras.cameras, &chart, &photographed, 1, stream)?;
            let estimates = model.estimate_rows(&rows)?;
            let truths: Vec<Vec<f64>> = light
                .photographed
                .iter()
                .map(|s| Ok(normalise_by_max(s.resampled(&grid)?.values())))
                .collect::<Result<_>>()?;
            let estimates: Vec<&[f64]> = estimates.chunks(grid.count).collect();
            let estimated: Vec<Vec<f64>> = estimates.iter().map(|e| basis.project(e)).collect();
            let truth: Vec<Vec<f64>> = truths.iter().map(|t| basis.project(t)).collect();
            let even = |v: &[Vec<f64>]| -> Vec<Vec<f64>> { v.iter().step_by(2).cloned().collect() };
            let trial = KindPrior::from_photos(
                kind,
                recipe,
                particles.clone(),
                &even(&estimated),
                &even(&truth),
            )?;
            let trial = KindPriors {
                format: FORMAT.into(),
                version: VERSION,
                model: model.fingerprint(),
                method: String::new(),
                basis: basis.clone(),
                kinds: vec![trial],
            };
            checks.push(check(
                kind,
                &trial,
                model.header().colour_map.as_ref(),
                &truths,
                &estimates,
                &grid,
                worst_particle_gfc,
            )?);
            priors.push(KindPrior::from_photos(
                kind, recipe, particles, &estimated, &truth,
            )?);
        }
        Ok(KindFit {
            priors: KindPriors {
                format: FORMAT.into(),
                version: VERSION,
                model: model.fingerprint(),
                method: format!(
                    "per kind, {} particles drawn from its lighting recipe and {} fresh lights of \
                     it photographed once each (patch level, randomised in-camera stage) by the \
                     {} training cameras of the split with seed {}; basis: PCA of every kind's \
                     particles ({} % of their variance); seed {}",
                    options.particles,
                    options.photos,
                    cameras.cameras.len(),
                    split.seed,
                    BASIS_VARIANCE * 100.0,
                    options.seed
                ),
                basis,
                kinds: priors,
            },
            checks,
            skipped: cameras.skipped,
            model,
        })
    }

    /// The trial as a Markdown table.
    pub fn markdown(&self) -> String {
        let mut out = String::from(
            "| kind | worst particle GFC in the basis | GFC: model → told the kind | \
             median Δu′v′: model → told the kind | called unlike the kind |\n\
             |---|---:|---:|---:|---:|\n",
        );
        for c in &self.checks {
            out.push_str(&format!(
                "| {} | {:.4} | {} |\n",
                c.kind.name(),
                c.worst_particle_gfc,
                c.told.cells()
            ));
        }
        out
    }
}

/// The particles and the photographed lights of `kind`, drawn from its recipe.
fn kind_lights(
    kind: LightKind,
    options: &KindFitOptions,
    stream: u64,
    data_dir: &DataDir,
    grid: &Grid,
) -> Result<KindLights> {
    let recipe = kind
        .recipe()
        .ok_or_else(|| EvalError::invalid("the unknown kind has no recipe"))?;
    let lighting = Lighting::parse(recipe, data_dir, &GRID)?;
    let draw = |i: usize| -> Result<Spd> { Ok(lighting.draw(stream, i as u64)?.spd) };
    let particles = (0..options.particles)
        .into_par_iter()
        .map(|i| Ok(normalise_by_max(draw(i)?.resampled(grid)?.values())))
        .collect::<Result<Vec<_>>>()?;
    let photographed = (0..options.photos)
        .into_par_iter()
        .map(|i| draw(options.particles + i))
        .collect::<Result<Vec<_>>>()?;
    Ok(KindLights {
        particles,
        photographed,
    })
}

/// The trial of `priors` (one kind's) on the odd-numbered photos, with the model's colour
/// `map` as `estimate --light` uses it.
fn check(
    kind: LightKind,
    priors: &KindPriors,
    map: Option<&ColourMap>,
    truths: &[Vec<f64>],
    estimates: &[&[f64]],
    grid: &Grid,
    worst_particle_gfc: f64,
) -> Result<KindCheck> {
    let odd = truths
        .iter()
        .map(Vec::as_slice)
        .zip(estimates.iter().copied())
        .skip(1)
        .step_by(2);
    Ok(KindCheck {
        kind,
        worst_particle_gfc,
        told: Told::of(kind, priors, map, odd, grid)?,
    })
}

/// `values` to five significant digits: the priors file stays small, the posterior unchanged
/// far below any GFC's resolution.
fn rounded(values: &[f64]) -> Vec<f64> {
    values
        .iter()
        .map(|&v| {
            if v == 0.0 || !v.is_finite() {
                return v;
            }
            let scale = 10f64.powi(4 - v.abs().log10().floor() as i32);
            (v * scale).round() / scale
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounding_keeps_five_significant_digits() {
        assert_eq!(
            rounded(&[0.123456789, -12345.6789, 0.0]),
            [0.12346, -12346.0, 0.0]
        );
    }
}
