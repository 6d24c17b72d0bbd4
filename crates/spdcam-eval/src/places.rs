//! The light at several places, measured on rendered scenes of two to four charts (both
//! kinds, a tenth to a third of the photo's width, half of them tilted up to 60°), lit by
//! the split's lamps through its held-out cameras with the full camera chain, estimated by
//! the shipped models as a user's photo is: every chart found and none invented; each
//! chart's estimate against the same chart alone in a photo of its own (same light, size
//! and tilt); "the lights differ" said when the lamps differ and not when one lamp lights
//! every chart (at levels from a quarter to the full light, as shadows give); and the light
//! level between places against the true ratio. Validation lamps choose the threshold of
//! "the lights differ"; test lamps are only reported. Beside them, scenes whose first
//! chart is a ColorChecker 24 held in a ColorChecker Passport's open case
//! ([`spdcam_core::photo::pocket`]): the chart found, its other page never taken for a
//! chart, and the chart read as well as alone.

use crate::colour::lights::{lights, Light, LightSet};
use crate::colour::score::{ColourScore, LightColour};
use crate::error::{EvalError, Result};
use crate::held_out::{held_out_cameras, HeldOutCameras, LampFiles, GRID};
use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};
use rayon::prelude::*;
use spdcam_core::builtin::DataDir;
use spdcam_core::camera::sensor::Sensitivities;
use spdcam_core::camera::{Camera, CameraConfig};
use spdcam_core::chart::{Chart, KnownChart};
use spdcam_core::light_families::ValidationSplit;
use spdcam_core::photo::pocket::{page_camera, PassportPage};
use spdcam_core::photo::scene::{scene_layout, SceneOptions, Tilt, TiltAxis};
use spdcam_core::photo::scene_places::{photograph_places, PlaceTruth, ScenePlace};
use spdcam_core::photo::{quad_centre, quads_near, ChartTemplate};
use spdcam_core::seed;
use spdcam_core::spectral_error;
use spdcam_infer::places::LIGHTS_DIFFER_DUV;
use spdcam_infer::{Estimate, Estimator, InferError, PhotoOptions};
use std::path::PathBuf;

/// The photos' size: a phone photo reduced, the scale the trust scenes are judged at.
pub const PHOTO_SIZE: (usize, usize) = (1600, 1000);

/// The charts a scene is made of, as photos show them.
const CHARTS: [KnownChart; 2] = [KnownChart::ColorChecker24, KnownChart::Sg140];
/// The ColorChecker 24's index in [`CHARTS`], the chart a Passport holds.
const COLORCHECKER24: usize = 0;

/// Lights this far apart in Δu′v′ or more must be told apart; one light must not be.
pub const MUST_DIFFER_DUV: f64 = 0.01;

/// What the protocol reads and how many scenes it renders.
#[derive(Debug, Clone)]
pub struct PlacesOptions {
    /// The validation split (`spdcam lamps split`).
    pub split: PathBuf,
    /// The lamp library.
    pub library: LampFiles,
    /// Directory of the held-out cameras' CSVs; `None`: the data directory's cameras/.
    pub cameras: Option<PathBuf>,
    /// Scenes per part (validation lamps, test lamps).
    pub scenes: u64,
    /// Seed of the scenes.
    pub seed: u64,
}

/// One chart of a scene, scored.
#[derive(Debug, Clone, PartialEq)]
pub struct ChartOutcome {
    /// Its share of the photo's width.
    pub width: f64,
    /// Its tilt, degrees (0: face-on).
    pub tilt: f64,
    /// Its estimate in the scene (`None`: not found, or no estimate), and the same chart
    /// alone in a photo (`None`: not found there).
    pub in_scene: Option<Scored>,
    /// The same chart alone in a photo of its own.
    pub alone: Option<Scored>,
    /// Its true light level against the scene's first chart, and the estimate's.
    pub level: (f64, Option<f64>),
}

/// An estimate's shape and colour against the truth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scored {
    /// GFC on the estimate's wavelengths.
    pub gfc: f64,
    /// Δu′v′ of the estimate's light against the truth's.
    pub delta_uv: f64,
    /// The light's level in the photo's linear units ([`Estimate::light_level`]).
    pub light_level: Option<f64>,
}

