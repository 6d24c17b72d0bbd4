//! The real-camera study: how far each way of estimating the light gets on the real photo
//! sets of the thesis (chapter 5), each number beside a constant guess and a ridge trained on
//! real photos of the same camera.
//!
//! Every set is split once, before any result is looked at, into the photos candidates are
//! *chosen* on (validation) and the photos they are *reported* on (test):
//!
//! - Telelumen by a Canon 5D IV (640 photos): a seeded shuffle ([`DEV_SPLIT_SEED`]), the
//!   first half validation, the second half test;
//! - Philips Hue by the same camera: its `train` file validation, its `val` file test;
//! - Telelumen by a Galaxy Tab S7: likewise (54 / 7 photos).
//!
//! Candidates trained on virtual photos only are the closed-form ridge of the sim-to-real
//! ablation (features ÷ their mean → the SPD at 400–700 nm / 10 nm) under a light prior and
//! a rendering ([`VirtualRecipe`]), the same ridge with each set's real features aligned
//! without labels to the virtual ones ([`Alignment`]), and any trained model file. The
//! simple things every number stands beside: the constant (the mean peak-normalised SPD of
//! the set's validation photos) and ridge trained on the validation photos themselves (its
//! penalty by 5-fold cross-validation). Scores: mean GFC and median Δu′v′ (CIE 1976 u′v′ of
//! the CIE 1931 2° observer over 400–700 nm) of the estimates against the measured SPDs.

use crate::error::{EvalError, Result};
use faer::{Mat, Side};
use rand::rngs::SmallRng;
use rand::seq::SliceRandom;
use rand::SeedableRng;
use spdcam_core::builtin::DataDir;
use spdcam_core::camera::sensor::Sensitivities;
use spdcam_core::camera::{Camera, CameraConfig};
use spdcam_core::chart::{Chart, KnownChart};
use spdcam_core::colorimetry::Observer;
use spdcam_core::dataset::randomise::RandomiseRequest;
use spdcam_core::dataset::{GenerateOptions, Generator, MeasuredPhotos, Pipeline};
use spdcam_core::light_families::Lighting;
use spdcam_core::quality::uv::xyz_to_uv1976;
use spdcam_core::spectral::Grid;
use spdcam_core::spectral_error;
use spdcam_infer::ridge::Ridge;
use spdcam_infer::Model;
use std::path::{Path, PathBuf};

/// Seed of the Telelumen/Canon set's validation/test shuffle.
pub const DEV_SPLIT_SEED: u64 = 26;

/// The grid every estimate is scored on: 400–700 nm at 10 nm (the measured sets' sampling).
pub fn score_grid() -> Grid {
    Grid::from_parts(400.0, 10.0, 31).expect("a valid grid")
}

/// One real photo set split into the photos candidates are chosen on and those reported.
#[derive(Debug, Clone)]
pub struct SplitSet {
    /// How tables name the set.
    pub label: &'static str,
    /// The photos candidates are chosen on (and unlabelled alignment is fitted on).
    pub val: MeasuredPhotos,
    /// The photos the study reports.
    pub test: MeasuredPhotos,
}

/// Reads the three real sets under `thesis` (the data directory's `thesis/`), split as the
/// module documentation says; SPDs on [`score_grid`].
pub fn split_sets(thesis: &Path) -> Result<Vec<SplitSet>> {
    split_sets_on(thesis, &score_grid())
}

