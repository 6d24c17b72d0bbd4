//! The sim-to-real ablation (`spdcam sim2real`): a ridge regression from features to the
//! SPD (400–700 nm, 10 nm) is trained on virtual samples only, each step of the virtual
//! camera on or off, and scored (mean GFC) on the real measured sets; steps that use real
//! photos (calibration) are cross-validated: calibrated on a few photos outside the test
//! fold. [`curve`] measures the fine-tuning learning curve on the same sets.
//!
//! - [`ridge`]: the ridge's inputs and targets, trained on virtual or real photos, scored.
//! - [`curve`]: the learning curve of fine-tuning a virtual-trained model on real photos.

pub mod curve;
pub mod ridge;

use crate::error::Result;
use ridge::{real_to_real, score, train_virtual};
use spdcam_core::builtin::DataDir;
use spdcam_core::camera::in_camera::{fit_to_photos, InCamera};
use spdcam_core::camera::sensor::Sensitivities;
use spdcam_core::camera::{Camera, CameraConfig};
use spdcam_core::chart::{Chart, KnownChart};
use spdcam_core::dataset::randomise::{
    camera_pool, InCameraRanges, Randomisation, IN_CAMERA_AND_GRADIENT_GROUPS, IN_CAMERA_GROUPS,
};
use spdcam_core::dataset::{MeasuredPhotos, REAL_PHOTO_SETS};
use spdcam_core::light_families::Lighting;
use spdcam_core::spectral::Grid;
use spdcam_infer::ridge::Ridge;
use std::path::Path;

/// Training lights: the Telelumen configurations with some white LED and Planckian light.
pub const LIGHTING: &str =
    "mix:telelumen:config1=0.3,telelumen:config2=0.3,telelumen:config3=0.2,phosphor=0.1,planck=0.1";
/// The grid the virtual samples and the real sets' SPDs are on.
pub const GRID: Grid = Grid::SIMULATION;
/// The thesis's camera: the Canon 5D Mark II behind its BW486 filter.
pub const THESIS_CAMERA: &str = "canon_eos_5d_mark_ii_mod_bw486";
/// The real sets' camera as made: the Canon 5D Mark II's own curves.
pub const PLAIN_CAMERA: &str = "canon_eos_5d_mark_ii";
/// Perturbed copies of each camera in the randomised pool.
const POOL_VARIANTS: usize = 1;
/// Seed of the pool's perturbations.
const POOL_SEED: u64 = 11;
/// Nelder–Mead evaluations of each in-camera calibration.
const CALIBRATION_EVALUATIONS: usize = 2000;

/// One real photo set, named by its label.
pub struct RealSet {
    /// The set's label ([`REAL_PHOTO_SETS`]).
    pub label: &'static str,
    /// Its photos' features and measured SPDs on [`GRID`].
    pub photos: MeasuredPhotos,
}

/// Every real photo set of the thesis's data `thesis` (holding measured/…), on [`GRID`].
pub fn real_sets(thesis: &Path) -> Result<Vec<RealSet>> {
    REAL_PHOTO_SETS
        .iter()
        .map(|set| {
            Ok(RealSet {
                label: set.label,
                photos: set.load(thesis, &GRID)?,
            })
        })
        .collect()
}

/// `pool` with in-camera settings drawn from [`IN_CAMERA_GROUPS`], and with `gradient`
/// also the light's gradient across the chart ([`IN_CAMERA_AND_GRADIENT_GROUPS`]): the
/// randomisations of the ablation's rows.
pub fn randomised(pool: Vec<Camera>, gradient: bool) -> Result<Randomisation> {
    let groups: &[&str] = if gradient {
        &IN_CAMERA_AND_GRADIENT_GROUPS
    } else {
        &IN_CAMERA_GROUPS
    };
    Ok(Randomisation::new(
        pool,
        InCameraRanges::for_groups(groups)?,
    )?)
}

/// The virtual side of the experiment: the training lights, the cameras by name and the
/// domain-randomisation pool.
pub struct VirtualCameras {
    data_dir: DataDir,
    lighting: Lighting,
    /// The pool: every camera given and the plain camera, each with a perturbed copy.
    pool: Vec<Camera>,
}