/// One scene, scored.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneOutcome {
    /// Every chart, in the order placed.
    pub charts: Vec<ChartOutcome>,
    /// Detections that match no chart.
    pub invented: usize,
    /// One lamp lights every chart.
    pub one_light: bool,
    /// The largest true Δu′v′ between two charts' lights.
    pub true_spread: f64,
    /// The largest Δu′v′ between the places' estimates, when two or more were found.
    pub estimated_spread: Option<f64>,
    /// The largest Δu′v′ between the places' greys, when two or more were found and every
    /// one's greys were read.
    pub grey_spread: Option<f64>,
}

/// One scene with a ColorChecker Passport, scored.
#[derive(Debug, Clone, PartialEq)]
pub struct PocketOutcome {
    /// Places the photo gave that lie on no chart of the scene (the Passport's other page,
    /// or anything else taken for a chart) and were refused as not the chart: no estimate
    /// is made of them, but the user reads the refusal.
    pub refused: usize,
    /// Estimates that lie on no chart of the scene: invented.
    pub invented: usize,
    /// The Passport's chart in its case (`None`: not found or no estimate).
    pub in_case: Option<Scored>,
    /// The same chart in the same scene (seed, charts, lights, background) without the
    /// case.
    pub alone: Option<Scored>,
}

/// The outcomes of one part of the split.
#[derive(Debug, Clone, PartialEq)]
pub struct PartOutcome {
    /// The part's label.
    pub label: &'static str,
    /// Every scene.
    pub scenes: Vec<SceneOutcome>,
    /// Every scene with a Passport.
    pub pockets: Vec<PocketOutcome>,
}

/// The whole measurement.
#[derive(Debug, Clone, PartialEq)]
pub struct PlacesReport {
    /// Validation lamps, then test lamps.
    pub parts: Vec<PartOutcome>,
    /// The threshold the validation part chooses for "the lights differ".
    pub chosen_threshold: f64,
    /// The held-out cameras used.
    pub cameras: Vec<String>,
}

impl PlacesReport {
    /// Renders and scores the scenes of both parts (`progress` hears of each part).
    pub fn measure(
        options: &PlacesOptions,
        data_dir: &DataDir,
        progress: &mut dyn FnMut(&str),
    ) -> Result<PlacesReport> {
        if options.scenes == 0 {
            return Err(EvalError::invalid("--scenes must be at least 1"));
        }
        let split = ValidationSplit::read(&options.split)?;
        let library = options.library.read(data_dir, &GRID)?;
        let HeldOutCameras { cameras, skipped } =
            held_out_cameras(&split, options.cameras.as_deref(), data_dir)?;
        for s in &skipped {
            progress(&s.to_string());
        }
        let estimator =
            Estimator::shipped(data_dir.clone(), spdcam_core::spectral::Grid::ESTIMATION)?;
        let charts = CHARTS
            .iter()
            .map(|known| {
                let chart = known.chart(data_dir, &GRID)?;
                let template = ChartTemplate::from_chart(&chart)?;
                Ok(chart.with_layout(scene_layout(&template))?)
            })
            .collect::<Result<Vec<Chart>>>()?;
        let mut parts = Vec::new();
        for (k, set) in [LightSet::Validation, LightSet::Test]
            .into_iter()
            .enumerate()
        {
            progress(&format!("{}: {} scenes", set.label(), options.scenes));
            let lamps = lights(&library, &split, set)?;
            let part_seed = seed::derive(options.seed, k as u64);
            let scenes = (0..options.scenes)
                .into_par_iter()
                .map(|s| {
                    let scene_seed = seed::derive(part_seed, s);
                    score_scene(&estimator, &cameras, &charts, &lamps, scene_seed)
                })
                .collect::<Result<Vec<_>>>()?;
            let pockets = (0..options.scenes.div_ceil(2))
                .into_par_iter()
                .map(|s| {
                    let scene_seed = seed::derive(part_seed, options.scenes + s);
                    score_pocket(&estimator, &cameras, &charts, &lamps, scene_seed)
                })
                .collect::<Result<Vec<_>>>()?;
            parts.push(PartOutcome {
                label: set.label(),
                scenes,
                pockets,
            });
        }
        let chosen_threshold = choose_threshold(&parts[0].scenes);
        Ok(PlacesReport {
            parts,
            chosen_threshold,
            cameras: cameras.iter().map(|c| c.name.clone()).collect(),
        })
    }
}

