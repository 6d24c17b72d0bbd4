//! The lamp validation's photos and scores: the held-out lamps photographed by the held-out
//! cameras through the randomised in-camera stage (a) and through the independent simple
//! camera (b), each model's mean GFC per lamp on them, and the average-SPD baseline.

use crate::error::Result;
use crate::held_out::{randomised_cameras, GRID};
use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};
use spdcam_core::camera::sensor::Sensitivities;
use spdcam_core::camera::Camera;
use spdcam_core::chart::Chart;
use spdcam_core::light_families::LampLibrary;
use spdcam_core::simple_camera::{Shot, SimpleCamera};
use spdcam_core::spectral::Spd;
use spdcam_core::{seed, spectral_error};
use spdcam_infer::Model;

/// Random stream of the simple camera's draws.
const SIMPLE_STREAM: u64 = 0x5349_4D50_4C45_0001;

/// Feature rows of the held-out lamps under one camera model: `shots` rows per lamp.
pub(crate) struct Photos {
    /// Row-major features, `lamps × shots` rows.
    features: Vec<f64>,
    width: usize,
}

/// The mean of the lamps `ids` of `spds`, normalised by its maximum: the estimate of a model
/// that knows nothing but the lamps it was fitted to, the baseline every score stands beside.
///
/// ```
/// use spdcam_eval::lamp_validation::average_spd;
///
/// let spds = [vec![2.0, 0.0], vec![9.0, 9.0], vec![2.0, 2.0]];
/// // The mean of the first and the last lamp, [2, 1], scaled to a peak of 1.
/// assert_eq!(average_spd(&spds, &[0, 2]), [1.0, 0.5]);
/// ```
pub fn average_spd(spds: &[Vec<f64>], ids: &[usize]) -> Vec<f64> {
    let d = spds[0].len();
    let sum: Vec<f64> = (0..d)
        .map(|k| ids.iter().map(|&i| spds[i][k]).sum::<f64>())
        .collect();
    spdcam_core::spectral::normalise_by_max(&sum)
}

/// (a): each lamp `shots` times through a held-out camera with the randomised in-camera stage.
pub(crate) fn pipeline_photos(
    cameras: &[Sensitivities],
    chart: &Chart,
    library: &LampLibrary,
    ids: &[usize],
    shots: u64,
    seed: u64,
) -> Result<Photos> {
    let lights: Vec<&Spd> = ids.iter().map(|&i| &library.spds[i]).collect();
    Ok(Photos {
        features: randomised_rows(cameras, chart, &lights, shots, seed)?,
        width: chart.feature_names().len(),
    })
}

/// Feature rows (row-major, `lights × shots` rows) of each of `lights` photographed `shots`
/// times, each by one of `cameras` with the randomised in-camera stage, patch level.
pub(crate) fn randomised_rows(
    cameras: &[Sensitivities],
    chart: &Chart,
    lights: &[&Spd],
    shots: u64,
    seed: u64,
) -> Result<Vec<f64>> {
    let randomisation = randomised_cameras(cameras, seed, chart)?;
    let width = chart.feature_names().len();
    let mut features = Vec::with_capacity(lights.len() * shots as usize * width);
    let (mut raw, mut out) = (Vec::new(), Vec::new());
    for (j, spd) in lights.iter().enumerate() {
        for k in 0..shots {
            let (camera, ic): (&Camera, _) = randomisation.draw(seed, j as u64 * shots + k);
            let light = camera.light(spd)?;
            out.clear();
            camera.features_fast_with(ic.as_ref(), &light, &mut raw, &mut out);
            features.extend(out.iter().map(|&v| f64::from(v)));
        }
    }
    Ok(features)
}

/// (b): each lamp `shots` times through the simple camera, camera and shot drawn at random.
pub(crate) fn simple_photos(
    cameras: &[Sensitivities],
    chart: &Chart,
    library: &LampLibrary,
    ids: &[usize],
    shots: u64,
    seed: u64,
) -> Result<Photos> {
    let simple = cameras
        .iter()
        .map(|s| Ok(SimpleCamera::new(s, chart, &GRID)?))
        .collect::<Result<Vec<_>>>()?;
    let width = chart.feature_names().len();
    let mut features = Vec::with_capacity(ids.len() * shots as usize * width);
    for (j, &i) in ids.iter().enumerate() {
        for k in 0..shots {
            let mut rng = SmallRng::seed_from_u64(seed::derive(
                seed::derive(seed, j as u64 * shots + k),
                SIMPLE_STREAM,
            ));
            let camera = &simple[rng.random_range(0..simple.len())];
            let shot = Shot::draw(&mut rng);
            features.extend(camera.photograph(&library.spds[i], &shot)?);
        }
    }
    Ok(Photos { features, width })
}

/// Mean GFC per lamp of `model` on `photos` (rows `shots` per lamp of `ids`).
pub(crate) fn score(
    model: &Model,
    photos: &Photos,
    truth: &[Vec<f64>],
    ids: &[usize],
    shots: u64,
) -> Result<Vec<f64>> {
    let estimates = model.estimate_rows(&photos.features)?;
    let d = model.grid().count;
    debug_assert_eq!(
        photos.features.len() / photos.width,
        ids.len() * shots as usize
    );
    Ok(ids
        .iter()
        .enumerate()
        .map(|(j, &i)| {
            (0..shots as usize)
                .map(|k| {
                    let row = j * shots as usize + k;
                    spectral_error::gfc(&truth[i], &estimates[row * d..(row + 1) * d])
                        .unwrap_or(0.0)
                })
                .sum::<f64>()
                / shots as f64
        })
        .collect())
}