impl VirtualCameras {
    /// Parses [`LIGHTING`] and builds the randomisation pool from `pool` (the data
    /// directory's cameras, say) and [`PLAIN_CAMERA`], each as measured and once perturbed,
    /// photographing the SG 96 chart noise-free.
    pub fn new(pool: &[Sensitivities], data_dir: &DataDir) -> Result<VirtualCameras> {
        let lighting = Lighting::parse(LIGHTING, data_dir, &GRID)?;
        let chart = Chart::resolve(KnownChart::Sg96.name(), None, data_dir, &GRID)?;
        let mut sens = pool.to_vec();
        sens.push(Sensitivities::resolve(PLAIN_CAMERA, data_dir, &GRID)?);
        let pool = camera_pool(&sens, POOL_VARIANTS, POOL_SEED, &chart, config(), &GRID)?;
        Ok(VirtualCameras {
            data_dir: data_dir.clone(),
            lighting,
            pool,
        })
    }

    /// The camera `camera` photographing `chart` noise-free, with the in-camera stage `ic`
    /// (none: the default rendering).
    pub fn camera(&self, camera: &str, chart: &str, ic: Option<InCamera>) -> Result<Camera> {
        let chart = Chart::resolve(chart, None, &self.data_dir, &GRID)?;
        let config = CameraConfig {
            in_camera: ic,
            ..config()
        };
        Ok(Camera::new(
            &Sensitivities::resolve(camera, &self.data_dir, &GRID)?,
            chart,
            config,
            &GRID,
        )?)
    }

    /// The plain camera photographing the SG 96 chart, with the in-camera stage `ic`.
    fn plain(&self, ic: Option<InCamera>) -> Result<Camera> {
        self.camera(PLAIN_CAMERA, KnownChart::Sg96.name(), ic)
    }

    /// How many cameras the pool holds.
    pub fn pool_size(&self) -> usize {
        self.pool.len()
    }

    /// The prior the fine-tuning curve's "ridge towards virtual" shrinks towards: ridge on
    /// `count` virtual samples of the randomised pool with in-camera stage and lighting
    /// gradient (penalty `ridge`).
    pub fn prior(&self, count: u64, ridge: f64) -> Result<Ridge> {
        let with_gradient = randomised(self.pool.clone(), true)?;
        train_virtual(
            &self.plain(None)?,
            Some(&with_gradient),
            &self.lighting,
            count,
            ridge,
        )
    }
}

/// The noise-free camera configuration every virtual camera uses.
fn config() -> CameraConfig {
    CameraConfig {
        noise: None,
        ..CameraConfig::default()
    }
}

/// How the ablation is measured.
#[derive(Debug, Clone, Copy)]
pub struct AblationOptions {
    /// Virtual training samples per model.
    pub count: u64,
    /// Real photos each calibration fits on.
    pub calibration_photos: usize,
    /// Cross-validation folds for the rows that use real photos (at least 2 are used).
    pub folds: usize,
    /// Ridge penalty (relative to the mean diagonal of XᵀX).
    pub ridge: f64,
}

/// One row of the ablation: what the virtual camera did, and the mean GFC on each set.
#[derive(Debug, Clone, PartialEq)]
pub struct AblationRow {
    /// The row's label.
    pub label: String,
    /// Mean GFC per real set, in the order of the sets.
    pub scores: Vec<f64>,
}

/// The ablation measured: a row per step of the virtual camera, a calibrated row and the
/// real-to-real reference.
#[derive(Debug, Clone)]
pub struct Ablation {
    /// The real sets' labels, the table's columns.
    pub sets: Vec<String>,
    /// The rows, in the table's order.
    pub rows: Vec<AblationRow>,
    /// The options measured with.
    pub options: AblationOptions,
}