/// As [`split_sets`], the SPDs on `grid` (the trust calibration's, a model's grid).
pub fn split_sets_on(thesis: &Path, grid: &Grid) -> Result<Vec<SplitSet>> {
    let read = |folder: &str| -> Result<MeasuredPhotos> {
        let dir = thesis.join("measured").join(folder);
        Ok(MeasuredPhotos::read(
            &dir.join("features.csv"),
            &dir.join("spds.csv"),
            grid,
        )?)
    };
    let dev = read("telelumen_canon5d4_dev")?;
    let mut order: Vec<usize> = (0..dev.features.len()).collect();
    order.shuffle(&mut SmallRng::seed_from_u64(DEV_SPLIT_SEED));
    let (val, test) = order.split_at(order.len() / 2);
    let pick = |rows: &[usize]| MeasuredPhotos {
        features: rows.iter().map(|&i| dev.features[i].clone()).collect(),
        spds: rows.iter().map(|&i| dev.spds[i].clone()).collect(),
    };
    Ok(vec![
        SplitSet {
            label: "Telelumen, Canon 5D IV",
            val: pick(val),
            test: pick(test),
        },
        SplitSet {
            label: "Philips Hue, Canon 5D IV",
            val: read("hue_canon5d4_train")?,
            test: read("hue_canon5d4_val")?,
        },
        SplitSet {
            label: "Telelumen, Galaxy Tab S7",
            val: read("telelumen_galaxy_tab_s7_train")?,
            test: read("telelumen_galaxy_tab_s7_val")?,
        },
    ])
}

/// The ridge's input row: the features divided by their mean (removing exposure), and a bias.
pub fn ridge_inputs(features: &[f64]) -> Vec<f64> {
    let mean = features.iter().sum::<f64>() / features.len() as f64;
    let mut x: Vec<f64> = features.iter().map(|v| v / mean.max(1e-9)).collect();
    x.push(1.0);
    x
}

/// The measured SPDs of `photos`, each normalised to a peak of 1.
pub fn targets(photos: &MeasuredPhotos) -> Vec<Vec<f64>> {
    photos
        .spds
        .iter()
        .map(|s| spdcam_core::spectral::normalise_by_max(s.values()))
        .collect()
}

/// Mean GFC and median Δu′v′ of a set of estimates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Score {
    /// Mean goodness-of-fit coefficient against the measured SPDs.
    pub gfc: f64,
    /// Median distance of the estimates' CIE 1976 u′v′ from the measured lights'.
    pub duv: f64,
}

/// Scores `estimates` (on [`score_grid`]) against `truths`.
pub fn score(truths: &[Vec<f64>], estimates: &[Vec<f64>]) -> Result<Score> {
    if truths.is_empty() || truths.len() != estimates.len() {
        return Err(EvalError::invalid(format!(
            "{} truths and {} estimates to score",
            truths.len(),
            estimates.len()
        )));
    }
    let observer = Observer::cie1931(&score_grid())?;
    let uv = |s: &[f64]| xyz_to_uv1976(observer.spd_to_xyz(s));
    let mut gfc = 0.0;
    let mut duv = Vec::with_capacity(truths.len());
    for (t, e) in truths.iter().zip(estimates) {
        gfc += spectral_error::gfc(t, e).unwrap_or(0.0);
        let (a, b) = (uv(t), uv(e));
        let d = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt();
        duv.push(if d.is_finite() { d } else { 1.0 });
    }
    duv.sort_by(f64::total_cmp);
    let n = duv.len();
    let median = if n % 2 == 1 {
        duv[n / 2]
    } else {
        0.5 * (duv[n / 2 - 1] + duv[n / 2])
    };
    Ok(Score {
        gfc: gfc / truths.len() as f64,
        duv: median,
    })
}

/// The constant guess: the mean peak-normalised SPD of `photos`.
pub fn constant(photos: &MeasuredPhotos) -> Vec<f64> {
    let t = targets(photos);
    let mut mean = vec![0.0; t[0].len()];
    for row in &t {
        for (m, v) in mean.iter_mut().zip(row) {
            *m += v / t.len() as f64;
        }
    }
    mean
}

/// Ridge trained on real photos (the penalty by 5-fold cross-validation on them).
pub fn real_ridge(photos: &MeasuredPhotos) -> Result<Ridge> {
    let x: Vec<Vec<f64>> = photos.features.iter().map(|f| ridge_inputs(f)).collect();
    Ok(Ridge::fit_cv(&x, &targets(photos), 5, None)?)
}

/// Estimates of a ridge for `features` rows (already through any alignment).
pub fn ridge_estimates(model: &Ridge, rows: &[Vec<f64>]) -> Vec<Vec<f64>> {
    rows.iter()
        .map(|f| model.predict_non_negative(&ridge_inputs(f)))
        .collect()
}

