//! How often a chart is found, and how exactly: scene photos made by
//! [`scene::photograph`] with fixed seeds, one difficulty varied at a time (the chart's
//! size, its tilt, its rotation in its plane, a shadow over part of it), each searched for
//! among the given charts as `spdcam estimate` searches a photo. A photo counts as found
//! when the right chart is found with every corner within half a patch side of its true
//! place (so also the right way round); the corner error is the mean distance of the four
//! found corners from the true ones, over the patch side (the square root of a patch's
//! area in the photo, so a foreshortened patch's geometric-mean side).

use super::detect::detect;
use super::load::decode_photo;
use super::scene::{self, SceneLight, SceneOptions, ScenePhoto, Shadow, Tilt, TiltAxis};
use super::ChartTemplate;
use crate::camera::Camera;
use crate::cie_illuminant;
use crate::error::Result;
use crate::seed;
use crate::spectral::Grid;
use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};
use rayon::prelude::*;
use std::fmt::Write as _;

/// A corner farther than this share of a patch side from its true place is not found.
pub const FOUND_WITHIN: f64 = 0.5;

/// Which difficulty a bucket varies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Difficulty {
    /// The chart's width as a share of the photo's, face-on.
    Size,
    /// The chart's plane turned away from the camera.
    Tilt,
    /// Any rotation in the chart's plane, with some tilt.
    Rotation,
    /// A shadow over part of the chart.
    Shadow,
}

impl Difficulty {
    /// The difficulty's name in the table.
    pub fn label(self) -> &'static str {
        match self {
            Difficulty::Size => "size",
            Difficulty::Tilt => "tilt",
            Difficulty::Rotation => "rotation",
            Difficulty::Shadow => "shadow",
        }
    }
}

/// One bucket of scene photos: everything but the varied difficulty is drawn per photo
/// from its seed (position, light, blur, vignetting, JPEG quality, background).
#[derive(Debug, Clone, PartialEq)]
pub struct Bucket {
    /// What it varies.
    pub difficulty: Difficulty,
    /// Its value, as the table shows it.
    pub label: String,
    /// The patch grid's width as a share of the photo's width, face-on.
    pub width_share: f64,
    /// The tilt in degrees (its side and axis drawn per photo).
    pub tilt_deg: f64,
    /// Any in-plane rotation; else within ±10°.
    pub any_rotation: bool,
    /// The light left in a shadow over 30–60 % of the chart, from any side.
    pub shadow: Option<f64>,
}

/// The buckets of the protocol: sizes 1/4, 1/8, 1/12 and 1/15 of the width face-on; tilts
/// 0, 30, 50 and 70° at 1/4; any rotation at 1/6 and 30° tilt; shadows leaving 50 % and
/// 25 % of the light at 1/6.
pub fn buckets() -> Vec<Bucket> {
    let plain = |difficulty, label: String, width_share| Bucket {
        difficulty,
        label,
        width_share,
        tilt_deg: 0.0,
        any_rotation: false,
        shadow: None,
    };
    let mut out = Vec::new();
    for n in [4u32, 8, 12, 15] {
        out.push(plain(
            Difficulty::Size,
            format!("1/{n}"),
            1.0 / f64::from(n),
        ));
    }
    for tilt in [0.0, 30.0, 50.0, 70.0] {
        out.push(Bucket {
            tilt_deg: tilt,
            ..plain(Difficulty::Tilt, format!("{tilt:.0}°"), 0.25)
        });
    }
    out.push(Bucket {
        tilt_deg: 30.0,
        any_rotation: true,
        ..plain(Difficulty::Rotation, "any, 30° tilt".into(), 1.0 / 6.0)
    });
    for factor in [0.5, 0.25] {
        out.push(Bucket {
            shadow: Some(factor),
            ..plain(
                Difficulty::Shadow,
                format!("{:.0} % light", 100.0 * factor),
                1.0 / 6.0,
            )
        });
    }
    out
}

impl Bucket {
    /// The scene of photo `seed` in this bucket at `width × height`, and its light's
    /// colour temperature (K).
    pub fn scene(&self, seed: u64, width: usize, height: usize) -> (SceneOptions, f64) {
        let mut rng = SmallRng::seed_from_u64(seed);
        let rotation = if self.any_rotation {
            rng.random_range(0.0..360.0)
        } else {
            rng.random_range(-10.0..10.0)
        };
        let side = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
        let axis = if rng.random_bool(0.5) {
            TiltAxis::Horizontal
        } else {
            TiltAxis::Vertical
        };
        let shadow = self.shadow.map(|factor| Shadow {
            factor,
            cover: rng.random_range(0.3..0.6),
            direction_deg: rng.random_range(0.0..360.0),
        });
        let cct = rng.random_range(2700.0..6500.0);
        let options = SceneOptions {
            width,
            height,
            width_share: (self.width_share, self.width_share),
            perspective: 0.05,
            rotation_deg: Some(rotation),
            tilt: (self.tilt_deg > 0.0).then_some(Tilt {
                degrees: side * self.tilt_deg,
                axis,
            }),
            shadow,
            ..SceneOptions::default()
        };
        (options, cct)
    }
}

impl Bucket {
    /// Photo `seed` of this bucket at `width × height`, taken with `camera` under the
    /// scene's Planckian light: the photo [`measure`] searches, so that a miss can be
    /// looked at.
    pub fn photograph(
        &self,
        camera: &Camera,
        seed: u64,
        (width, height): (usize, usize),
    ) -> Result<ScenePhoto> {
        let (options, cct) = self.scene(seed, width, height);
        let spd = cie_illuminant::planck(cct, &Grid::SIMULATION)?;
        scene::photograph(camera, SceneLight::single(&spd), seed, &options)
    }
}