impl Ablation {
    /// Measures the ablation on `sets`; `progress` hears each row's scores as it is
    /// measured, by its label (the calibrated row: `calibrated`; not the reference).
    pub fn measure(
        sets: &[RealSet],
        cameras: &VirtualCameras,
        options: &AblationOptions,
        progress: &mut dyn FnMut(&str, &[f64]),
    ) -> Result<Ablation> {
        let folds = options.folds.max(2);
        let sg = KnownChart::Sg96.name();
        let (lighting, count, penalty) = (&cameras.lighting, options.count, options.ridge);
        let in_camera_only = randomised(vec![cameras.plain(None)?], false)?;
        let pool = randomised(cameras.pool.clone(), false)?;
        let with_gradient = randomised(cameras.pool.clone(), true)?;

        let mut rows: Vec<AblationRow> = Vec::new();
        let all = |set: &MeasuredPhotos| (0..set.features.len()).collect::<Vec<usize>>();
        let mut fixed_row =
            |label: &str, camera: &Camera, r: Option<&Randomisation>| -> Result<()> {
                let model = train_virtual(camera, r, lighting, count, penalty)?;
                let scores = sets
                    .iter()
                    .map(|s| score(&model, &s.photos, &all(&s.photos)))
                    .collect::<Result<Vec<f64>>>()?;
                progress(label, &scores);
                rows.push(AblationRow {
                    label: label.to_string(),
                    scores,
                });
                Ok(())
            };
        fixed_row(
            "thesis camera (5D II + BW486, file patch order)",
            &cameras.camera(THESIS_CAMERA, KnownChart::Sg96Thesis.name(), None)?,
            None,
        )?;
        fixed_row(
            "+ physical patch order",
            &cameras.camera(THESIS_CAMERA, sg, None)?,
            None,
        )?;
        fixed_row("+ unmodified 5D II curves", &cameras.plain(None)?, None)?;
        fixed_row(
            "+ randomised in-camera stage (exposure, wb, tone, jpeg)",
            &cameras.plain(None)?,
            Some(&in_camera_only),
        )?;
        fixed_row(
            &format!(
                "+ randomised camera ({} curves incl. perturbed) and in-camera stage",
                cameras.pool_size()
            ),
            &cameras.plain(None)?,
            Some(&pool),
        )?;
        fixed_row(
            "+ uneven lighting across the chart (randomised gradient)",
            &cameras.plain(None)?,
            Some(&with_gradient),
        )?;
        // Calibrated: per fold, fit on a few photos outside the fold, test on the fold.
        let mut calibrated = Vec::new();
        for RealSet { photos: set, .. } in sets {
            let n = set.features.len();
            let base = cameras.plain(None)?;
            let mut total = 0.0;
            for f in 0..folds {
                let (test, rest): (Vec<usize>, Vec<usize>) = (0..n).partition(|i| i % folds == f);
                let step = (rest.len() / options.calibration_photos.max(1)).max(1);
                let pick: Vec<usize> = rest
                    .iter()
                    .step_by(step)
                    .take(options.calibration_photos)
                    .copied()
                    .collect();
                let fit = fit_to_photos(
                    &base,
                    &set.reference_photos(&pick),
                    InCamera::NEUTRAL,
                    CALIBRATION_EVALUATIONS,
                )?;
                let camera = cameras.plain(Some(fit.in_camera))?;
                let model = train_virtual(&camera, None, lighting, count, penalty)?;
                total += score(&model, set, &test)? * test.len() as f64;
            }
            calibrated.push(total / n as f64);
        }
        progress("calibrated", &calibrated);
        rows.push(AblationRow {
            label: format!(
                "+ in-camera stage calibrated on {} real photos (CV)",
                options.calibration_photos
            ),
            scores: calibrated,
        });
        let reference = sets
            .iter()
            .map(|s| real_to_real(&s.photos, folds))
            .collect::<Result<Vec<f64>>>()?;
        rows.push(AblationRow {
            label: format!(
                "reference: ridge trained on real photos ({folds}-fold CV, penalty by inner CV)"
            ),
            scores: reference,
        });
        Ok(Ablation {
            sets: sets.iter().map(|s| s.label.to_string()).collect(),
            rows,
            options: *options,
        })
    }

    /// The table as the Markdown `spdcam sim2real` writes, with how it was measured.
    pub fn markdown(&self) -> String {
        let mut md = String::from("| virtual camera (ridge on virtual data only, unless noted) | ");
        md += &self.sets.join(" | ");
        md += " |\n|---|";
        md += &"---:|".repeat(self.sets.len());
        md.push('\n');
        for AblationRow { label, scores } in &self.rows {
            md += &format!(
                "| {label} | {} |\n",
                scores
                    .iter()
                    .map(|s| format!("{s:.4}"))
                    .collect::<Vec<_>>()
                    .join(" | ")
            );
        }
        md += &format!(
            "\nMean GFC (400–700 nm, 10 nm). {} virtual samples per model, lighting `{LIGHTING}`, \
             noise-free patch-level camera, ridge λ = {} (relative) for the rows trained on virtual \
             data.\n",
            self.options.count, self.options.ridge
        );
        md
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_markdown_lays_out_a_row_per_step_and_a_column_per_set() {
        let ablation = Ablation {
            sets: vec!["A".into(), "B".into()],
            rows: vec![AblationRow {
                label: "step".into(),
                scores: vec![0.5, 0.87654],
            }],
            options: AblationOptions {
                count: 10,
                calibration_photos: 3,
                folds: 2,
                ridge: 0.01,
            },
        };
        let md = ablation.markdown();
        assert!(md.starts_with(
            "| virtual camera (ridge on virtual data only, unless noted) | A | B |\n|---|---:|---:|\n\
             | step | 0.5000 | 0.8765 |\n"
        ));
        assert!(md.contains("10 virtual samples per model"));
        assert!(md.contains("ridge λ = 0.01 (relative)"));
    }
}