/// One scene drawn from `seed`: two to four charts of either kind, one lamp for all (at
/// levels a quarter to the full light) or one each, through one held-out camera.
fn score_scene(
    estimator: &Estimator,
    cameras: &[Sensitivities],
    charts: &[Chart],
    lamps: &[Light],
    seed: u64,
) -> Result<SceneOutcome> {
    let mut rng = SmallRng::seed_from_u64(seed);
    let (_, cameras) = scene_cameras(&mut rng, cameras, charts)?;
    let options = photo_options();
    // Charts that cannot all be laid apart in the photo are drawn again.
    let mut attempt = 0;
    let (drawn, one_light, shot) = loop {
        let (drawn, one_light) = draw_charts(&mut rng, charts.len(), lamps.len());
        let places = scene_places(&drawn, &cameras, lamps);
        match photograph_places(&places, seed, &options) {
            Ok(shot) => break (drawn, one_light, shot),
            Err(_) if attempt < 20 => attempt += 1,
            Err(e) => return Err(e.into()),
        }
    };
    let places = scene_places(&drawn, &cameras, lamps);
    let estimates = found(estimator, &shot.jpeg);
    // Each truth's estimate: the detection whose centre lies on it.
    let mut matched = vec![false; estimates.len()];
    let mut charts_out = Vec::with_capacity(places.len());
    for (k, (place, truth)) in places.iter().zip(&shot.places).enumerate() {
        let hit = estimates.iter().position(|e| on_chart(e, truth));
        if let Some(i) = hit {
            matched[i] = true;
        }
        let light = &lamps[drawn[k].1];
        let in_scene = hit.map(|i| score(&estimates[i], light)).transpose()?;
        let alone_shot = photograph_places(
            std::slice::from_ref(place),
            seed::derive(seed, 1 + k as u64),
            &options,
        )?;
        let alone = found(estimator, &alone_shot.jpeg)
            .first()
            .map(|e| score(e, light))
            .transpose()?;
        charts_out.push(ChartOutcome {
            width: drawn[k].3,
            tilt: drawn[k].4.map_or(0.0, |t| t.degrees.abs()),
            in_scene,
            alone,
            level: (truth.relative_illuminance, None),
        });
    }
    let first_level = charts_out[0].in_scene.and_then(|s| s.light_level);
    for c in &mut charts_out {
        c.level.1 = match (c.in_scene.and_then(|s| s.light_level), first_level) {
            (Some(l), Some(f)) if f > 0.0 => Some(l / f),
            _ => None,
        };
    }
    let uv: Vec<[f64; 2]> = drawn
        .iter()
        .map(|d| LightColour::of(&lamps[d.1].spd).map(|c| c.uv_prime))
        .collect::<Result<_>>()?;
    Ok(SceneOutcome {
        charts: charts_out,
        invented: matched.iter().filter(|m| !**m).count(),
        one_light,
        true_spread: largest_distance(&uv),
        estimated_spread: estimates
            .first()
            .and_then(|e| e.across_places.as_ref())
            .map(|a| a.largest_delta_uv.2),
        grey_spread: estimates
            .first()
            .and_then(|e| e.across_places.as_ref())
            .and_then(|a| a.greys_largest_delta_uv)
            .map(|g| g.2),
    })
}