/// Estimates of a trained model file for `photos`, on [`score_grid`] (its grid must hold
/// every 10 nm point of 400–700 nm), each normalised to a peak of 1.
pub fn model_estimates(model: &Model, photos: &MeasuredPhotos) -> Result<Vec<Vec<f64>>> {
    let grid = model.grid();
    let at: Vec<usize> = score_grid()
        .wavelengths()
        .iter()
        .map(|&nm| {
            grid.index_of(nm).ok_or_else(|| {
                EvalError::invalid(format!("the model's grid {} lacks {nm} nm", grid.label()))
            })
        })
        .collect::<Result<_>>()?;
    let flat: Vec<f64> = photos.features.iter().flatten().copied().collect();
    let spds = model.estimate_rows(&flat)?;
    Ok(spds
        .chunks(grid.count)
        .map(|s| {
            spdcam_core::spectral::normalise_by_max(&at.iter().map(|&i| s[i]).collect::<Vec<_>>())
        })
        .collect())
}

/// How virtual training photos are made: a light prior and a rendering.
#[derive(Debug, Clone)]
pub struct VirtualRecipe {
    /// How tables name it.
    pub name: String,
    /// The lighting recipe (`spdcam generate --lighting`).
    pub lighting: String,
    /// The randomised groups (`spdcam generate --randomise`).
    pub groups: Vec<String>,
}

/// Where the virtual cameras come from.
#[derive(Debug, Clone)]
pub struct CameraSource {
    /// The measured data directory (cameras, lamps, the SG reflectances, the Telelumen).
    pub data_dir: DataDir,
    /// A directory of camera sensitivities for `camera` randomisation.
    pub cameras: PathBuf,
    /// A validation split whose held-out cameras stay out of the pool.
    pub camera_split: Option<PathBuf>,
}

/// Virtual photos of the ColorChecker Digital SG (96 centre patches, noise-free patch level)
/// made with `recipe`: their ridge inputs' features and SPDs (400–700 nm / 10 nm, peak 1).
pub fn virtual_photos(
    recipe: &VirtualRecipe,
    source: &CameraSource,
    count: u64,
    seed: u64,
) -> Result<MeasuredPhotosOwned> {
    let grid = Grid::SIMULATION;
    let data_dir = &source.data_dir;
    let chart = Chart::resolve(KnownChart::Sg96.name(), None, data_dir, &grid)?;
    let config = CameraConfig {
        noise: None,
        ..CameraConfig::default()
    };
    let base = Sensitivities::resolve("canon_eos_5d_mark_ii", data_dir, &grid)?;
    let camera = Camera::new(&base, chart.clone(), config, &grid)?;
    let request = RandomiseRequest {
        groups: recipe.groups.clone(),
        cameras: Some(source.cameras.display().to_string()),
        camera_split: source.camera_split.clone(),
        camera_variants: 1,
    };
    let (randomisation, _) = request.build(&base, &chart, config, seed, data_dir, &grid)?;
    let lighting = Lighting::parse(&recipe.lighting, data_dir, &grid)?;
    let mut options = GenerateOptions::new(count, seed);
    options.pipeline = Pipeline::Fast;
    let mut generator = Generator::new(&camera, &lighting, options)?;
    if let Some(r) = &randomisation {
        generator = generator.with_randomisation(r)?;
    }
    let batch = generator.samples(0..count, None, &|_| {})?;
    let at: Vec<usize> = score_grid()
        .wavelengths()
        .iter()
        .map(|&nm| {
            grid.index_of(nm)
                .expect("the simulation grid holds 400–700 nm")
        })
        .collect();
    Ok(MeasuredPhotosOwned {
        features: (0..batch.len())
            .map(|i| batch.features_of(i).to_vec())
            .collect(),
        targets: (0..batch.len())
            .map(|i| {
                let spd = batch.spd_of(i);
                spdcam_core::spectral::normalise_by_max(
                    &at.iter().map(|&k| spd[k]).collect::<Vec<_>>(),
                )
            })
            .collect(),
    })
}

/// Photos as feature rows and peak-normalised target SPDs on [`score_grid`].
#[derive(Debug, Clone)]
pub struct MeasuredPhotosOwned {
    /// Feature rows (0–255).
    pub features: Vec<Vec<f64>>,
    /// Target SPDs (400–700 nm / 10 nm, peak 1).
    pub targets: Vec<Vec<f64>>,
}