/// What one bucket gave for one chart.
#[derive(Debug, Clone, PartialEq)]
pub struct BucketRate {
    /// The chart photographed.
    pub chart: String,
    /// The bucket.
    pub bucket: Bucket,
    /// Photos made.
    pub photos: usize,
    /// Photos in which the chart was found.
    pub found: usize,
    /// Mean corner error of the found photos, as a share of a patch side.
    pub mean_corner_error: f64,
    /// Largest corner error of the found photos, as a share of a patch side.
    pub worst_corner_error: f64,
    /// Per photo not found: its seed and what happened.
    pub misses: Vec<(u64, String)>,
}

impl BucketRate {
    /// The share of photos found.
    pub fn rate(&self) -> f64 {
        self.found as f64 / self.photos.max(1) as f64
    }
}

/// Photographs `photos` scenes of `bucket` with `camera` (its chart laid out by
/// [`scene::scene_layout`]), seeds derived from `seed`, at `width × height`, and searches
/// each for `templates` (which must include the camera's chart).
pub fn measure(
    camera: &Camera,
    templates: &[ChartTemplate],
    bucket: &Bucket,
    photos: usize,
    seed: u64,
    (width, height): (usize, usize),
) -> Result<BucketRate> {
    let chart = camera.chart().name.clone();
    let outcomes: Vec<Result<(u64, std::result::Result<f64, String>)>> = (0..photos as u64)
        .into_par_iter()
        .map(|i| {
            let s = seed::derive(seed, i);
            let shot = bucket.photograph(camera, s, (width, height))?;
            let photo = decode_photo(&shot.jpeg, &format!("scene-{s}.jpg"))?;
            let outcome = match detect(&photo, templates) {
                Ok(d) if d.chart != chart => Err(format!("found {} instead", d.chart)),
                Ok(d) => {
                    let errors: Vec<f64> = (0..4)
                        .map(|k| {
                            (d.corners[k][0] - shot.corners[k][0])
                                .hypot(d.corners[k][1] - shot.corners[k][1])
                                / shot.patch_px
                        })
                        .collect();
                    let worst = errors.iter().copied().fold(0.0, f64::max);
                    if worst <= FOUND_WITHIN {
                        Ok(errors.iter().sum::<f64>() / 4.0)
                    } else {
                        Err(format!(
                            "placed wrongly: a corner {worst:.2} patch sides off (confidence {:.2})",
                            d.confidence
                        ))
                    }
                }
                Err(e) => Err(e.to_string()),
            };
            Ok((s, outcome))
        })
        .collect();
    let mut errors = Vec::new();
    let mut misses = Vec::new();
    for outcome in outcomes {
        match outcome? {
            (_, Ok(e)) => errors.push(e),
            (s, Err(why)) => misses.push((s, why)),
        }
    }
    Ok(BucketRate {
        chart,
        bucket: bucket.clone(),
        photos,
        found: errors.len(),
        mean_corner_error: errors.iter().sum::<f64>() / errors.len().max(1) as f64,
        worst_corner_error: errors.iter().copied().fold(0.0, f64::max),
        misses,
    })
}

/// The rates as a Markdown table, one row per bucket and a column pair per chart (in the
/// order the charts first appear in `rates`).
pub fn markdown_table(rates: &[BucketRate]) -> String {
    let mut charts: Vec<&str> = Vec::new();
    for r in rates {
        if !charts.contains(&r.chart.as_str()) {
            charts.push(&r.chart);
        }
    }
    let mut buckets: Vec<&Bucket> = Vec::new();
    for r in rates {
        if !buckets.contains(&&r.bucket) {
            buckets.push(&r.bucket);
        }
    }
    let mut out = String::from("| difficulty | bucket |");
    for c in &charts {
        let _ = write!(out, " {c}: found | {c}: corner error (mean / worst) |");
    }
    out.push_str("\n|---|---|");
    out.push_str(&"---:|---:|".repeat(charts.len()));
    out.push('\n');
    for b in buckets {
        let _ = write!(out, "| {} | {} |", b.difficulty.label(), b.label);
        for c in &charts {
            match rates.iter().find(|r| r.chart == *c && r.bucket == *b) {
                Some(r) if r.found == 0 => {
                    let _ = write!(out, " 0.0 % (0/{}) | – |", r.photos);
                }
                Some(r) => {
                    let _ = write!(
                        out,
                        " {:.1} % ({}/{}) | {:.1} % / {:.1} % |",
                        100.0 * r.rate(),
                        r.found,
                        r.photos,
                        100.0 * r.mean_corner_error,
                        100.0 * r.worst_corner_error
                    );
                }
                None => out.push_str(" – | – |"),
            }
        }
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn buckets_vary_one_difficulty_and_draw_the_rest_from_the_seed() {
        let all = buckets();
        let labels: Vec<String> = all
            .iter()
            .map(|b| format!("{} {}", b.difficulty.label(), b.label))
            .collect();
        assert_eq!(
            labels,
            [
                "size 1/4",
                "size 1/8",
                "size 1/12",
                "size 1/15",
                "tilt 0°",
                "tilt 30°",
                "tilt 50°",
                "tilt 70°",
                "rotation any, 30° tilt",
                "shadow 50 % light",
                "shadow 25 % light"
            ]
        );
        let tilted = &all[7];
        let (a, cct) = tilted.scene(3, 1600, 1200);
        assert_eq!(a.tilt.map(|t| t.degrees.abs()), Some(70.0));
        assert_eq!(a.width_share, (0.25, 0.25));
        assert!((2700.0..6500.0).contains(&cct));
        assert_eq!(tilted.scene(3, 1600, 1200).0, a, "the seed fixes the scene");
        assert!(all[0].scene(3, 1600, 1200).0.tilt.is_none());
    }
}