/// One scene drawn from `seed` as [`score_scene`] draws one, its first chart a
/// ColorChecker 24 (10–22 % of the width) held in a Passport's case, open beside one of
/// its other pages (drawn); scored for the Passport's chart against the same scene without
/// the case, and for the places the photo gives.
fn score_pocket(
    estimator: &Estimator,
    cameras: &[Sensitivities],
    charts: &[Chart],
    lamps: &[Light],
    seed: u64,
) -> Result<PocketOutcome> {
    let mut rng = SmallRng::seed_from_u64(seed);
    let (sensitivities, cameras) = scene_cameras(&mut rng, cameras, charts)?;
    let page = PassportPage::ALL[rng.random_range(0..PassportPage::ALL.len())];
    let page = page_camera(page, sensitivities, &cameras[COLORCHECKER24])?;
    let options = photo_options();
    let mut attempt = 0;
    let (drawn, shot) = loop {
        let (mut drawn, _) = draw_charts(&mut rng, charts.len(), lamps.len());
        drawn[0].0 = COLORCHECKER24;
        drawn[0].3 = rng.random_range(0.1..0.22);
        let mut places = scene_places(&drawn, &cameras, lamps);
        places[0].case = Some(&page);
        match photograph_places(&places, seed, &options) {
            Ok(shot) => break (drawn, shot),
            Err(_) if attempt < 40 => attempt += 1,
            Err(e) => return Err(e.into()),
        }
    };
    let photos = estimator.photo_bytes_places(&shot.jpeg, "scene.jpg", &PhotoOptions::default());
    // A refusal lies on no chart when the places found outnumber the charts found.
    let refusals = photos
        .iter()
        .filter(|p| matches!(&p.analysed, Err(InferError::NotTheChart(_))))
        .count();
    let estimates: Vec<Estimate> = photos
        .into_iter()
        .filter_map(|p| p.estimate.and_then(|e| e.ok()))
        .collect();
    let on_some_chart = |e: &Estimate| shot.places.iter().any(|t| on_chart(e, t));
    let invented = estimates.iter().filter(|e| !on_some_chart(e)).count();
    let estimated_charts = estimates.len() - invented;
    let refused = (estimated_charts + refusals)
        .saturating_sub(drawn.len())
        .min(refusals);
    let light = &lamps[drawn[0].1];
    let in_case = estimates
        .iter()
        .find(|e| on_chart(e, &shot.places[0]))
        .map(|e| score(e, light))
        .transpose()?;
    // The same scene (same seed, charts, lights and background) without the case.
    let uncased = photograph_places(&scene_places(&drawn, &cameras, lamps), seed, &options)?;
    let alone = found(estimator, &uncased.jpeg)
        .iter()
        .find(|e| on_chart(e, &uncased.places[0]))
        .map(|e| score(e, light))
        .transpose()?;
    Ok(PocketOutcome {
        refused,
        invented,
        in_case,
        alone,
    })
}

/// One of the held-out `cameras`, drawn, and it photographing each of `charts` with the
/// full camera chain.
fn scene_cameras<'a>(
    rng: &mut SmallRng,
    cameras: &'a [Sensitivities],
    charts: &[Chart],
) -> Result<(&'a Sensitivities, Vec<Camera>)> {
    let sensitivities = &cameras[rng.random_range(0..cameras.len())];
    let cameras = charts
        .iter()
        .map(|c| Camera::new(sensitivities, c.clone(), CameraConfig::default(), &GRID))
        .collect::<std::result::Result<_, _>>()?;
    Ok((sensitivities, cameras))
}

/// A scene photo's size; its lens and JPEG as [`SceneOptions`] draws them.
fn photo_options() -> SceneOptions {
    SceneOptions {
        width: PHOTO_SIZE.0,
        height: PHOTO_SIZE.1,
        ..SceneOptions::default()
    }
}

/// One chart drawn for a scene: its chart (index into the charts), lamp, level, share of the
/// photo's width and tilt.
type Drawn = (usize, usize, f64, f64, Option<Tilt>);

/// Two to four charts of `charts` kinds under `lamps`: one lamp for every chart (the others
/// at 25–100 % of the first's level) or one each; and whether one lamp lights them all.
fn draw_charts(rng: &mut SmallRng, charts: usize, lamps: usize) -> (Vec<Drawn>, bool) {
    let count = rng.random_range(2..=4usize);
    let one_light = rng.random_bool(0.5);
    let first = rng.random_range(0..lamps);
    let drawn = (0..count)
        .map(|k| {
            let lamp = if one_light || k == 0 {
                first
            } else {
                rng.random_range(0..lamps)
            };
            let level = if one_light && k > 0 {
                rng.random_range(0.25..1.0)
            } else {
                1.0
            };
            let width = rng.random_range(0.1..0.3);
            let tilt = rng.random_bool(0.5).then(|| Tilt {
                degrees: rng.random_range(-60.0..60.0),
                axis: if rng.random_bool(0.5) {
                    TiltAxis::Vertical
                } else {
                    TiltAxis::Horizontal
                },
            });
            (rng.random_range(0..charts), lamp, level, width, tilt)
        })
        .collect();
    (drawn, one_light)
}