/// Ridge on virtual photos with a fixed relative penalty (strong shrinkage transfers best
/// from virtual to real photos: `docs/sim2real.md`).
pub fn virtual_ridge(photos: &MeasuredPhotosOwned, penalty: f64) -> Result<Ridge> {
    let x: Vec<Vec<f64>> = photos.features.iter().map(|f| ridge_inputs(f)).collect();
    Ok(Ridge::fit(&x, &photos.targets, penalty, None)?)
}

/// A map of one camera's real feature rows onto the virtual photos' statistics, fitted on
/// unlabelled photos of that camera (no SPDs): the domain adaptation a user with many
/// photos of one camera can have without measuring a single light.
#[derive(Debug, Clone)]
pub struct Alignment {
    /// Mean of the source (real) ridge inputs, without the bias.
    source_mean: Vec<f64>,
    /// Mean of the target (virtual) ridge inputs.
    target_mean: Vec<f64>,
    /// `C_s^{-1/2} C_t^{1/2}` (identity for a mean-only alignment).
    map: Option<Mat<f64>>,
}

impl Alignment {
    /// Shifts the real inputs' mean onto the virtual inputs' mean (each feature ÷ the row's
    /// mean, as the ridge sees them).
    pub fn mean_only(real: &[Vec<f64>], virtual_rows: &[Vec<f64>]) -> Alignment {
        Alignment {
            source_mean: column_mean(&normalised(real)),
            target_mean: column_mean(&normalised(virtual_rows)),
            map: None,
        }
    }

    /// CORAL (Sun, Feng & Saenko, "Return of frustratingly easy domain adaptation", AAAI
    /// 2016): whitens the real inputs with their covariance and recolours them with the
    /// virtual one, `x' = (x − μ_s) C_s^{-1/2} C_t^{1/2} + μ_t`; each covariance is
    /// regularised by `shrink` times its mean diagonal on the diagonal (the paper adds the
    /// identity), which also makes it invertible with fewer photos than features.
    pub fn coral(real: &[Vec<f64>], virtual_rows: &[Vec<f64>], shrink: f64) -> Result<Alignment> {
        let (s, t) = (normalised(real), normalised(virtual_rows));
        let (ms, mt) = (column_mean(&s), column_mean(&t));
        let cs = covariance(&s, &ms, shrink);
        let ct = covariance(&t, &mt, shrink);
        let map = matrix_power(&cs, -0.5)? * matrix_power(&ct, 0.5)?;
        Ok(Alignment {
            source_mean: ms,
            target_mean: mt,
            map: Some(map),
        })
    }

    /// `row` (0–255 features) mapped into the virtual domain, as features whose mean is 1
    /// (what [`ridge_inputs`] then leaves as they are).
    pub fn apply(&self, row: &[f64]) -> Vec<f64> {
        // The ridge's inputs; the zip below leaves their bias out.
        let x = ridge_inputs(row);
        let centred: Vec<f64> = x
            .iter()
            .zip(&self.source_mean)
            .map(|(a, m)| a - m)
            .collect();
        let moved: Vec<f64> = match &self.map {
            None => centred,
            Some(map) => (0..map.ncols())
                .map(|j| (0..map.nrows()).map(|i| centred[i] * map[(i, j)]).sum())
                .collect(),
        };
        moved
            .iter()
            .zip(&self.target_mean)
            .map(|(v, m)| (v + m).max(1e-6))
            .collect()
    }
}

/// Rows divided by their mean.
fn normalised(rows: &[Vec<f64>]) -> Vec<Vec<f64>> {
    rows.iter()
        .map(|r| {
            let mut x = ridge_inputs(r);
            x.pop();
            x
        })
        .collect()
}

fn column_mean(rows: &[Vec<f64>]) -> Vec<f64> {
    let d = rows[0].len();
    let mut m = vec![0.0; d];
    for r in rows {
        for (a, v) in m.iter_mut().zip(r) {
            *a += v / rows.len() as f64;
        }
    }
    m
}