/// The scene's charts as [`photograph_places`] takes them.
fn scene_places<'a>(
    drawn: &[Drawn],
    cameras: &'a [Camera],
    lamps: &'a [Light],
) -> Vec<ScenePlace<'a>> {
    drawn
        .iter()
        .map(|&(chart, lamp, level, width, tilt)| ScenePlace {
            camera: &cameras[chart],
            light: &lamps[lamp].spd,
            level,
            placing: SceneOptions {
                width_share: (width, width),
                tilt,
                perspective: 0.05,
                ..SceneOptions::default()
            },
            case: None,
        })
        .collect()
}

/// The estimates of every chart found in a JPEG (none when the photo gives none).
fn found(estimator: &Estimator, jpeg: &[u8]) -> Vec<Estimate> {
    estimator
        .photo_bytes_places(jpeg, "scene.jpg", &PhotoOptions::default())
        .into_iter()
        .filter_map(|p| p.estimate.and_then(|e| e.ok()))
        .collect()
}

/// Whether an estimate's chart lies on the chart `truth` (its centre inside the truth's
/// patch grid).
fn on_chart(estimate: &Estimate, truth: &PlaceTruth) -> bool {
    estimate.photo.as_ref().is_some_and(|p| {
        let c = quad_centre(&p.corners);
        quads_near(&truth.corners, &[c, c, c, c], 0.0)
    })
}

/// `estimate` of `light` scored.
fn score(estimate: &Estimate, light: &Light) -> Result<Scored> {
    let truth = light
        .spd
        .resampled(estimate.spd.grid())?
        .normalised_by_max();
    Ok(Scored {
        gfc: spectral_error::gfc_spd(&truth, &estimate.spd.normalised_by_max())?,
        delta_uv: ColourScore::of(&light.spd, &estimate.spd)?.delta_uv_prime,
        light_level: estimate.light_level.as_ref().map(|l| l.level),
    })
}

/// The largest distance between two of `points`.
fn largest_distance(points: &[[f64; 2]]) -> f64 {
    let mut out = 0.0f64;
    for (i, a) in points.iter().enumerate() {
        for b in &points[i + 1..] {
            out = out.max((a[0] - b[0]).hypot(a[1] - b[1]));
        }
    }
    out
}

/// Of the scenes that must be told apart (lights ≥ [`MUST_DIFFER_DUV`] apart) and those
/// that must not (one light), the shares told right at `threshold`: (said where they
/// differ, not said where one light).
pub fn told_right(scenes: &[SceneOutcome], threshold: f64) -> (f64, f64) {
    let share = |must_differ: bool| {
        let judged: Vec<bool> = scenes
            .iter()
            .filter(|s| {
                if must_differ {
                    !s.one_light && s.true_spread >= MUST_DIFFER_DUV
                } else {
                    s.one_light
                }
            })
            .map(|s| {
                s.grey_spread
                    .or(s.estimated_spread)
                    .is_some_and(|d| d > threshold)
                    == must_differ
            })
            .collect();
        judged.iter().filter(|r| **r).count() as f64 / judged.len().max(1) as f64
    };
    (share(true), share(false))
}

/// The threshold between 0.001 and 0.010 (steps of 0.0005) that tells the most scenes
/// right in the worse of the two directions ([`told_right`]); of several as good, the
/// middle one (the farthest from both kinds of mistake).
pub fn choose_threshold(scenes: &[SceneOutcome]) -> f64 {
    let scored: Vec<(f64, f64)> = (2..=20)
        .map(|k| f64::from(k) * 0.0005)
        .map(|t| {
            let (a, b) = told_right(scenes, t);
            (t, a.min(b))
        })
        .collect();
    let best = scored.iter().map(|s| s.1).fold(f64::NEG_INFINITY, f64::max);
    let tied: Vec<f64> = scored
        .iter()
        .filter(|s| s.1 >= best - 1e-12)
        .map(|s| s.0)
        .collect();
    tied[tied.len() / 2]
}