/// The sample covariance of `rows` around `mean`, plus `shrink` × its mean diagonal on the
/// diagonal.
fn covariance(rows: &[Vec<f64>], mean: &[f64], shrink: f64) -> Mat<f64> {
    let d = mean.len();
    let centred = Mat::from_fn(rows.len(), d, |i, j| rows[i][j] - mean[j]);
    let mut c = centred.transpose() * &centred;
    let scale = 1.0 / (rows.len().max(2) - 1) as f64;
    let mut trace = 0.0;
    for i in 0..d {
        for j in 0..d {
            c[(i, j)] *= scale;
        }
        trace += c[(i, i)];
    }
    let add = shrink * trace / d as f64;
    for i in 0..d {
        c[(i, i)] += add.max(1e-12);
    }
    c
}

/// `c^p` of a symmetric positive-definite matrix by its eigendecomposition.
fn matrix_power(c: &Mat<f64>, p: f64) -> Result<Mat<f64>> {
    let eig = c
        .self_adjoint_eigen(Side::Lower)
        .map_err(|e| EvalError::invalid(format!("eigendecomposition failed: {e:?}")))?;
    let u = eig.U();
    let s = eig.S().column_vector();
    let d = c.nrows();
    let scaled = Mat::from_fn(d, d, |i, j| u[(i, j)] * s[j].max(1e-12).powf(p));
    Ok(scaled * u.transpose())
}

/// Label-free statistics of feature rows that tell how photos look (what item 1 of the
/// rendering is fitted to): the median over photos of the darkest patch channel over the
/// mean (flare and glare lift it), and of the grey-balance of the neutral patches (the
/// standard deviation of r/g/b of the brightest patch over their mean: how far white balance
/// left the white).
pub fn appearance(rows: &[Vec<f64>]) -> [f64; 2] {
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let dark = rows
        .iter()
        .map(|r| {
            let mean = r.iter().sum::<f64>() / r.len() as f64;
            r.iter().copied().fold(f64::INFINITY, f64::min) / mean.max(1e-9)
        })
        .collect();
    let cast = rows
        .iter()
        .map(|r| {
            let brightest = r
                .chunks(3)
                .max_by(|a, b| a.iter().sum::<f64>().total_cmp(&b.iter().sum::<f64>()))
                .expect("rows hold patches");
            let m = brightest.iter().sum::<f64>() / 3.0;
            (brightest.iter().map(|v| (v - m).powi(2)).sum::<f64>() / 3.0).sqrt() / m.max(1e-9)
        })
        .collect();
    [median(dark), median(cast)]
}

/// The light prior of the shipped models (README, "The shipped models"): two sources at
/// once from real-lamp families, daylight, Planckian light and the Telelumen.
pub const SHIPPED_PRIOR: &str = "blend:mix:lamp:phosphor-led=0.36,lamp:hybrid-led=0.06,lamp:mixed-led=0.14,lamp:fluorescent=0.1,lamp:hid=0.06,lamp:incandescent=0.04,planck=0.04,daylight=0.06,telelumen:config1=0.04,telelumen:config2=0.04,telelumen:config3=0.03,gaussian:7=0.03";

/// The union prior: multi-channel luminaires (the Telelumen set-ups), RGB(W) LED lamps
/// (`lamp:mixed-led`) and room lamps with daylight, about a third each.
pub const UNION_PRIOR: &str = "mix:telelumen:config1=0.1,telelumen:config2=0.1,telelumen:config3=0.1,lamp:mixed-led=0.25,lamp:phosphor-led=0.15,lamp:hybrid-led=0.04,lamp:fluorescent=0.06,lamp:hid=0.04,lamp:incandescent=0.03,planck=0.04,daylight=0.06,gaussian:7=0.03";

/// The rendering of the shipped models: every camera of the pool and the in-camera groups.
pub const SHIPPED_RENDERING: [&str; 6] = ["camera", "exposure", "wb", "tone", "jpeg", "gradient"];

/// The shipped rendering with white-balance adaptation drawn from none to full.
pub const WIDE_RENDERING: [&str; 6] = ["camera", "exposure", "wb-wide", "tone", "jpeg", "gradient"];