/// The median of `values` (`NaN` when empty).
fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    match values.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => values[n / 2],
        n => 0.5 * (values[n / 2 - 1] + values[n / 2]),
    }
}

impl PlacesReport {
    /// The report as Markdown: per part, charts found and invented, the estimates in the
    /// scene beside the same charts alone, the lights told apart, the light levels.
    pub fn markdown(&self, command: &str) -> String {
        let mut out = String::from(
            "# The light at several places: rendered scenes of two to four charts\n\n",
        );
        out += &format!(
            "Made by `{command}`. Scenes of {}×{} px, two to four charts each (ColorChecker 24 \
             or Digital SG, 10–30 % of the width, half of them tilted up to 60°), one lamp of \
             the split for every chart (the others at 25–100 % of the first's level) or one \
             each, photographed by one of the split's {} held-out cameras with the full camera \
             chain (mosaic, noise, demosaicing, white balance, tone, JPEG); estimated by the \
             shipped models as `spdcam estimate` does. Each chart is also photographed alone \
             (same light, size and tilt) and estimated: the single-chart accuracy it is \
             judged against. The threshold of \"the lights differ\" is chosen on the \
             validation lamps ({:.4}; shipped: {LIGHTS_DIFFER_DUV}); the test lamps are only \
             reported.\n\n",
            PHOTO_SIZE.0,
            PHOTO_SIZE.1,
            self.cameras.len(),
            self.chosen_threshold
        );
        out += "| lamps | scenes | charts | found | invented | median GFC in the scene · alone | median Δu′v′ in the scene · alone | \"lights differ\" said where they differ by ≥ 0.01 | not said under one light | light level within ±5 % (one light) | median level error |\n";
        out += "|---|---|---|---|---|---|---|---|---|---|---|\n";
        for part in &self.parts {
            let charts: Vec<&ChartOutcome> = part.scenes.iter().flat_map(|s| &s.charts).collect();
            let found = charts.iter().filter(|c| c.in_scene.is_some()).count();
            let invented: usize = part.scenes.iter().map(|s| s.invented).sum();
            // Charts estimated both ways: the pairs compared.
            let both: Vec<(Scored, Scored)> = charts
                .iter()
                .filter_map(|c| Some((c.in_scene?, c.alone?)))
                .collect();
            let gfc = |pick: fn(&(Scored, Scored)) -> f64| median(both.iter().map(pick).collect());
            let (differ, same) = told_right(&part.scenes, LIGHTS_DIFFER_DUV);
            let must: usize = part
                .scenes
                .iter()
                .filter(|s| !s.one_light && s.true_spread >= MUST_DIFFER_DUV)
                .count();
            let single: usize = part.scenes.iter().filter(|s| s.one_light).count();
            let levels: Vec<f64> = part
                .scenes
                .iter()
                .filter(|s| s.one_light)
                .flat_map(|s| s.charts.iter().skip(1))
                .filter_map(|c| Some(c.level.1? / c.level.0 - 1.0))
                .collect();
            let within = levels.iter().filter(|e| e.abs() <= 0.05).count();
            out += &format!(
                "| {} | {} | {} | {} ({:.1} %) | {} | {:.4} · {:.4} | {:.4} · {:.4} | {:.0} % of {must} | {:.0} % of {single} | {within} of {} | {:.1} % |\n",
                part.label,
                part.scenes.len(),
                charts.len(),
                found,
                100.0 * found as f64 / charts.len().max(1) as f64,
                invented,
                gfc(|p| p.0.gfc),
                gfc(|p| p.1.gfc),
                gfc(|p| p.0.delta_uv),
                gfc(|p| p.1.delta_uv),
                100.0 * differ,
                100.0 * same,
                levels.len(),
                100.0 * median(levels.iter().map(|e| e.abs()).collect()),
            );
        }
        out += "\nWhat the verdict rests on: the largest Δu′v′ between two places' greys (as the \
                photo shows them) and between their estimates, under one light and under lights \
                at least 0.01 apart.\n\n";
        out += "| lamps | one light: greys (median · largest) | one light: estimates (median · largest) | lights ≥ 0.01 apart: greys (smallest · median) | lights ≥ 0.01 apart: estimates (smallest · median) |\n|---|---|---|---|---|\n";
        for part in &self.parts {
            let spread = |one: bool, pick: fn(&SceneOutcome) -> Option<f64>| -> Vec<f64> {
                let mut v: Vec<f64> = part
                    .scenes
                    .iter()
                    .filter(|s| {
                        if one {
                            s.one_light
                        } else {
                            !s.one_light && s.true_spread >= MUST_DIFFER_DUV
                        }
                    })
                    .filter_map(pick)
                    .collect();
                v.sort_by(f64::total_cmp);
                v
            };
            // Under one light the median and the largest spread; apart the smallest and
            // the median (each list sorted).
            let median_largest = |v: Vec<f64>| {
                let largest = v.last().copied().unwrap_or(f64::NAN);
                format!("{:.4} · {largest:.4}", median(v))
            };
            let smallest_median = |v: Vec<f64>| {
                let smallest = v.first().copied().unwrap_or(f64::NAN);
                format!("{smallest:.4} · {:.4}", median(v))
            };
            out += &format!(
                "| {} | {} | {} | {} | {} |\n",
                part.label,
                median_largest(spread(true, |s| s.grey_spread)),
                median_largest(spread(true, |s| s.estimated_spread)),
                smallest_median(spread(false, |s| s.grey_spread)),
                smallest_median(spread(false, |s| s.estimated_spread)),
            );
        }
        out += "\nA ColorChecker 24 held in a ColorChecker Passport's open case, beside its other \
                page (the creative enhancement page or the white balance grey, drawn), as the \
                first chart of a scene drawn as above (10–22 % of the width): the Passport's \
                chart found; places beyond the scene's charts (the other page or anything \
                else taken for a chart) refused as not the chart (no estimate is made of \
                them, but the refusal is printed) and estimated (invented); and the chart \
                in its case against the same chart in the same scene without the case.\n\n";
        out += "| lamps | scenes | Passports found | places beyond the charts: refused · estimated | median GFC in the case · without | median Δu′v′ in the case · without |\n|---|---|---|---|---|---|\n";
        for part in &self.parts {
            let pockets = &part.pockets;
            let found = pockets.iter().filter(|p| p.in_case.is_some()).count();
            let refused: usize = pockets.iter().map(|p| p.refused).sum();
            let invented: usize = pockets.iter().map(|p| p.invented).sum();
            let both: Vec<(Scored, Scored)> = pockets
                .iter()
                .filter_map(|p| Some((p.in_case?, p.alone?)))
                .collect();
            let med = |pick: fn(&(Scored, Scored)) -> f64| median(both.iter().map(pick).collect());
            out += &format!(
                "| {} | {} | {found} of {} | {refused} · {invented} | {:.4} · {:.4} | {:.4} · {:.4} |\n",
                part.label,
                pockets.len(),
                pockets.len(),
                med(|p| p.0.gfc),
                med(|p| p.1.gfc),
                med(|p| p.0.delta_uv),
                med(|p| p.1.delta_uv),
            );
        }
        out += "\nBy chart size (both parts): found, and median Δu′v′ in the scene · alone.\n\n";
        out += "| width of the photo | charts | found | median Δu′v′ in the scene · alone |\n|---|---|---|---|\n";
        for (lo, hi) in [(0.1, 0.15), (0.15, 0.2), (0.2, 0.3)] {
            let charts: Vec<&ChartOutcome> = self
                .parts
                .iter()
                .flat_map(|p| &p.scenes)
                .flat_map(|s| &s.charts)
                .filter(|c| c.width >= lo && c.width < hi)
                .collect();
            let found = charts.iter().filter(|c| c.in_scene.is_some()).count();
            let pairs: Vec<(f64, f64)> = charts
                .iter()
                .filter_map(|c| Some((c.in_scene?.delta_uv, c.alone?.delta_uv)))
                .collect();
            out += &format!(
                "| {:.0}–{:.0} % | {} | {} | {:.4} · {:.4} |\n",
                100.0 * lo,
                100.0 * hi,
                charts.len(),
                found,
                median(pairs.iter().map(|p| p.0).collect()),
                median(pairs.iter().map(|p| p.1).collect()),
            );
        }
        out
    }
}