/// The virtual recipes the study compares, fixed before any result was seen: the shipped
/// prior, the Telelumen-heavy prior of the sim-to-real ablation, the union prior (single
/// lights and two at once), each with the shipped rendering, and the union prior with the
/// wide white balance.
pub fn recipes() -> Vec<VirtualRecipe> {
    let groups = |g: &[&str]| g.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    vec![
        VirtualRecipe {
            name: "shipped prior".into(),
            lighting: SHIPPED_PRIOR.into(),
            groups: groups(&SHIPPED_RENDERING),
        },
        VirtualRecipe {
            name: "Telelumen-heavy prior".into(),
            lighting: "mix:telelumen:config1=0.3,telelumen:config2=0.3,telelumen:config3=0.2,phosphor=0.1,planck=0.1".into(),
            groups: groups(&SHIPPED_RENDERING),
        },
        VirtualRecipe {
            name: "union prior".into(),
            lighting: UNION_PRIOR.into(),
            groups: groups(&SHIPPED_RENDERING),
        },
        VirtualRecipe {
            name: "union prior, two lights at once".into(),
            lighting: format!("blend:{UNION_PRIOR}"),
            groups: groups(&SHIPPED_RENDERING),
        },
        VirtualRecipe {
            name: "union prior, wide white balance".into(),
            lighting: UNION_PRIOR.into(),
            groups: groups(&WIDE_RENDERING),
        },
    ]
}

/// Scores of one way of estimating on every set: validation, test.
#[derive(Debug, Clone)]
pub struct Row {
    /// What the row is.
    pub name: String,
    /// Per set: (validation score, test score); `None` where the row is not scored on the
    /// validation photos (trained on them).
    pub scores: Vec<(Option<Score>, Score)>,
}

/// How the study aligns real photos to the virtual ones before a virtual ridge.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AlignmentKind {
    /// No alignment.
    None,
    /// [`Alignment::mean_only`].
    Mean,
    /// [`Alignment::coral`] with a shrinkage of 1 (the paper's identity, relative).
    Coral,
}

impl AlignmentKind {
    /// Every kind, in table order.
    pub const ALL: [AlignmentKind; 3] = [
        AlignmentKind::None,
        AlignmentKind::Mean,
        AlignmentKind::Coral,
    ];

    /// How tables name it.
    pub fn label(self) -> &'static str {
        match self {
            AlignmentKind::None => "",
            AlignmentKind::Mean => ", real means aligned (unlabelled)",
            AlignmentKind::Coral => ", CORAL-aligned (unlabelled)",
        }
    }
}

/// The rows of the simple things: the constant and ridge on the validation photos.
pub fn baseline_rows(sets: &[SplitSet]) -> Result<Vec<Row>> {
    let constant_row = sets
        .iter()
        .map(|s| {
            let c = constant(&s.val);
            let est = |n: usize| vec![c.clone(); n];
            Ok((
                Some(score(&targets(&s.val), &est(s.val.features.len()))?),
                score(&targets(&s.test), &est(s.test.features.len()))?,
            ))
        })
        .collect::<Result<Vec<_>>>()?;
    let ridge_row = sets
        .iter()
        .map(|s| {
            let model = real_ridge(&s.val)?;
            Ok((
                None,
                score(
                    &targets(&s.test),
                    &ridge_estimates(&model, &s.test.features),
                )?,
            ))
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(vec![
        Row {
            name: "constant: the mean SPD of the set's validation photos".into(),
            scores: constant_row,
        },
        Row {
            name: "ridge trained on the set's validation photos (real, labelled)".into(),
            scores: ridge_row,
        },
    ])
}

/// The row of a trained model file.
pub fn model_row(name: &str, model: &Model, sets: &[SplitSet]) -> Result<Row> {
    let scores = sets
        .iter()
        .map(|s| {
            Ok((
                Some(score(&targets(&s.val), &model_estimates(model, &s.val)?)?),
                score(&targets(&s.test), &model_estimates(model, &s.test)?)?,
            ))
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(Row {
        name: name.to_string(),
        scores,
    })
}

/// The rows of a ridge trained on `photos` (virtual), with each alignment of
/// [`AlignmentKind::ALL`]; the alignment of a set is fitted on its validation photos'
/// features alone.
pub fn virtual_rows(
    recipe_name: &str,
    photos: &MeasuredPhotosOwned,
    penalty: f64,
    sets: &[SplitSet],
) -> Result<Vec<Row>> {
    let model = virtual_ridge(photos, penalty)?;
    AlignmentKind::ALL
        .iter()
        .map(|&kind| {
            let scores = sets
                .iter()
                .map(|s| {
                    let align = match kind {
                        AlignmentKind::None => None,
                        AlignmentKind::Mean => {
                            Some(Alignment::mean_only(&s.val.features, &photos.features))
                        }
                        AlignmentKind::Coral => {
                            Some(Alignment::coral(&s.val.features, &photos.features, 1.0)?)
                        }
                    };
                    let rows = |p: &MeasuredPhotos| -> Vec<Vec<f64>> {
                        match &align {
                            None => p.features.clone(),
                            Some(a) => p.features.iter().map(|f| a.apply(f)).collect(),
                        }
                    };
                    Ok((
                        Some(score(
                            &targets(&s.val),
                            &ridge_estimates(&model, &rows(&s.val)),
                        )?),
                        score(&targets(&s.test), &ridge_estimates(&model, &rows(&s.test)))?,
                    ))
                })
                .collect::<Result<Vec<_>>>()?;
            Ok(Row {
                name: format!("ridge on virtual photos, {recipe_name}{}", kind.label()),
                scores,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_perfect_estimate_scores_one_and_no_colour_error() {
        let t = vec![vec![0.5; 31], (0..31).map(|k| k as f64 / 30.0).collect()];
        let s = score(&t, &t).unwrap();
        assert!((s.gfc - 1.0).abs() < 1e-12);
        assert!(s.duv < 1e-12);
    }

    #[test]
    fn a_colour_shift_shows_in_delta_uv() {
        // A flat light against one rising towards red: the GFC stays high while u′v′ moves.
        let flat = vec![vec![1.0; 31]];
        let warm = vec![(0..31)
            .map(|k| 0.7 + 0.3 * k as f64 / 30.0)
            .collect::<Vec<_>>()];
        let s = score(&flat, &warm).unwrap();
        assert!(s.gfc > 0.98, "{}", s.gfc);
        assert!(s.duv > 0.005, "{}", s.duv);
    }

    #[test]
    fn coral_maps_the_source_moments_onto_the_target() {
        // Source rows are a scaled, shifted copy of the target rows: CORAL undoes it.
        let target: Vec<Vec<f64>> = (0..200)
            .map(|i| {
                let a = (i as f64 * 0.37).sin();
                let b = (i as f64 * 0.11).cos();
                vec![10.0 + a, 10.0 + b, 10.0 + 0.5 * (a - b)]
            })
            .collect();
        let source: Vec<Vec<f64>> = target
            .iter()
            .map(|r| vec![r[0] * 1.0, 10.0 + 2.0 * (r[1] - 10.0), r[2]])
            .collect();
        let a = Alignment::coral(&source, &target, 1e-9).unwrap();
        let mapped: Vec<Vec<f64>> = source.iter().map(|r| a.apply(r)).collect();
        let want = normalised(&target);
        let (m1, m2) = (column_mean(&mapped), column_mean(&want));
        for j in 0..3 {
            assert!((m1[j] - m2[j]).abs() < 1e-9);
        }
        let (c1, c2) = (covariance(&mapped, &m1, 0.0), covariance(&want, &m2, 0.0));
        for i in 0..3 {
            for j in 0..3 {
                assert!((c1[(i, j)] - c2[(i, j)]).abs() < 1e-6, "{i},{j}");
            }
        }
    }

    #[test]
    fn the_constant_is_the_mean_of_the_peak_normalised_spds() {
        let grid = score_grid();
        let spd = |v: f64| spdcam_core::spectral::Spd::new(grid, vec![v; 31]).unwrap();
        let photos = MeasuredPhotos {
            features: vec![vec![1.0; 3]; 2],
            spds: vec![spd(2.0), spd(5.0)],
        };
        assert_eq!(constant(&photos), vec![1.0; 31]);
    }
}
